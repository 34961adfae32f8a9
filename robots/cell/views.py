"""The pairs a check looks at, as coal models, and each thread's own collision data.

A cell's *candidate pairs* are its checked pairs (:attr:`Cell.pairs`) followed by its
``"out of reach"`` and ``"constant"`` pairs (:data:`.pairs.BOUNDED`) in increasing order of their proven distance bound. A check at a
clearance or margin ``c`` looks at a prefix of them (:meth:`Cell.pairs_for`): every checked
pair and every out-of-reach pair whose bound is at most ``c``. :class:`PairViews` keeps one
``pin.GeometryModel`` per prefix length used (built once, shared, never written after) and,
per thread, the Pinocchio ``Data``, the ``GeometryData`` (with their margin-dependent
request settings) and the broad-phase managers: two threads never share mutable collision
data, so one :class:`Cell` can be used from several threads at once.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np
import pinocchio as pin

from pinarms.robots.collision_requests import cold_start

__all__ = ["PairViews", "Checker"]


def _set_margin(gd: pin.GeometryData, margin: float) -> None:
    for req in gd.collisionRequests:
        req.security_margin = margin


class Checker:
    """Pinocchio broad-phase checks (dynamic AABB tree) over one prefix of pairs, for one thread."""

    def __init__(self, model: pin.Model, gm: pin.GeometryModel) -> None:
        self.model, self.gm = model, gm
        self.margin: float | None = None
        self.gd = cold_start(pin.GeometryData(gm))
        self.manager = pin.BroadPhaseManager_DynamicAABBTreeCollisionManager(model, gm, self.gd)
        self.data = model.createData()
        self.pools: dict[int, Any] = {}
        self.pool_margin: dict[int, float] = {}

    def single(self, q_pin: np.ndarray, margin: float) -> bool:
        if self.margin != margin:
            _set_margin(self.gd, margin)
            self.margin = margin
        return bool(pin.computeCollisions(self.model, self.data, self.manager, q_pin, True))

    def batch(self, q_pin: np.ndarray, margin: float, threads: int) -> np.ndarray:
        pool = self.pools.get(threads)
        if pool is None:
            pool = pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager(self.model, self.gm, threads)
            for gd in pool.getGeometryDatas():
                cold_start(gd)
            self.pools[threads] = pool
        if self.pool_margin.get(threads) != margin:
            for gd in pool.getGeometryDatas():
                _set_margin(gd, margin)
            self.pool_margin[threads] = margin
        out = pin.computeCollisionsInParallel(threads, pool, np.asfortranarray(q_pin.T), True, False)
        return np.asarray(out, dtype=bool).reshape(-1)


class PairViews:
    """Geometry models over prefixes of a cell's candidate pairs, and per-thread collision data."""

    def __init__(self, model: pin.Model, collision_model: pin.GeometryModel, candidates: tuple) -> None:
        self.model = model
        self.base = collision_model
        self.candidates = candidates
        self._models: dict[int, pin.GeometryModel] = {}
        self._lock = threading.Lock()
        self._local = threading.local()

    def geometry(self, n: int) -> pin.GeometryModel:
        """The collision model whose pairs are the first ``n`` candidates (built once, then read only)."""
        gm = self._models.get(n)
        if gm is None:
            with self._lock:
                gm = self._models.get(n)
                if gm is None:
                    gm = self.base.copy()
                    gm.removeAllCollisionPairs()
                    for p in self.candidates[:n]:
                        gm.addCollisionPair(pin.CollisionPair(p.index_a, p.index_b))
                    self._models[n] = gm
        return gm

    def _state(self) -> Any:
        local = self._local
        if not hasattr(local, "data"):
            local.data = self.model.createData()
            local.distance = {}
            local.collision = {}
            local.checkers = {}
        return local

    def data(self) -> pin.Data:
        """This thread's Pinocchio ``Data``."""
        return self._state().data

    def distance_data(self, n: int) -> pin.GeometryData:
        """This thread's ``GeometryData`` for exact distances over the first ``n`` candidates (cold GJK, 1e-10 m)."""
        state = self._state()
        gd = state.distance.get(n)
        if gd is None:
            gd = state.distance[n] = cold_start(pin.GeometryData(self.geometry(n)), distance_tolerance=1e-10)
        return gd

    def collision_data(self, n: int, margin: float) -> pin.GeometryData:
        """This thread's ``GeometryData`` for contact tests over the first ``n`` candidates, at ``margin`` [m]."""
        state = self._state()
        gd = state.collision.get(n)
        if gd is None:
            gd = state.collision[n] = cold_start(pin.GeometryData(self.geometry(n)))
        _set_margin(gd, margin)
        return gd

    def checker(self, n: int) -> Checker:
        """This thread's broad-phase checker over the first ``n`` candidates."""
        state = self._state()
        checker = state.checkers.get(n)
        if checker is None:
            checker = state.checkers[n] = Checker(self.model, self.geometry(n))
        return checker
