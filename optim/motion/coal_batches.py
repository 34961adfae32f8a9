"""coal's side of a :class:`.checker.MotionChecker`: Pinocchio's batch loops, their pools per screen, the deadline.

Every check first asks the sphere cover (:mod:`pinarms.robots.cell.cover`); with the per-pair route
(:attr:`PAIRWISE`) coal computes only the pairs the cover does not prove, per configuration
(:meth:`CoalBatches.pair_collides`); otherwise what it does not prove as a whole goes to coal through Pinocchio's C++ batch loop (``computeCollisionsInParallel``), one pool
per screen level (the margins raised by ``step / 2^(L+1)``) and one at the margins
themselves. The coal data (geometry copy, cold-started requests, pools) is shared by the
checkers of one cell with the same pairs, margins and thread count made in the same thread
(:func:`shared_coal`). Under a deadline the batches run in chunks of :data:`COAL_CHUNK`
configurations, the clock read between two (:class:`.proof.GiveUp` past it).
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Any, TYPE_CHECKING

import numpy as np
import pinocchio as pin

from pinarms.optim.errors import InvalidSettings
from pinarms.optim.motion.proof import COARSE_LEVELS, GiveUp

if TYPE_CHECKING:
    from pinarms.robots.cell.cell import Cell

__all__ = ["CoalBatches", "CheckRoute", "MAX_THREADS", "COAL_CHUNK", "PAIRWISE", "check_threads", "shared_coal", "cold",
           "set_margins"]

#: Configurations per coal batch while a deadline runs (the clock is read between two).
COAL_CHUNK = 16
#: Default of :class:`.checker.MotionChecker`'s ``pairwise``: coal computes only the pairs the cover
#: does not prove (False: every pair of a configuration the cover does not prove as a whole).
PAIRWISE = True


def cold(gd: pin.GeometryData) -> pin.GeometryData:
    """Cold-started GJK (a cached guess from another configuration misses contacts between a
    planner's far-apart samples: :mod:`pinarms.robots.collision_requests`), exact distances."""
    from pinarms.robots.collision_requests import cold_start

    return cold_start(gd, distance_tolerance=1e-10)


def set_margins(gd: pin.GeometryData, margins: np.ndarray) -> None:
    for req, m in zip(gd.collisionRequests, margins):
        req.security_margin = float(m)



class CoalBatches:
    """Batched coal checks of a :class:`.checker.MotionChecker` (a mixin: the checker holds the cell, its
    pairs and margins, the shared coal data, the cover and the deadline)."""

    def _calibrate(self) -> str:
        """The faster of Pinocchio's two batch loops for this geometry, timed once on a straight edge
        between two random configurations (the verdicts are the same; only the speed differs):
        ``"broad phase"`` (dynamic AABB tree: many geometries far apart) or ``"pairs"`` (every
        checked pair in turn, stopping at the first contact: few pairs, or many overlapping
        bounding boxes)."""
        import time as _time

        x = self.cell.random_q(2, seed=0)[:, self.cols]
        if self.timed:
            x = np.column_stack([x, np.zeros(2)])
        Q = self.full(x[0] + np.linspace(0.0, 1.0, 96)[:, None] * (x[1] - x[0]))
        qp = np.asfortranarray(self.to_pinocchio(Q).T)
        best, choice = np.inf, "broad phase"
        for name in ("broad phase", "pairs"):
            pool = self._make_pool(name, self.pair_margin)
            pin.computeCollisionsInParallel(self.threads, pool, qp[:, :8], True, False)  # warm up
            t0 = _time.perf_counter()
            pin.computeCollisionsInParallel(self.threads, pool, qp, True, False)
            dt = _time.perf_counter() - t0
            if dt < best:
                best, choice = dt, name
        return choice

    def _make_pool(self, kind: str, margins: np.ndarray):
        if kind == "pairs":
            pool = pin.GeometryPool(self.model, self.geometry, self.threads)
        else:
            pool = pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager(self.model, self.geometry, self.threads)
        for gd in pool.getGeometryDatas():
            cold(gd)
            set_margins(gd, margins)
        return pool

    def _pool(self, which: Any):
        pool = self._pools.get(which)
        if pool is None:
            if self._shared["loop"] is None:
                self._shared["loop"] = self._calibrate()
            extra = 0.0 if which == "margin" else self.step * 2.0 ** (-int(which) - 1)
            pool = self._make_pool(self._shared["loop"], self.pair_margin + extra)
            self._pools[which] = pool
        return pool

    def warm(self, finest: int = 2) -> None:
        """Build now what the proofs otherwise build on first use (coal's batch pools of the margins
        and of the screens down to level ``finest``, the choice of batch loop, whether the cover
        decides the coarse screens; kept for the next checker of this cell), so that a search's
        clock measures the search."""
        self._pool("margin")
        for level in range(-COARSE_LEVELS, int(finest) + 1):
            self._pool(level)
        _ = self.cover_decides_screens

    def timed_out(self) -> bool:
        """Past :attr:`deadline` (a proof then gives up: the edge counts as not valid)."""
        if self.deadline is None or time.perf_counter() <= self.deadline:
            return False
        self.counts["timeouts"] += 1
        return True

    @property
    def cover_decides_screens(self) -> bool:
        """Whether the cover is used, and then alone screens the coarse raised margins of the proof's
        ladder (what it does not prove counts as not passing: the interval is split; the margins
        themselves and the fine screens go to coal where it is inconclusive). Chosen once per
        cell, pairs and margins: when the cover proves clear at least 97 % of 256 seeded random
        configurations that coal finds clear (spheres and cylinders: the cover is nearly exact);
        otherwise (meshes, the AUBO-i3 under the guard plate: 93.5 %) it would mostly add its
        cost to coal's, and coal alone checks, as without the cover."""
        if self.cover is None or self.timed:
            return False
        tight = self._shared.get("tight")
        if tight is None:
            X = self.cell.random_q(256, seed=0)[:, self.cols]
            Q = self.full(X)
            clear = ~self.coal_collides(Q, "margin")
            proven = self.cover.screen(Q, self._cover_pairs, self.pair_margin)
            tight = bool(proven.sum() >= 0.97 * clear.sum())
            self._shared["tight"] = tight
            self._shared["share"] = float(proven.sum() / max(int(clear.sum()), 1))
        return tight

    @property
    def cover_share(self) -> float:
        """Share of 256 seeded random configurations coal finds clear that the cover proves clear (0: no cover)."""
        if self.cover is None or self.timed:
            return 0.0
        _ = self.cover_decides_screens
        return float(self._shared["share"])

    @property
    def batch_loop(self) -> str | None:
        """Pinocchio's batch loop used (``"broad phase"`` or ``"pairs"``, the faster here; see
        :meth:`_calibrate`); ``None`` until the first batch."""
        return self._shared["loop"]

    def to_pinocchio(self, Q: np.ndarray) -> np.ndarray:
        """Cell configurations ``Q`` (N, nq) as Pinocchio configuration vectors (the same array where they coincide)."""
        return Q if self._identity else self.cell.robot.q_to_pinocchio(Q)


    def batch_collides(self, Q: np.ndarray, which: str | int = "margin", stop: bool = False) -> np.ndarray:
        """``(N,)`` bool: cell configurations ``Q`` closer than the margins (``"margin"``) or the
        margins + ``step / 2^(L+1)`` (``which = L``, a screen level) on some pair; ``stop``:
        stop at the first such row (the rows after it are then reported False). With
        :attr:`pairwise` the per-pair route (:meth:`pair_collides`), else the cover per
        configuration and coal on every pair of the configurations it does not prove."""
        if self.pairwise:
            return self.pair_collides(Q, which, stop)
        Q = np.atleast_2d(Q)
        out = np.zeros(Q.shape[0], dtype=bool)
        rest = np.flatnonzero(~self.covered(Q, which))
        out[rest] = self.coal_collides(Q[rest], which, stop)
        return out

    def _thresholds(self, which: Any) -> np.ndarray:
        """Each pair's threshold [m] at the margins (``"margin"``) or at screen level ``which``: the raise
        ``step / 2^(L+1)`` scaled by the pair's share of the edge's travel while an edge is proven by the
        per-pair route (:meth:`.checker.MotionChecker.edge_valid`), else whole."""
        if which == "margin":
            return self.pair_margin
        extra = self.step * 2.0 ** (-int(which) - 1)
        return self.pair_margin + (extra if self._share is None else extra * self._share)

    def _travel_share(self, xa: np.ndarray, xb: np.ndarray) -> np.ndarray:
        """``(P,)`` in [0, 1]: how far each pair's distance can change along the edge ``xa → xb`` (the joints
        upstream of one of its links and not of the other, :func:`pinarms.optim.motion.link_levers.group_levers`)
        over the edge's travel ``T``. Two samples whose pair ``k`` keeps ``share_k · s`` above its margin,
        with travel ``B ≤ 2s`` between them, keep it above its margin in between: the ladder's raise is
        scaled per pair (:meth:`_thresholds`)."""
        from pinarms.optim.motion.link_levers import group_levers

        if self._pair_rows is None:
            ps = self._cover_pairs
            G = group_levers(self.cover, ps, self.model.lowerPositionLimit, self.model.upperPositionLimit, self.cols)
            rows = np.empty((len(self.pairs), self.n))
            rows[ps.order] = np.repeat(G, np.diff(ps.group_start), axis=0)
            self._pair_rows = rows
        dx = np.abs(xb[: self.n] - xa[: self.n])
        T = float(dx @ self.levers)
        if T <= 0.0:
            return np.ones(len(self.pairs))
        return np.minimum(self._pair_rows @ dx / T, 1.0)

    def open_pairs(self, Q: np.ndarray, which: str | int = "margin") -> np.ndarray:
        """``(N, P)`` bool: the pairs the exact check must decide at cell configurations ``Q`` — those the
        cover (:meth:`pinarms.robots.cell.cover.Cover.pair_screen`) does not prove farther apart than their
        threshold (``which``: the margins, or a screen level; :meth:`_thresholds`)."""
        Q = np.atleast_2d(Q)
        P = len(self.pairs)
        if self.cover is None:
            return np.ones((Q.shape[0], P), dtype=bool)
        screen = self._screeners.get("cover")
        if screen is None:
            screen = self._screeners["cover"] = self.cover.pair_screener(self._cover_pairs, self.pair_margin)
        return ~screen(Q, self._thresholds(which))

    def _state_pairs(self, q: np.ndarray) -> bool:
        """Whether cell configuration ``q`` is closer than the margins on a pair, by the per-pair route: coal
        (one call per pair, stopping at the first too close) on the pairs the cover leaves open only."""
        want = np.flatnonzero(self.open_pairs(q[None], "margin")[0])
        if want.size == 0:
            return False
        self.counts["coal"] += 1
        self.counts["coal_pairs"] += int(want.size)
        gm, gd = self.geometry, self._gd
        pin.updateGeometryPlacements(self.model, self._data, gm, gd, self.to_pinocchio(q[None])[0])
        return any(pin.computeCollision(gm, gd, k) for k in want.tolist())

    def pair_collides(self, Q: np.ndarray, which: str | int = "margin", stop: bool = False) -> np.ndarray:
        """:meth:`batch_collides` by the per-pair route: coal computes only the pairs the cover leaves open
        (:meth:`open_pairs`); a configuration with none open is proven clear without coal. With ``stop``
        (or a deadline) a few configurations at a time, cover then coal, in their order (with ``stop`` 1, 2,
        4, ... up to :data:`COAL_CHUNK`: an edge through an obstacle often fails on its first sample)."""
        Q = np.atleast_2d(Q)
        N = Q.shape[0]
        self.counts["configurations"] += N
        out = np.zeros(N, dtype=bool)
        chunked = stop or self.deadline is not None
        a, chunk = 0, (1 if stop else COAL_CHUNK) if chunked else max(N, 1)
        while a < N:
            if self.deadline is not None and self.timed_out():
                raise GiveUp
            a0 = a
            want = self.open_pairs(Q[a0:a0 + chunk], which)
            a += chunk
            if chunked:
                chunk = min(2 * chunk, COAL_CHUNK)
            rows = np.flatnonzero(want.any(axis=1))
            if rows.size == 0:
                continue
            hit = self.coal_pairs(Q[a0 + rows], want[rows], which, stop)
            out[a0 + rows] = hit
            if stop and hit.any():
                out[a0 + int(rows[int(np.argmax(hit))]) + 1:] = False
                break
        return out

    def coal_pairs(self, Q: np.ndarray, want: np.ndarray, which: str | int = "margin", stop: bool = False) -> np.ndarray:
        """``(N,)`` bool: configuration ``Q[i]`` closer than its threshold on one of the pairs ``want[i]``
        (``(N, P)`` bool) — coal on those pairs only, through Pinocchio's batch loop: the configurations
        with the same open pairs in one batch (``stop``: the rows after the first hit are reported False;
        the caller gives few rows at a time, :meth:`pair_collides`)."""
        Q = np.atleast_2d(Q)
        N = Q.shape[0]
        out = np.zeros(N, dtype=bool)
        if N == 0:
            return out
        self.counts["coal"] += N
        self.counts["coal_pairs"] += int(want.sum())
        qp = np.asfortranarray(self.to_pinocchio(Q).T)
        pool = self._pair_pool(which)
        datas = pool.getGeometryDatas()
        t = self._thresholds(which).tolist()
        groups: dict[bytes, list[int]] = {}
        for i, key in enumerate(np.packbits(want, axis=1)):
            groups.setdefault(key.tobytes(), []).append(i)
        for rows in groups.values():
            for gd in datas:
                gd.deactivateAllCollisionPairs()
                requests = gd.collisionRequests
                for k in np.flatnonzero(want[rows[0]]).tolist():
                    gd.activateCollisionPair(k)
                    requests[k].security_margin = t[k]
            cols = np.array(rows)
            hit = pin.computeCollisionsInParallel(self.threads, pool, np.asfortranarray(qp[:, cols]), True, False)
            out[cols] = np.asarray(hit, dtype=bool).reshape(-1)
        if stop and out.any():
            out[int(np.argmax(out)) + 1:] = False
        return out

    def _pair_pool(self, which: Any):
        """The pool of the per-pair route (Pinocchio's pair loop: it honours each data's active pairs; their
        security margins are set at every batch, :meth:`coal_pairs`)."""
        pool = self._pools.get("pairwise")
        if pool is None:
            pool = self._pools["pairwise"] = self._make_pool("pairs", self.pair_margin)
        return pool

    def covered(self, Q: np.ndarray, which: str | int = "margin") -> np.ndarray:
        """``(N,)`` bool: configurations the sphere cover proves clear of the margins (``"margin"``)
        or of the margins + ``step / 2^(L+1)`` (``which = L``); False: left to coal."""
        Q = np.atleast_2d(Q)
        self.counts["configurations"] += Q.shape[0]
        if Q.shape[0] == 0 or not self.cover_decides_screens:
            return np.zeros(Q.shape[0], dtype=bool)
        extra = 0.0 if which == "margin" else self.step * 2.0 ** (-int(which) - 1)
        return self.cover.screen(Q, self._cover_pairs, self.pair_margin + extra)

    def exact_collides(self, Q: np.ndarray, which: str | int = "margin", stop: bool = False) -> np.ndarray:
        """:meth:`batch_collides` for configurations the cover did not prove as a whole: the per-pair route
        (:meth:`pair_collides`) with :attr:`pairwise`, else coal on every pair (:meth:`coal_collides`)."""
        return self.pair_collides(Q, which, stop) if self.pairwise else self.coal_collides(Q, which, stop)

    def coal_collides(self, Q: np.ndarray, which: str | int = "margin", stop: bool = False) -> np.ndarray:
        """:meth:`batch_collides` by coal alone (Pinocchio's batch loop), no cover."""
        Q = np.atleast_2d(Q)
        self.counts["coal"] += Q.shape[0]
        self.counts["coal_pairs"] += Q.shape[0] * len(self.pairs)
        if Q.shape[0] == 0:
            return np.zeros(0, dtype=bool)
        qp = np.asfortranarray(self.to_pinocchio(Q).T)
        pool = self._pool(which)
        if self.deadline is None:
            hit = pin.computeCollisionsInParallel(self.threads, pool, qp, True, bool(stop))
            return np.asarray(hit, dtype=bool).reshape(-1)
        out = np.zeros(Q.shape[0], dtype=bool)
        for a in range(0, Q.shape[0], COAL_CHUNK):  # under a deadline: in chunks, looking at the clock
            if self.timed_out():
                raise GiveUp
            chunk = np.asfortranarray(qp[:, a:a + COAL_CHUNK])
            hit = np.asarray(pin.computeCollisionsInParallel(self.threads, pool, chunk, True, bool(stop)),
                             dtype=bool).reshape(-1)
            out[a:a + hit.size] = hit
            if stop and hit.any():
                break
        return out



#: Most threads of Pinocchio's batch checks.
MAX_THREADS = 256
#: Checkers' coal data kept per cell (pairs, margins, threads, calling thread) before the oldest go.
_SHARED_KEEP = 16


@dataclass(frozen=True)
class CheckRoute:
    """How a :class:`pinarms.optim.motion.checker.MotionChecker` runs its checks (the verdicts are the same).

    Attributes:
        threads: threads of Pinocchio's batch checks (1 to :data:`MAX_THREADS`).
        cover: screen every check on the sphere cover first (:mod:`pinarms.robots.cell.cover`; coal only
            where the cover is inconclusive).
        pairwise: the per-pair route (``None``: :data:`PAIRWISE`, read when the checker is made):
            coal only on the pairs the cover does not prove, not on every pair of a state it does not prove.

    Raises:
        InvalidSettings: a thread count out of range, ``cover`` or ``pairwise`` not a bool.
    """

    threads: int = 1
    cover: bool = True
    pairwise: bool | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "threads", check_threads(self.threads))
        if not isinstance(self.cover, (bool, np.bool_)):
            raise InvalidSettings(f"cover must be True or False, got {self.cover!r}")
        if self.pairwise is not None and not isinstance(self.pairwise, (bool, np.bool_)):
            raise InvalidSettings(f"pairwise must be True, False or None (the default route), got {self.pairwise!r}")


def check_threads(threads: object) -> int:
    """``threads`` as an int in ``1..MAX_THREADS`` or :class:`InvalidSettings` (0 or fewer crash
    Pinocchio's batch loop; huge counts overflow its argument)."""
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)):
        raise InvalidSettings(f"threads must be an integer from 1 to {MAX_THREADS}, got {threads!r}")
    if not 1 <= int(threads) <= MAX_THREADS:
        raise InvalidSettings(f"threads must be from 1 to {MAX_THREADS} (threads of the batched collision checks), "
                              f"got {int(threads)}")
    return int(threads)


_SHARED_LOCK = threading.Lock()


def shared_coal(cell: Cell, pairs: tuple, margins: np.ndarray, threads: int) -> dict:
    """coal data (geometry copy, GeometryData, broad phase, batch pools per screen level) shared by
    the checkers of one cell with the same pairs, margins and thread count, made in the same
    thread: making them costs tens of ms per checker (cold-starting every request)."""
    key = (tuple((p.index_a, p.index_b) for p in pairs), margins.tobytes(), threads, threading.get_ident())
    with _SHARED_LOCK:
        store = cell.memo("motion checker shared", dict)
        entry = store.pop(key, None)
        if entry is None:
            entry = {}
            while len(store) >= _SHARED_KEEP:
                store.pop(next(iter(store)))
        store[key] = entry  # most recently used last
        return entry

