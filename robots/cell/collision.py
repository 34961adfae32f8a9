"""Collisions and clearance of cell configurations, one or a batch (Pinocchio + coal).

- :func:`in_collision`: does a configuration touch? Pinocchio's broad phase (coal's dynamic
  AABB tree) culls the checked pairs whose boxes are apart, then coal decides the others,
  stopping at the first contact. One configuration: one call; a batch: Pinocchio's C++
  batch (``computeCollisionsInParallel`` on a broad-phase pool), no Python per configuration.
- :func:`collisions`: *which* pairs touch (the batch above first, then every pair of the
  touching configurations only).
- :func:`clearance`: the smallest signed distance (coal, negative = penetration depth)
  and the pair that has it. A numpy broad phase bounds every pair's distance from below
  for the whole batch at once (bounding spheres of the moving geometries against bounding
  spheres or boxes); per configuration, coal's exact distance is computed for the pairs in
  increasing order of their bound until the next bound exceeds the best exact distance.
  The result is the exact minimum over all checked pairs.

Distances are in m, in the world frame; the pairs are :attr:`Cell.pairs`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
import pinocchio as pin

from pinarms.errors import CollisionGeometryError, InvalidInput
from pinarms.robots.cell.pairs import CollisionPair

from pinarms.robots.cell.cell_model import CellModel

__all__ = ["Collisions", "Clearance", "in_collision", "collisions", "clearance", "pair_lower_bounds", "check_margin"]


@dataclass(frozen=True, eq=False)
class Collisions:
    """Which checked pairs touch, per configuration.

    Attributes:
        pairs: the checked pairs (:attr:`Cell.pairs`).
        colliding: ``(N,)`` bool: the configuration has at least one touching pair.
        touching: per configuration, the indices (into ``pairs``) of the touching pairs.
        margin: pairs closer than this [m] count as touching.
        single: one configuration was given.
    """

    pairs: tuple[CollisionPair, ...]
    colliding: np.ndarray
    touching: tuple[tuple[int, ...], ...]
    margin: float
    single: bool

    def __bool__(self) -> bool:
        return bool(self.colliding.any())

    def __len__(self) -> int:
        return len(self.touching)

    def pairs_at(self, i: int = 0) -> list[CollisionPair]:
        """The touching pairs of configuration ``i``."""
        return [self.pairs[k] for k in self.touching[i]]

    def bodies_at(self, i: int = 0) -> list[tuple[str, str]]:
        """``(body_a, body_b)`` of the touching pairs of configuration ``i``."""
        return [self.pairs[k].bodies for k in self.touching[i]]

    def __repr__(self) -> str:
        n = int(self.colliding.sum())
        where = f"{n} of {self.colliding.size} configurations touch" if not self.single else (
            f"{len(self.touching[0])} pair(s) touch" + (f", e.g. {self.pairs[self.touching[0][0]]}" if self.touching[0] else ""))
        return f"Collisions({where} at margin {self.margin * 1e3:.1f} mm; {len(self.pairs)} pairs looked at)"


@dataclass(frozen=True, eq=False)
class Clearance:
    """The smallest signed distance over every pair not allowed by design, per configuration.

    Attributes:
        distance: [m] ``float`` (one configuration) or ``(N,)``; negative: the bodies
            overlap by that depth. Exact (coal) over the checked pairs and every
            out-of-reach pair whose proven bound is below it.
        pair: index into ``pairs`` of the pair that has it (``int`` or ``(N,)``).
        point_a, point_b: nearest points on ``body_a`` and ``body_b`` in the world [m]
            (``(3,)`` or ``(N, 3)``).
        margin: the requested safety distance [m].
        pairs: the candidate pairs (:meth:`Cell.pairs_for` ``(inf)``: the checked pairs
            first, then the out-of-reach ones).

    ``repr`` is a one-line summary (smallest distance, its pair, how many configurations).
    """

    distance: Any
    pair: Any
    point_a: np.ndarray
    point_b: np.ndarray
    margin: float
    pairs: tuple[CollisionPair, ...]

    @property
    def ok(self) -> Any:
        """Whether the clearance is at least ``margin`` (``bool`` or ``(N,)``)."""
        return self.distance >= self.margin

    def pair_of(self, i: int | None = None) -> CollisionPair:
        """The closest pair (of configuration ``i`` for a batch)."""
        k = self.pair if i is None else self.pair[i]
        return self.pairs[int(k)]

    def __repr__(self) -> str:
        d = np.atleast_1d(np.asarray(self.distance, dtype=float))
        k = np.atleast_1d(np.asarray(self.pair))
        if d.size == 0:
            return "Clearance(no configurations)"
        i = int(np.argmin(d))
        pair = str(self.pairs[int(k[i])]) if k[i] >= 0 else "no pair"
        where = "" if np.ndim(self.distance) == 0 else f" (configuration {i} of {d.size})"
        ok = int(np.count_nonzero(d >= self.margin))
        return (f"Clearance({d[i] * 1e3:.3f} mm{where}, {pair}; {ok} of {d.size} at least the margin "
                f"{self.margin * 1e3:.1f} mm; {len(self.pairs)} pairs)")


def check_margin(margin: float) -> float:
    """``margin`` [m] as a float.

    Raises:
        InvalidInput: not a finite number >= 0 (a bool counts as no number).
    """
    ok = isinstance(margin, (int, float, np.integer, np.floating)) and not isinstance(margin, bool)
    value = float(margin) if ok else float("nan")
    if not np.isfinite(value) or value < 0.0:
        raise InvalidInput(f"margin must be a finite number >= 0 [m], got {margin!r}")
    return value


#: Most threads of one batched contact check (each holds its own copy of the collision data).
MAX_THREADS = 64


def in_collision(cell: "CellModel", q: ArrayLike, *, margin: float = 0.0, threads: int = 1) -> bool | np.ndarray:
    """See :meth:`Cell.in_collision`."""
    if margin != 0.0:
        margin = check_margin(margin)
    n = cell.pair_count(float(margin)) if margin == margin else 0
    fast = cell.pin_vector_or_none(q)  # one finite (nq,) vector: skip the batch machinery
    if fast is not None and n:
        return cell.pair_views.checker(n).single(fast, float(margin))
    margin = check_margin(margin)
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or not 1 <= threads <= MAX_THREADS:
        raise InvalidInput(f"threads must be an integer from 1 to {MAX_THREADS}, got {threads!r}")
    arr, single = cell.robot.check_q(q)
    if not n:
        return False if single else np.zeros(arr.shape[0], dtype=bool)
    qp = cell.robot.q_to_pinocchio(arr)
    checker = cell.pair_views.checker(n)
    if single:
        return checker.single(qp[0], margin)
    return checker.batch(qp, margin, int(threads))


def collisions(cell: "CellModel", q: ArrayLike, *, margin: float = 0.0) -> Collisions:
    """See :meth:`Cell.collisions`."""
    margin = check_margin(margin)
    arr, single = cell.robot.check_q(q)
    hit = np.atleast_1d(in_collision(cell, arr if not single else arr[0], margin=margin))
    if single:
        hit = np.array([hit[0]])
    touching: list[tuple[int, ...]] = [()] * arr.shape[0]
    n = cell.pair_count(margin)
    if hit.any():
        qp = cell.robot.q_to_pinocchio(arr)
        views = cell.pair_views
        gm, gd, data = views.geometry(n), views.collision_data(n, margin), views.data()
        for i in np.flatnonzero(hit):
            pin.updateGeometryPlacements(cell.model, data, gm, gd, qp[i])
            pin.computeCollisions(gm, gd, False)
            touching[i] = tuple(k for k, r in enumerate(gd.collisionResults) if r.isCollision())
    return Collisions(cell.pairs_for(margin), hit.copy(), tuple(touching), margin, single)


# ------------------------------------------------------------------ broad phase
def _bounds_data(cell: "CellModel") -> dict:
    """Constant data of the broad phase: bounding spheres, static boxes, pair index lists (built once per cell)."""
    return cell.memo("broad phase", lambda: _broad_phase(cell))


def _broad_phase(cell: "CellModel") -> dict:
    objs = list(cell.collision_model.geometryObjects)
    G = len(objs)
    radius = np.zeros(G)
    half = np.zeros((G, 3))
    offset = np.zeros((G, 3))  # bounding-box centre in the parent joint's frame
    for k, g in enumerate(objs):
        g.geometry.computeLocalAABB()
        lo, hi = np.asarray(g.geometry.aabb_local.min_), np.asarray(g.geometry.aabb_local.max_)
        half[k] = (hi - lo) / 2.0
        radius[k] = float(np.linalg.norm(half[k]))
        offset[k] = g.placement.act((lo + hi) / 2.0)
    joint = np.array([g.parentJoint for g in objs], dtype=int)
    by_joint = {int(j): np.flatnonzero(joint == j) for j in np.unique(joint) if j > 0}
    static = joint == 0
    data = cell.model.createData()
    pin.forwardKinematics(cell.model, data, pin.neutral(cell.model))
    box_R = np.array([g.placement.rotation for g in objs])  # static: parent joint is the world
    box_c = offset.copy()
    ia = np.array([p.index_a for p in cell.candidates], dtype=int)
    ib = np.array([p.index_b for p in cell.candidates], dtype=int)
    # pairs of a moving geometry with a static one, grouped by the static geometry
    static_groups = []
    for s_idx in np.flatnonzero(static):
        cols = np.flatnonzero((ib == s_idx) & ~static[ia])
        cols_b = np.flatnonzero((ia == s_idx) & ~static[ib])
        cols = np.concatenate([cols, cols_b])
        if cols.size:
            moving = np.where(ia[cols] == s_idx, ib[cols], ia[cols])
            static_groups.append((int(s_idx), cols, moving))
    cached = {
        "radius": radius, "half": half, "offset": offset, "by_joint": by_joint, "static": static,
        "box_R": box_R, "box_c": box_c, "ia": ia, "ib": ib, "static_groups": static_groups,
    }
    return cached


def pair_lower_bounds(cell: "CellModel", q: np.ndarray, n: int | None = None) -> np.ndarray:
    """``(N, P)`` lower bounds of the candidate pairs' distances [m] for a batch ``q (N, nq)``.

    Columns: the first ``n`` candidate pairs (default all: :meth:`Cell.pairs_for` ``(inf)``;
    the checked pairs are the first ``len(cell.pairs)``).

    Bounding sphere against bounding sphere (for overlapping bodies too: the penetration
    depth of two bodies is at most that of their bounding spheres); against a static
    geometry, also the moving geometry's sphere against the static one's oriented bounding
    box when that proves them apart (tighter for long fixtures such as a conveyor). A bound
    may be negative; it never exceeds the signed distance.
    """
    b = _bounds_data(cell)
    arr = np.asarray(q, dtype=float)
    N, G = arr.shape[0], len(b["radius"])
    R, p = cell.batched_placements.joints(arr)
    c = np.empty((N, G, 3))
    c[:, b["static"]] = b["box_c"][b["static"]]
    for j, idx in b["by_joint"].items():
        c[:, idx] = p[:, j, None, :] + np.matmul(R[:, j], b["offset"][idx].T).transpose(0, 2, 1)
    n = len(b["ia"]) if n is None else int(n)
    ia, ib = b["ia"][:n], b["ib"][:n]
    lb = np.linalg.norm(c[:, ia] - c[:, ib], axis=-1) - b["radius"][ia] - b["radius"][ib]
    for s_idx, cols, moving in b["static_groups"]:
        if n < len(b["ia"]):
            keep = cols < n
            cols, moving = cols[keep], moving[keep]
            if not cols.size:
                continue
        local = (c[:, moving] - b["box_c"][s_idx]) @ b["box_R"][s_idx]
        outside = np.maximum(np.abs(local) - b["half"][s_idx], 0.0)
        box_lb = np.linalg.norm(outside, axis=-1) - b["radius"][moving]
        # a positive bound proves the pair apart by at least that much; a negative one says
        # nothing about the penetration depth (the sphere's centre may lie inside the box)
        lb[:, cols] = np.where(box_lb > 0.0, np.maximum(lb[:, cols], box_lb), lb[:, cols])
    return lb


#: Up to this many out-of-reach pairs, a batch's clearance sorts them with the checked pairs in one pass.
ONE_PASS_REACH = 2000


def clearance(cell: "CellModel", q: ArrayLike, *, margin: float = 0.0) -> Clearance:
    """See :meth:`Cell.clearance`."""
    margin = check_margin(margin)
    arr, single = cell.robot.check_q(q)
    N = arr.shape[0]
    pairs = cell.candidates
    if not pairs:
        inf = np.full(N, np.inf)
        nan3 = np.full((N, 3), np.nan)
        pick = (lambda x: x[0]) if single else (lambda x: x)
        return Clearance(pick(inf), pick(np.full(N, -1)), pick(nan3), pick(nan3), margin, pairs)
    if N <= 4 or len(cell.reach_bounds) > ONE_PASS_REACH:
        # a few configurations (the checked pairs in Pinocchio's loop), or a huge cell: the checked
        # pairs first, then only the out-of-reach pairs whose bound is below each row's distance
        dist, pair, pa, pb = exact_min_distance(cell, arr)
        _reach_pass(cell, arr, dist, pair, pa, pb)
    else:  # one pass over every candidate, each out-of-reach pair's bound raised to its proven one
        lb = pair_lower_bounds(cell, arr)
        n0 = len(cell.pairs)
        lb[:, n0:] = np.maximum(lb[:, n0:], cell.reach_bounds)
        dist, pair, pa, pb = exact_min_distance(cell, arr, lb=lb, n=len(pairs))
    if single:
        return Clearance(float(dist[0]), int(pair[0]), pa[0], pb[0], margin, pairs)
    return Clearance(dist, pair, pa, pb, margin, pairs)


def _reach_pass(cell: "CellModel", arr: np.ndarray, dist: np.ndarray, pair: np.ndarray, pa: np.ndarray,
                pb: np.ndarray) -> None:
    """Bring in the out-of-reach pairs whose bound is below each row's smallest distance (in place)."""
    n0 = len(cell.pairs)
    need = [i for i in range(arr.shape[0]) if cell.pair_count(float(dist[i]), strict=True) > n0]
    if not need:
        return
    n_max = max(cell.pair_count(float(dist[i]), strict=True) for i in need)
    views = cell.pair_views
    gm, gd, data = views.geometry(n_max), views.distance_data(n_max), views.data()
    lb = pair_lower_bounds(cell, arr[need], n_max)[:, n0:]
    bounds = cell.reach_bounds
    qp = cell.robot.q_to_pinocchio(arr[need])
    for row, i in enumerate(need):
        pin.updateGeometryPlacements(cell.model, data, gm, gd, qp[row])
        for k in range(n0, n_max):
            if bounds[k - n0] >= dist[i]:
                break
            if lb[row, k - n0] >= dist[i]:
                continue
            res = pin.computeDistance(gm, gd, k)
            d = _finite(cell, res.min_distance, k)
            if d < dist[i]:
                dist[i], pair[i] = d, k
                pa[i], pb[i] = np.array(res.getNearestPoint1()), np.array(res.getNearestPoint2())


def _finite(cell: "CellModel", d: float, k: int) -> float:
    if not np.isfinite(d):
        p = cell.candidates[k]
        raise CollisionGeometryError(f"coal returned distance {d} for {p.body_a} – {p.body_b}")
    return float(d)


def exact_min_distance(cell: "CellModel", arr: np.ndarray, lb: np.ndarray | None = None, n: int | None = None,
                       cap: float = np.inf):
    """Exact smallest distance over the first ``n`` candidate pairs (default: the checked pairs) per row of ``arr (N, nq)``.

    Returns ``(distance (N,), pair (N,), point_a (N, 3), point_b (N, 3))``; ``pair`` indexes
    :meth:`Cell.pairs_for` (a prefix of the candidates). ``inf`` and pair −1 when ``n`` is 0.
    ``cap`` [m]: a row stops once the next pair's bound reaches it; a distance below ``cap``
    is exact, one at or above it only a lower bound of the row's smallest distance (its pair
    and points those of the smallest computed, −1 and nan when none was).
    """
    N = arr.shape[0]
    n = len(cell.pairs) if n is None else int(n)
    if n == 0:
        return np.full(N, np.inf), np.full(N, -1, dtype=int), np.full((N, 3), np.nan), np.full((N, 3), np.nan)
    if lb is None and N <= 4:  # a few configurations: every pair in Pinocchio's loop beats the broad phase
        return _all_pairs_min_distance(cell, arr, n)
    if lb is None:
        lb = pair_lower_bounds(cell, arr, n)
    order = np.argsort(lb, axis=1, kind="stable")
    sorted_lb = np.take_along_axis(lb, order, axis=1)
    qp = cell.robot.q_to_pinocchio(arr)
    views = cell.pair_views
    gm, gd, model, data = views.geometry(n), views.distance_data(n), cell.model, views.data()
    dist = np.empty(N)
    best_pair = np.empty(N, dtype=int)
    pa = np.empty((N, 3))
    pb = np.empty((N, 3))
    P = lb.shape[1]
    for i in range(N):
        pin.updateGeometryPlacements(model, data, gm, gd, qp[i])
        best, arg, res_best = np.inf, -1, None
        row, row_lb = order[i], sorted_lb[i]
        for r in range(P):
            if row_lb[r] >= best:
                break
            if row_lb[r] >= cap:  # every pair left is at least row_lb[r] >= cap away: a bound
                best = min(best, float(row_lb[r]))
                break
            k = int(row[r])
            res = pin.computeDistance(gm, gd, k)
            d = _finite(cell, res.min_distance, k)
            if d < best:
                best, arg, res_best = d, k, (np.array(res.getNearestPoint1()), np.array(res.getNearestPoint2()))
        dist[i], best_pair[i] = best, arg
        pa[i], pb[i] = res_best if res_best is not None else (np.full(3, np.nan), np.full(3, np.nan))
    return dist, best_pair, pa, pb


def _all_pairs_min_distance(cell: "CellModel", arr: np.ndarray, n: int):
    qp = cell.robot.q_to_pinocchio(arr)
    views = cell.pair_views
    gm, gd, data = views.geometry(n), views.distance_data(n), views.data()
    N = arr.shape[0]
    dist, pair = np.empty(N), np.empty(N, dtype=int)
    pa, pb = np.empty((N, 3)), np.empty((N, 3))
    for i in range(N):
        pin.updateGeometryPlacements(cell.model, data, gm, gd, qp[i])
        pin.computeDistances(gm, gd)
        d = np.array([r.min_distance for r in gd.distanceResults])
        if not np.all(np.isfinite(d)):
            _finite(cell, float(d[np.flatnonzero(~np.isfinite(d))[0]]), int(np.flatnonzero(~np.isfinite(d))[0]))
        k = int(np.argmin(d))
        r = gd.distanceResults[k]
        dist[i], pair[i] = d[k], k
        pa[i], pb[i] = np.array(r.getNearestPoint1()), np.array(r.getNearestPoint2())
    return dist, pair, pa, pb
