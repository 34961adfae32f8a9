"""pinarms' (coal's) distances of a cell's contact pairs at many configurations, exact where a figure of the
MuJoCo re-check needs them (:mod:`pinarms.export.verify`), proven bounds elsewhere.

coal's exact distance between two meshes of tens of thousands of triangles takes 10-20 ms (a traversal of both
triangle trees), so the re-check of a foreign arm's planned move spent minutes there: every pair at every
instant. Most of those values cannot change what the re-check reports. Per pair and configuration, a
**proven interval** ``[lower, upper]`` of coal's distance is cheap:

- ``lower``: coal's distance between the **convex hulls** of the two shapes (a mesh's hull contains the
  mesh; a primitive is its own hull), less :data:`SLACK_M` for the two computations' tolerances (GJK at
  1e-10 on each side; measured at most 1e-10 above the exact mesh distance). Hulls that touch give
  ``-inf``.
- ``upper``: the distance between two points **on** the shapes: each hull's closest point moved to the
  nearest point of the mesh triangles around it (:func:`closest_on_triangles`; a primitive's closest point
  lies on it), plus :data:`SLACK_M`. Where the hulls touch: ``+inf``.

:func:`needed` says which entries a figure of :func:`pinarms.export.verify.compare_in_mujoco` may depend on,
given MuJoCo's distances: the sign where ``lower <= 0``; whether the pair is within ``DISTMAX`` where the
interval straddles it; the smallest distance where ``lower`` is at most the smallest ``upper``; the
largest mesh excess (MuJoCo above coal) where ``d_mujoco - lower`` reaches the largest proven excess;
the largest mesh gap (coal above MuJoCo) where ``upper - d_mujoco`` reaches the largest proven gap; and
every pair without a mesh (cheap, compared two-sided). Only those get coal's exact distance, computed as
before (``pin.computeDistance`` on a geometry model of the pairs, cold-started at 1e-10 m). Every other
entry is reported as its ``lower`` bound: it lies on the same side of 0 and of ``DISTMAX``, above the
smallest distance, and below the largest excess and gap, so each figure is the one every exact distance
gives (tests/export/test_pair_distances.py compares both on whole reports).
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import pinocchio as pin

from pinarms.robots.collision_requests import cold_start

__all__ = ["SLACK_M", "BATCH", "NEAR_TRIANGLES", "closest_on_triangles", "PairDistances", "pair_bounds", "needed", "settle", "exact_distances", "pinarms_distances"]

#: Added to each bound [m]: coal's GJK on the hulls and its exact mesh distance each iterate to 1e-10 m.
SLACK_M = 1e-9
#: Tolerance of coal's exact distances [m] (as the re-check always asked).
DISTANCE_TOLERANCE_M = 1e-10


@dataclass(frozen=True)
class PairDistances:
    """Distances ``(N, P)`` [m] of P pairs at N configurations: ``value`` coal's exact distance where ``exact``,
    else the entry's proven lower bound (module doc); ``lower`` and ``upper`` the proven bounds (equal to
    ``value`` where exact)."""

    value: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    exact: np.ndarray

    @property
    def exact_share(self) -> float:
        """Share of the entries coal computed exactly."""
        return float(self.exact.mean()) if self.exact.size else 1.0


def _probe(cell: Any, pairs: tuple) -> tuple[Any, Any]:
    """The cell's geometry model with only ``pairs`` (in order) and its data, cold-started at the tolerance."""
    gm = cell.collision_model.copy()
    gm.removeAllCollisionPairs()
    for p in pairs:
        gm.addCollisionPair(pin.CollisionPair(p.index_a, p.index_b))
    return gm, cold_start(pin.GeometryData(gm), distance_tolerance=DISTANCE_TOLERANCE_M)


#: :func:`_hull` of the last :data:`_KEPT` meshes of this process: ``coal id -> (object, vertices, hull)`` (the
#: object held so that its id is not reused); again while the vertices are the same.
_HULLS: OrderedDict = OrderedDict()
_KEPT = 64


def _hull(geometry: Any) -> tuple[Any, np.ndarray | None]:
    """``(convex shape, mesh vertices or None)``: a mesh's convex hull (coal) and its vertices in the shape's
    frame [m]; a shape without vertices (a primitive) is its own hull. Computed once per process and mesh."""
    try:
        V = np.array(geometry.vertices(), dtype=float).reshape(-1, 3)
    except (AttributeError, TypeError, RuntimeError):
        return geometry, None
    key = geometry.id() if callable(getattr(geometry, "id", None)) else id(geometry)
    kept = _HULLS.get(key)
    if kept is not None and np.array_equal(kept[1], V):
        _HULLS.move_to_end(key)
        return kept[2], kept[1]
    hull = _convex_hull(V)
    if hull is None:  # a flat mesh: no hull, its pairs computed exactly
        return geometry, None
    _HULLS[key] = (geometry, V, hull)
    if len(_HULLS) > _KEPT:
        _HULLS.popitem(last=False)
    return hull, V


def _convex_hull(V: np.ndarray) -> Any:
    """coal's convex hull (with its vertex neighbours, for GJK) of the points ``V (n, 3)``; None for points
    without a 3-D hull (flat, fewer than four)."""
    import coal
    from scipy.spatial import ConvexHull, QhullError

    try:
        corners = V[ConvexHull(V).vertices]  # fewer points for coal's own hull
        points = coal.StdVec_Vec3s()
        for v in corners:
            points.append(v)
        return coal.Convex.convexHull(points, False, "")
    except (QhullError, ValueError, RuntimeError):
        return None


def _is_shape(geometry: Any) -> bool:
    """A convex primitive coal's GJK takes as it is (box, sphere, cylinder, capsule, cone, ellipsoid, convex)."""
    import coal

    return isinstance(geometry, (coal.Box, coal.Sphere, coal.Cylinder, coal.Capsule, coal.Cone, coal.Ellipsoid,
                                 coal.ConvexBase))


def pair_bounds(cell: Any, pairs: tuple, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(lower, upper)``: proven bounds ``(N, P)`` [m] of coal's distance of ``pairs`` at the cell
    configurations ``qs`` (module doc). A pair with a shape that is neither a mesh nor a convex primitive,
    or whose hulls touch, gets ``(-inf, +inf)``."""
    import coal

    gm = cell.collision_model
    used = sorted({i for p in pairs for i in (p.index_a, p.index_b)})
    hulls: dict[int, tuple[Any, np.ndarray | None]] = {}
    for i in used:
        geo = gm.geometryObjects[i].geometry
        hulls[i] = (geo, None) if _is_shape(geo) else _hull(geo)
    usable = [_is_shape(hulls[p.index_a][0]) and _is_shape(hulls[p.index_b][0]) for p in pairs]
    n, m = len(qs), len(pairs)
    lower = np.full((n, m), -np.inf)
    local = np.full((n, m, 2, 3), np.nan)  # the hulls' closest points, each in its shape's own frame
    slot = {i: s for s, i in enumerate(used)}
    R, t = np.empty((n, len(used), 3, 3)), np.empty((n, len(used), 3))
    data, gd = cell.model.createData(), pin.GeometryData(gm)
    request = coal.DistanceRequest()
    request.gjk_tolerance = DISTANCE_TOLERANCE_M
    for k, q in enumerate(np.atleast_2d(cell.robot.q_to_pinocchio(qs))):
        pin.updateGeometryPlacements(cell.model, data, gm, gd, q)
        placed = {i: gd.oMg[i] for i in used}
        for i, M in placed.items():
            R[k, slot[i]], t[k, slot[i]] = M.rotation, M.translation
        for j, p in enumerate(pairs):
            if not usable[j]:
                continue
            result = coal.DistanceResult()
            coal.distance(hulls[p.index_a][0], placed[p.index_a], hulls[p.index_b][0], placed[p.index_b], request,
                          result)
            if result.min_distance > 0.0:
                lower[k, j] = result.min_distance
                for side, i, point in ((0, p.index_a, result.getNearestPoint1()),
                                       (1, p.index_b, result.getNearestPoint2())):
                    local[k, j, side] = R[k, slot[i]].T @ (np.asarray(point, dtype=float) - t[k, slot[i]])
    ends = _on_meshes(local, pairs, {i: None if hulls[i][1] is None else gm.geometryObjects[i].geometry
                                     for i in hulls})
    sides = np.array([[slot[p.index_a], slot[p.index_b]] for p in pairs], dtype=int).reshape(m, 2)
    rows = np.arange(n)[:, None, None]
    world = np.einsum("nmsij,nmsj->nmsi", R[rows, sides[None]], ends) + t[rows, sides[None]]
    span = np.linalg.norm(world[:, :, 0] - world[:, :, 1], axis=-1)
    found = np.isfinite(lower)
    upper = np.where(found & np.isfinite(span), span + SLACK_M, np.inf)
    return np.where(found, lower - SLACK_M, -np.inf), upper


def _on_meshes(local: np.ndarray, pairs: tuple, meshes: dict[int, Any]) -> np.ndarray:
    """The closest points ``local (N, P, 2, 3)`` of the hulls, each moved onto its mesh (``meshes``: geometry index
    -> coal mesh, or None for a primitive, whose point is on it already): to the nearest point of the
    :data:`NEAR_TRIANGLES` triangles whose centroids are nearest (a point on the mesh; on a face the hull
    shares with the mesh, the point itself). One tree query per mesh for all configurations."""
    from scipy.spatial import cKDTree

    from pinarms.robots.cell.mesh_cover import mesh_arrays

    ends = local.copy()
    index = np.array([[p.index_a, p.index_b] for p in pairs], dtype=int).reshape(-1, 2)
    for i, geo in meshes.items():
        arrays = None if geo is None else mesh_arrays(geo)
        if arrays is None:
            continue
        corners = arrays[0][arrays[1]]  # (T, 3, 3)
        tree = cKDTree(corners.mean(axis=1))
        k = min(NEAR_TRIANGLES, corners.shape[0])
        for side in (0, 1):
            cols = np.flatnonzero(index[:, side] == i)
            if cols.size == 0:
                continue
            block = local[:, cols, side].reshape(-1, 3)
            ok = np.all(np.isfinite(block), axis=1)
            moved = np.full_like(block, np.nan)
            if ok.any():
                near = tree.query(block[ok], k=k)[1].reshape(-1, k)
                moved[ok] = closest_on_triangles(block[ok], corners[near])
            ends[:, cols, side] = moved.reshape(local.shape[0], cols.size, 3)
    return ends


#: Triangles (nearest by centroid) a hull's closest point is projected on, to move it onto the mesh.
NEAR_TRIANGLES = 8


def closest_on_triangles(P: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """The point nearest ``P (m, 3)`` on the union of the triangles ``tri (m, k, 3, 3)`` (each row its own
    ``k`` triangles): the projection on a triangle's plane where it falls inside, else the nearest point of
    its edges; degenerate triangles by their edges."""
    A, B, C = tri[..., 0, :], tri[..., 1, :], tri[..., 2, :]
    X = P[:, None, :]
    n = np.cross(B - A, C - A)
    nn = np.einsum("mki,mki->mk", n, n)
    safe = np.where(nn > 0.0, nn, 1.0)
    proj = X - (np.einsum("mki,mki->mk", X - A, n) / safe)[..., None] * n
    inside = nn > 0.0
    for U, W in ((A, B), (B, C), (C, A)):  # the projection is on the inner side of every edge
        inside &= np.einsum("mki,mki->mk", np.cross(W - U, proj - U), n) >= 0.0
    candidates = [np.where(inside[..., None], proj, np.nan)]
    for U, W in ((A, B), (B, C), (C, A)):
        e = W - U
        ee = np.einsum("mki,mki->mk", e, e)
        s = np.clip(np.einsum("mki,mki->mk", X - U, e) / np.where(ee > 0.0, ee, 1.0), 0.0, 1.0)
        candidates.append(U + s[..., None] * e)
    Q = np.stack(candidates, axis=2).reshape(P.shape[0], -1, 3)  # (m, 4k, 3)
    d = np.linalg.norm(Q - X, axis=-1)
    d = np.where(np.isnan(d), np.inf, d)
    return Q[np.arange(P.shape[0]), np.argmin(d, axis=1)]


def needed(lower: np.ndarray, upper: np.ndarray, exact: np.ndarray, d_mujoco: np.ndarray, mesh: np.ndarray,
           distmax: float, batch: int | None = None) -> np.ndarray:
    """Entries ``(N, P)`` whose exact distance a figure of the re-check may depend on (module doc), among the
    entries not ``exact`` yet; ``lower``/``upper`` equal the exact value where it is known; ``mesh (P,)`` the
    pairs compared one-sided, ``distmax`` [m] the distance from which a pair is not compared. With
    ``batch``: of the entries needed for the smallest distance, the largest excess and the largest gap, only
    the ``batch`` most promising of each (the others may be settled by their exact values)."""
    far, near = lower >= distmax, upper < distmax
    open_ = ~exact
    need = open_ & ((lower <= 0.0) | ~(far | near) | ~mesh[None, :])
    on = near & mesh[None, :]
    tests = [(lower <= upper.min(), -lower)]
    if on.any():
        excess, gap = d_mujoco - lower, upper - d_mujoco
        tests += [(on & (excess >= (d_mujoco - upper)[on].max()), excess),
                  (on & (gap >= (lower - d_mujoco)[on].max()), gap)]
    for test, score in tests:
        test &= open_
        if batch is not None and test.sum() > batch:
            flat = np.flatnonzero(test)
            test = np.zeros_like(test)
            test.flat[flat[np.argsort(-score.flat[flat], kind="stable")[:batch]]] = True
        need |= test
    return need


class _Exact:
    """coal's exact distances of ``pairs`` at ``qs``, as the re-check always computed them:
    ``pin.computeDistance`` on a geometry model of the pairs, cold-started at 1e-10 m."""

    def __init__(self, cell: Any, pairs: tuple, qs: np.ndarray) -> None:
        self.cell, (self.gm, self.gd) = cell, _probe(cell, pairs)
        self.data = cell.model.createData()
        self.q_pin = np.atleast_2d(cell.robot.q_to_pinocchio(qs))

    def __call__(self, which: np.ndarray) -> np.ndarray:
        """Exact distances [m] of the entries ``which (N, P)``, NaN elsewhere."""
        out = np.full(which.shape, np.nan)
        for k in np.flatnonzero(which.any(axis=1)):
            pin.updateGeometryPlacements(self.cell.model, self.data, self.gm, self.gd, self.q_pin[k])
            for j in np.flatnonzero(which[k]):
                out[k, j] = pin.computeDistance(self.gm, self.gd, int(j)).min_distance
        return out


def exact_distances(cell: Any, pairs: tuple, qs: np.ndarray, which: np.ndarray) -> np.ndarray:
    """coal's exact distances [m] of the entries ``which (N, P)`` of ``pairs`` at ``qs`` (NaN elsewhere), as
    the re-check always computed them: ``pin.computeDistance`` on a geometry model of ``pairs``,
    cold-started at 1e-10 m."""
    return _Exact(cell, pairs, qs)(which)


#: Entries settled per round for each of the smallest distance, the largest excess and the largest gap.
BATCH = 8


def settle(lower: np.ndarray, upper: np.ndarray, d_mujoco: np.ndarray, mesh: np.ndarray, distmax: float,
           compute: Callable[[np.ndarray], np.ndarray]) -> PairDistances:
    """Exact values from ``compute(which) -> (N, P)`` (read where ``which``) for every entry :func:`needed`
    says a figure may depend on, the most promising first (:data:`BATCH` per figure and round, so that their
    exact values rule out the rest); the ``lower`` bound elsewhere (module doc)."""
    lower, upper = np.array(lower, dtype=float), np.array(upper, dtype=float)
    exact = np.zeros(lower.shape, dtype=bool)
    while True:
        which = needed(lower, upper, exact, d_mujoco, mesh, distmax, batch=BATCH)
        if not which.any():
            return PairDistances(value=lower.copy(), lower=lower, upper=upper, exact=exact)
        values = compute(which)
        lower, upper = np.where(which, values, lower), np.where(which, values, upper)
        exact |= which


def pinarms_distances(cell: Any, pairs: tuple, qs: np.ndarray, d_mujoco: np.ndarray, mesh: np.ndarray,
                      distmax: float) -> PairDistances:
    """coal's distances of ``pairs`` at ``qs``: exact wherever a figure of the re-check against MuJoCo's
    distances ``d_mujoco (N, P)`` may depend on it, the proven lower bound elsewhere (module doc). ``mesh (P,)``:
    the pairs the re-check compares one-sided (a mesh in MuJoCo); every other pair is computed exactly;
    ``distmax`` [m]: pairs at or beyond it are not compared."""
    lower, upper = pair_bounds(cell, pairs, qs)
    return settle(lower, upper, d_mujoco, mesh, distmax, _Exact(cell, pairs, qs))
