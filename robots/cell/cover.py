"""A conservative sphere cover of every collision geometry of a cell, and compiled screens on it.

Every geometry of :attr:`Cell.collision_model` gets a few spheres, fixed in its parent
joint's frame, whose union **contains** the geometry (:func:`geometry_spheres`):

- a sphere: itself;
- a cylinder (radius ``r``, half length ``h``): ``k`` slices of height ``2h/k`` along its
  axis, each inside the sphere at its centre of radius ``√(r² + (h/k)²)``;
- a box: ``k`` slices along its longest side, each inside its circumscribed sphere;
- a mesh (coal ``BVHModel``): at most :data:`MESH_SPHERES` spheres on the axes of its
  cylinder-like parts, holding every piece of its triangles (:func:`.mesh_cover.mesh_spheres`);
- a shape with neither (a convex without triangles, a plane ...): the sphere about its
  local bounding box.

A static box, cylinder or sphere (parent joint the world: the fixtures) is also kept
exactly: a sphere's distance to it is computed in closed form, not through its cover; a
static mesh (an arm's base) is kept exactly as the smaller of the box and the cylinders
holding its vertices (:func:`.mesh_cover.static_primitive`). A moving cylinder, and a moving
mesh whose holding cylinder is tight (:data:`CYLINDER_SHARE`, :data:`TURNING_SHARE`), is
taken exactly against the other geometry's spheres (:func:`geometry_segments`). Any other moving
mesh is also held by thin cylinders, each with the sphere of its slice (:func:`.mesh_cover.mesh_parts`):
against a static box its bound is the least over the cylinders of the larger of its sphere's
distance and the gaps of the cylinder's projections on the box's axes and on the line to the box's
nearest point (:func:`.box_kernel.held_low`; the flat end of a housing over a table, a flaring
housing beside a pedestal's edge).

Two geometries of one arm whose relative placement depends on at most two revolute joints, one
of them a mesh, that the spheres leave loose (the UR5's forearm and wrist_2, wrist_1 and wrist_3,
its base and upper arm) also get a **distance table** (:mod:`.pair_tables`): a proven lower
bound of their distance over cells of those joints' angles. Such a pair's bound is the larger
of its table's and its cover's (:data:`TABLES`).

The screen (:meth:`Cover.screen`) answers, for a batch of cell configurations and a
threshold per pair, which configurations are **proven** to keep every pair farther apart
than its threshold: the distance between two covers (or a cover and an exact fixture) is a
lower bound of the geometries' distance. The rest is *inconclusive*: the exact check (coal)
decides them. Forward kinematics of the batch and the screen run compiled (numba, cached
like :mod:`pinarms.robots.ik._kernel`). Distances in m, the world frame.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from pinarms.robots.cell.cell_model import CellModel

if TYPE_CHECKING:
    import pinocchio as pin

from pinarms.robots.cell.cover_kernel import excess_kernel, screen_kernel
from pinarms.robots.cell.mesh_cover import mesh_arrays, mesh_cylinder, static_primitive
from pinarms.robots.cell.mesh_cover_cache import cached_mesh_parts
from pinarms.robots.cell.pair_tables import PairTables, no_tables, pair_tables

__all__ = [
    "CYLINDER_SHARE",
    "MAX_SPHERES",
    "MESH_SPHERES",
    "TABLES",
    "TURNING_SHARE",
    "Cover",
    "PairSet",
    "geometry_segments",
    "geometry_spheres",
    "link_cover",
    "pair_arrays",
    "pairs_for",
    "motion_pairs",
]

#: Most spheres per box geometry.
MAX_SPHERES = 12
#: Spheres per mesh (:func:`.mesh_cover.mesh_spheres`).
MESH_SPHERES = 16
_MESH_CACHE: dict = {}
#: Whether :func:`link_cover` gives pairs close in the chain their distance tables (:mod:`.pair_tables`).
TABLES = True
_EXACT_NONE, _EXACT_BOX, _EXACT_CYLINDER, _EXACT_SPHERE = 0, 1, 2, 3
#: How a moving geometry's segments hold it (the kernels' ``cyl``): one cylinder, taken exactly against the
#: other geometry's spheres and through its projections against static boxes; or a mesh's slice cylinders,
#: each with its slice's sphere (``spart``), whose union holds it: against a static box only.
_HELD_ONE, _HELD_PARTS = 1, 2


def pairs_for(cell: CellModel, clearance: float) -> tuple:
    """The pairs a check at ``clearance`` [m] must look at: ``cell.pairs_for(clearance)`` where the
    cell has it (pairs proven farther apart than the clearance left out), else every checked pair."""
    chooser = getattr(cell, "pairs_for", None)
    return tuple(cell.pairs) if chooser is None else tuple(chooser(float(clearance)))


def motion_pairs(cell: CellModel, widest: float, planned: set, self_margin: float, margin: float) -> list:
    """The pairs a motion check of the ``planned`` arms looks at: :func:`pairs_for` ``(widest)`` (its coarsest
    screen) with a planned arm, less the ``constant`` pairs proven at least their margin apart (``self_margin``
    for one arm's links, else ``margin``): their distance never changes, so no motion and no screen raised for
    the travel can bring them closer. A constant pair below its margin stays: every state fails on it."""
    bound = {frozenset((a.index_a, a.index_b)): a.distance_bound for a in getattr(cell, "allowed", ())
             if a.reason == "constant"}
    out = []
    for p in pairs_for(cell, widest):
        if p.owner_a not in planned and p.owner_b not in planned:
            continue
        d = bound.get(frozenset((p.index_a, p.index_b)))
        if d is not None and d >= (self_margin if p.kind == "self" else margin):
            continue
        out.append(p)
    return out


def _slices(length: float, width: float) -> int:
    return int(min(MAX_SPHERES, max(1, math.ceil(1.5 * length / max(width, 1e-6)))))


def _mesh_cover(geo: Any) -> tuple[np.ndarray, ...] | None:
    """:func:`.mesh_cover.mesh_parts` of a mesh (kept per content, and on disk: :mod:`.mesh_cover_cache`), or None
    for a shape without triangles."""
    got = mesh_arrays(geo)
    if got is None:
        return None
    key = (got[0].tobytes(), got[1].tobytes(), MESH_SPHERES)
    if key not in _MESH_CACHE:
        _MESH_CACHE[key] = cached_mesh_parts(*got, MESH_SPHERES)
    return _MESH_CACHE[key]


def _mesh_spheres(geo: Any) -> tuple[np.ndarray, np.ndarray] | None:
    got = _mesh_cover(geo)
    return None if got is None else got[:2]


def _mesh_parts(geo: Any) -> tuple[np.ndarray, ...] | None:
    """The slice cylinders ``(a, b, radius, sphere)`` of a mesh (:func:`.mesh_cover.mesh_parts`), or None."""
    got = _mesh_cover(geo)
    return None if got is None else got[2:]


def geometry_spheres(geometry_object: pin.GeometryObject) -> tuple[np.ndarray, np.ndarray]:
    """Spheres ``(centres (k, 3) in the parent joint's frame [m], radii (k,) [m])`` whose union
    contains the geometry of a Pinocchio ``GeometryObject`` (module docstring)."""
    geo = geometry_object.geometry
    kind = type(geo).__name__
    if kind == "Sphere":
        c, r = np.zeros((1, 3)), np.array([float(geo.radius)])
    elif kind == "Cylinder" or kind == "Capsule":
        r, h = float(geo.radius), float(geo.halfLength)
        k = int(min(2 * MAX_SPHERES, max(1, math.ceil(3.2 * h / max(r, 1e-6)))))  # radius at most 5 % over r
        z = -h + (2.0 * np.arange(k) + 1.0) * h / k
        if kind == "Capsule":  # the end caps: spheres of radius r at the ends of the axis
            z = np.concatenate([z, [-h, h]])
            rad = np.concatenate([np.full(k, math.hypot(r, h / k)), [r, r]])
        else:
            rad = np.full(k, math.hypot(r, h / k))
        c, r = np.column_stack([np.zeros(z.size), np.zeros(z.size), z]), rad
    elif kind == "Box":
        half = np.asarray(geo.halfSide, dtype=float)
        order = np.argsort(half)
        axis = int(order[-1])
        k = _slices(2.0 * half[axis], 2.0 * half[order[-2]])
        z = -half[axis] + (2.0 * np.arange(k) + 1.0) * half[axis] / k
        c = np.zeros((k, 3))
        c[:, axis] = z
        slab = half.copy()
        slab[axis] = half[axis] / k
        r = np.full(k, float(np.linalg.norm(slab)))
    else:
        got = _mesh_spheres(geo)
        if got is None:
            geo.computeLocalAABB()
            lo, hi = np.asarray(geo.aabb_local.min_, dtype=float), np.asarray(geo.aabb_local.max_, dtype=float)
            got = (0.5 * (lo + hi))[None], np.array([0.5 * float(np.linalg.norm(hi - lo))])
        c, r = got
    M = geometry_object.placement
    centers = np.asarray(c, dtype=float) @ np.asarray(M.rotation).T + np.asarray(M.translation)
    # a hair of slack over floating-point rounding of the placements
    return centers, np.asarray(r, dtype=float) * (1.0 + 1e-9) + 1e-9


#: A moving mesh is screened through the cylinder holding it (exact against the other geometry's spheres,
#: its flat ends against boxes) when that cylinder is at most this many times its box's volume, and
#: :data:`TURNING_SHARE` times when its axis is its joint's axis (a housing turning about its own axis,
#: like the UR5's shoulder over its base).
CYLINDER_SHARE = 1.0
TURNING_SHARE = 1.3


def _mesh_cylinder(geometry_object: pin.GeometryObject, joint_axis: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, float] | None:
    """The axis ends (in the geometry's frame) and radius [m] of the cylinder holding a moving mesh where it
    is used (:data:`CYLINDER_SHARE`; ``joint_axis``: the parent joint's axis in its frame); else None."""
    if int(geometry_object.parentJoint) == 0:
        return None
    got = mesh_arrays(geometry_object.geometry)
    if got is None:
        return None
    a, b, radius, share = mesh_cylinder(got[0])
    if share <= CYLINDER_SHARE:
        return a, b, radius
    if joint_axis is not None and share <= TURNING_SHARE:
        u = np.asarray(geometry_object.placement.rotation) @ (b - a)
        if abs(float(u @ np.asarray(joint_axis, dtype=float))) >= (1.0 - 1e-6) * float(np.linalg.norm(u)):
            return a, b, radius
    return None


def geometry_segments(geometry_object: pin.GeometryObject, joint_axis: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The axis ``(end a (1, 3), end b (1, 3) in the parent joint's frame [m], radius (1,) [m])`` of a
    cylinder, or of the cylinder holding a moving mesh where it is smaller than the mesh's box (taken
    exactly against the other geometry's spheres; ``joint_axis``: the parent joint's unit axis in its
    frame, :data:`TURNING_SHARE`); another moving mesh: its slices' cylinders (:func:`.mesh_cover.mesh_parts`,
    screened against static boxes, :data:`_HELD_PARTS`); other geometries: their spheres as zero-length axes
    (unused by the screen)."""
    geo = geometry_object.geometry
    M = geometry_object.placement
    R, p = np.asarray(M.rotation), np.asarray(M.translation)
    if type(geo).__name__ == "Cylinder":
        h = float(geo.halfLength)
        a, b = p - h * R[:, 2], p + h * R[:, 2]
        return a[None], b[None], np.array([float(geo.radius) * (1.0 + 1e-9) + 1e-9])
    held = _mesh_cylinder(geometry_object, joint_axis)
    if held is not None:
        a, b, radius = held
        return (R @ a + p)[None], (R @ b + p)[None], np.array([radius * (1.0 + 1e-9) + 1e-9])
    parts = _mesh_parts(geo) if int(geometry_object.parentJoint) > 0 else None
    if parts is not None:
        a, b, radius, _ = parts
        return a @ R.T + p, b @ R.T + p, radius * (1.0 + 1e-9) + 1e-9
    c, r = geometry_spheres(geometry_object)
    return c, c.copy(), r


@dataclass(frozen=True, eq=False)
class Cover:
    """The sphere cover of a cell's geometries (module docstring).

    Attributes:
        start: ``(G+1,)`` spheres of geometry ``g`` are ``start[g]:start[g+1]``.
        joint: ``(S,)`` parent joint of each sphere; ``center``: ``(S, 3)`` in that joint's
            frame [m]; ``radius``: ``(S,)`` [m].
        exact: ``(G,)`` 0: the geometry is screened through its spheres; 1, 2, 3: a static
            box, cylinder or sphere screened exactly, ``frame_R (G, 3, 3)``, ``frame_p (G, 3)``
            its world placement and ``size (G, 3)`` its half sides / (radius, half length, 0)
            / (radius, 0, 0).
    """

    start: np.ndarray
    joint: np.ndarray
    center: np.ndarray
    radius: np.ndarray
    exact: np.ndarray
    frame_R: np.ndarray
    frame_p: np.ndarray
    size: np.ndarray
    fk: tuple
    segments: tuple = ()
    bounds: tuple = ()
    tables: PairTables = field(default_factory=no_tables)

    def world_centers(self, Q: np.ndarray) -> np.ndarray:
        """Sphere centres ``(N, S, 3)`` in the world for cell configurations ``Q (N, nq)`` (numpy)."""
        from pinarms.robots.cell.cover_kernel import centers_kernel

        Q = np.ascontiguousarray(np.atleast_2d(Q), dtype=float)
        out = np.empty((Q.shape[0], self.joint.size, 3))
        centers_kernel(Q, self.fk, self.joint, self.center, out)
        return out

    def prepare(self, pair_a: np.ndarray, pair_b: np.ndarray) -> PairSet:
        """The pairs ``(pair_a[k], pair_b[k])`` (geometry indices) grouped for :meth:`screen`: by the two
        links (a fixture's geometry alone), each link with one sphere holding its geometries."""
        pair_a = np.asarray(pair_a, dtype=np.int64)
        pair_b = np.asarray(pair_b, dtype=np.int64)
        bjoint, bc, br = self.bounds
        G = br.size
        key = np.where(bjoint > 0, bjoint, -np.arange(G) - 1)
        members: dict[int, list[int]] = {}
        for g in np.unique(np.concatenate([pair_a, pair_b])):
            members.setdefault(int(key[g]), []).append(int(g))
        hjoint, hc, hr, where = list(bjoint), list(bc), list(br), {}
        for k, gs in members.items():
            c, r = bc[gs], br[gs]
            centre = 0.5 * ((c - r[:, None]).min(axis=0) + (c + r[:, None]).max(axis=0))
            where[k] = len(hr)
            hjoint.append(int(bjoint[gs[0]]))
            hc.append(centre)
            hr.append(float((np.linalg.norm(c - centre, axis=1) + r).max()) * (1.0 + 1e-12))
        # an exact fixture goes second in its pairs (its link sphere is the one tested against it)
        swap = (self.exact[pair_a] != 0) & (self.exact[pair_b] == 0)
        pair_a, pair_b = np.where(swap, pair_b, pair_a), np.where(swap, pair_a, pair_b)
        ka, kb = key[pair_a], key[pair_b]
        order = np.lexsort((kb, ka))
        ka, kb = ka[order], kb[order]
        first = np.flatnonzero(np.concatenate([[True], (ka[1:] != ka[:-1]) | (kb[1:] != kb[:-1])])) if order.size \
            else np.zeros(0, dtype=int)
        fixed = np.array([-k - 1 if k < 0 and self.exact[-k - 1] != 0 else -1 for k in kb[first]], dtype=np.int64)
        return PairSet(pair_a[order], pair_b[order], order, np.append(first, order.size).astype(np.int64),
                       np.array([where[int(k)] for k in ka[first]], dtype=np.int64),
                       np.array([where[int(k)] for k in kb[first]], dtype=np.int64), fixed,
                       np.array(hjoint, dtype=np.int64), np.ascontiguousarray(np.array(hc).reshape(-1, 3)),
                       np.array(hr), self.tables.of_pairs(pair_a[order], pair_b[order]))

    def screen(self, Q: np.ndarray, pairs: PairSet, threshold: np.ndarray, stop: bool = False) -> np.ndarray:
        """``(N,)`` bool: True where the cover **proves** every pair of ``pairs`` (:meth:`prepare`)
        farther apart than its ``threshold`` [m] (in the order the pairs were given) at cell
        configuration ``Q[i]``; False: inconclusive (the exact check decides). ``stop``: the rows
        after the first inconclusive one are not screened (reported False)."""
        Q = np.ascontiguousarray(np.atleast_2d(Q), dtype=float)
        out = np.zeros(Q.shape[0], dtype=np.bool_)
        if Q.shape[0] == 0:
            return out
        if pairs.pair_a.size == 0:
            out[:] = True
            return out
        screen_kernel(Q, self.fk, self.kernel_arrays(), self.group_arrays(pairs, threshold), self.work(pairs),
                      bool(stop), out)
        return out

    def pair_screen(self, Q: np.ndarray, pairs: PairSet, threshold: np.ndarray) -> np.ndarray:
        """``(N, P)`` bool: True where the cover **proves** pair ``k`` of ``pairs`` (:meth:`prepare`; in the
        order the pairs were given) farther apart than its ``threshold[k]`` [m] at cell configuration
        ``Q[i]``; False: inconclusive (the exact check decides that pair). A row all True is what
        :meth:`screen` calls proven. :meth:`pair_screener` for many calls with one threshold."""
        return self.pair_screener(pairs, threshold)(Q)

    def pair_screener(self, pairs: PairSet, threshold: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
        """:meth:`pair_screen` with its arrays prepared once: a function of ``Q`` alone (one state costs
        the kernel's few µs, not the tens of µs of matching its arguments' types at every call)."""
        from pinarms.robots.cell._pair_kernel import pair_screener

        return pair_screener(self, pairs, threshold)

    def kernel_arrays(self) -> tuple:
        """The cover's arrays in the order of the compiled kernels (:func:`.cover_kernel.excess_one`)."""
        return (self.joint, self.center, self.radius, self.start, self.exact, self.frame_R, self.frame_p, self.size,
                *self.segments[:6], self.tables.arrays(), self.segments[6])

    def group_arrays(self, pairs: PairSet, threshold: np.ndarray) -> tuple:
        """The pair groups of ``pairs`` with their thresholds [m] (given in the pairs' order), for the kernels."""
        t = np.ascontiguousarray(np.asarray(threshold, dtype=float)[pairs.order])
        group_t = np.maximum.reduceat(t, pairs.group_start[:-1]) if t.size else np.zeros(0)
        return (pairs.hjoint, pairs.hcenter, pairs.hrad, pairs.group_start, pairs.group_a, pairs.group_b,
                pairs.group_fixed, group_t, pairs.pair_a, pairs.pair_b, t, pairs.table)

    def work(self, pairs: PairSet) -> tuple:
        """Scratch arrays of one kernel call (joint frames, world centres)."""
        nj = self.fk[0].shape[0]
        return (np.empty((nj, 3, 3)), np.empty((nj, 3)), np.empty((self.joint.size, 3)),
                np.empty((self.segments[0].size, 3)), np.empty((self.segments[0].size, 3)),
                np.empty((pairs.hjoint.size, 3)))

    def excess(self, Q: np.ndarray, pairs: PairSet, threshold: np.ndarray, cap: float = np.inf,
               floor: float = -np.inf) -> np.ndarray:
        """``(N,)`` lower bounds [m] of ``min_k (d_k − threshold_k)`` over ``pairs`` at cell configurations
        ``Q`` (capped at ``cap``; a row whose bound falls below ``floor`` stops early with some value
        below it). Positive: the cover proves every pair farther apart than its threshold."""
        Q = np.ascontiguousarray(np.atleast_2d(Q), dtype=float)
        out = np.empty(Q.shape[0])
        if pairs.pair_a.size == 0:
            out[:] = cap
            return out
        excess_kernel(Q, self.fk, self.kernel_arrays(), self.group_arrays(pairs, threshold), float(cap),
                      float(floor), self.work(pairs), out)
        return out


@dataclass(frozen=True, eq=False)
class PairSet:
    """Pairs of geometries grouped by link for :meth:`Cover.screen` (built by :meth:`Cover.prepare`)."""

    pair_a: np.ndarray
    pair_b: np.ndarray
    order: np.ndarray
    group_start: np.ndarray
    group_a: np.ndarray
    group_b: np.ndarray
    group_fixed: np.ndarray
    hjoint: np.ndarray
    hcenter: np.ndarray
    hrad: np.ndarray
    table: np.ndarray


def _fk_arrays(cell: CellModel) -> tuple:
    bp = cell.batched_placements
    return (np.asarray(bp.parent, dtype=np.int64), np.asarray(bp.index, dtype=np.int64), bp.scale.copy(),
            bp.offset.copy(), bp.revolute.copy(), bp.axis.copy(), bp.M_R.copy(), bp.M_p.copy())


def link_cover(cell: CellModel) -> Cover:
    """The :class:`Cover` of every geometry of ``cell`` (built once, kept with the cell: :meth:`Cell.memo`)."""
    return cell.memo("sphere cover", lambda: _build_cover(cell))


def _build_cover(cell: CellModel) -> Cover:
    objs = list(cell.collision_model.geometryObjects)
    G = len(objs)
    start = np.zeros(G + 1, dtype=np.int64)
    joints, centers, radii = [], [], []
    exact = np.zeros(G, dtype=np.int64)
    frame_R = np.tile(np.eye(3), (G, 1, 1))
    frame_p = np.zeros((G, 3))
    size = np.zeros((G, 3))
    for g, obj in enumerate(objs):
        c, r = geometry_spheres(obj)
        joints.append(np.full(r.size, int(obj.parentJoint), dtype=np.int64))
        centers.append(c)
        radii.append(r)
        start[g + 1] = start[g] + r.size
        if obj.parentJoint == 0:
            exact[g], frame_R[g], frame_p[g], size[g] = _static_shape(obj)
    cover = Cover(start, np.concatenate(joints), np.ascontiguousarray(np.concatenate(centers)),
                  np.concatenate(radii), exact, np.ascontiguousarray(frame_R), frame_p, size, _fk_arrays(cell),
                  _segments(objs, _fk_arrays(cell)[5], start), _bounds(objs, start, centers, radii))
    if TABLES:  # an arm's own pairs close in the chain that the spheres leave loose get distance tables
        own = [(p.index_a, p.index_b) for p in cell.pairs if p.kind == "self"]
        cover = replace(cover, tables=pair_tables(cell, own, cover))
    return cover


def _static_shape(obj: Any) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """``(kind, world rotation, world centre, size)`` of a static geometry screened exactly (kind 0: not,
    screened through its spheres): a box, cylinder or sphere itself; a mesh the smaller of the box and the
    cylinders holding its vertices (:func:`.mesh_cover.static_primitive`)."""
    geo, M = obj.geometry, obj.placement
    R, p = np.asarray(M.rotation, dtype=float), np.asarray(M.translation, dtype=float)
    kind = type(geo).__name__
    if kind == "Box":
        return _EXACT_BOX, R, p, np.asarray(geo.halfSide, dtype=float)
    if kind == "Cylinder":
        return _EXACT_CYLINDER, R, p, np.array([geo.radius, geo.halfLength, 0.0])
    if kind == "Sphere":
        return _EXACT_SPHERE, R, p, np.array([geo.radius, 0.0, 0.0])
    got = mesh_arrays(geo)
    if got is None:
        return 0, np.eye(3), np.zeros(3), np.zeros(3)
    shape, R_local, centre, half = static_primitive(got[0])
    # a hair of slack over floating-point rounding of the placement
    half = np.where(np.arange(3) < (3 if shape == "Box" else 2), half * (1.0 + 1e-9) + 1e-9, 0.0)
    return (_EXACT_BOX if shape == "Box" else _EXACT_CYLINDER), R @ R_local, R @ centre + p, half


def _segments(objs: list, axes: np.ndarray, start: np.ndarray) -> tuple:
    """The cover's cylinders (:func:`geometry_segments`; ``axes (nj, 3)``: each joint's axis in its frame) and,
    last, the cover spheres ``spart (n, 2)`` each cylinder holds with (its slice's, else all its geometry's)."""
    turning = [axes[int(o.parentJoint)] if int(o.parentJoint) > 0 else None for o in objs]
    parts = [geometry_segments(obj, u) for obj, u in zip(objs, turning)]
    sstart = np.concatenate([[0], np.cumsum([r.size for _, _, r in parts])]).astype(np.int64)
    sjoint = np.concatenate([np.full(r.size, int(o.parentJoint), dtype=np.int64) for o, (_, _, r) in zip(objs, parts)])
    cyl = [_HELD_ONE if type(o.geometry).__name__ == "Cylinder" or _mesh_cylinder(o, u) is not None
           else _HELD_PARTS if int(o.parentJoint) > 0 and _mesh_parts(o.geometry) is not None else 0
           for o, u in zip(objs, turning)]
    spart = []  # a mesh's slice cylinder k holds with its sphere k; one cylinder with all the geometry's spheres
    for g in range(len(objs)):
        n = int(sstart[g + 1] - sstart[g])
        spart += ([(start[g] + i, start[g] + i + 1) for i in _mesh_parts(objs[g].geometry)[3]]
                  if cyl[g] == _HELD_PARTS else [(start[g], start[g + 1])] * n)
    return (sjoint, np.ascontiguousarray(np.concatenate([a for a, _, _ in parts])),
            np.ascontiguousarray(np.concatenate([b for _, b, _ in parts])), np.concatenate([r for _, _, r in parts]),
            sstart, np.array(cyl, dtype=np.int64), np.array(spart, dtype=np.int64).reshape(-1, 2))


def _bounds(objs: list, start: np.ndarray, centers: list, radii: list) -> tuple:
    """One sphere per geometry holding all its cover spheres (so the geometry)."""
    G = len(objs)
    bc = np.zeros((G, 3))
    br = np.zeros(G)
    for g in range(G):
        c, r = centers[g], radii[g]
        bc[g] = 0.5 * ((c - r[:, None]).min(axis=0) + (c + r[:, None]).max(axis=0))
        br[g] = float((np.linalg.norm(c - bc[g], axis=1) + r).max()) * (1.0 + 1e-12)
    return np.array([int(o.parentJoint) for o in objs], dtype=np.int64), bc, br


def pair_arrays(pairs: Sequence[Any]) -> tuple[np.ndarray, np.ndarray]:
    """Geometry indices ``(pair_a, pair_b)`` of :class:`CollisionPair` s, for :meth:`Cover.screen`."""
    return (np.array([p.index_a for p in pairs], dtype=np.int64), np.array([p.index_b for p in pairs], dtype=np.int64))
