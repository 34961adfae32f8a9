"""Proofs that a pair of collision geometries keeps its distance, or a gap, in every configuration.

Two proofs, from the structure and the shapes only (never from a sample):

**Invariance** (:func:`invariant_pair`). Walk the joints between the two geometries (up from
one to the joint both chains share, down to the other). A shape that is mapped onto itself by
every rotation about a revolute joint's axis (:mod:`.coaxial`: a sphere centred on it, a
cylinder, capsule or cone along it) fills the same space at every angle of that joint: as far
as any distance is concerned it is fixed on the joint's far side too, and the test goes on
with the next joint of the walk. Each shape absorbs joints from its own end of the walk; when
the two absorbed runs cover every joint between them, no joint angle changes their distance
(``d(A, R x) = d(R⁻¹ A, x) = d(A, x)`` for a set ``A`` that ``R`` maps onto itself): it is a
constant, measured once by coal at the neutral configuration.

**Axial gap** (:func:`axial_gap`). When every joint between the two that neither shape absorbs
(as above) is revolute about one common line (collinear axes), each rotation keeps that line
in place, so each shape's
projection onto the line is the same in every configuration. The projection of a shape is an
interval computed from the shape itself (a box's corners, a cylinder's end discs, a cone's base
disc and apex, a sphere, a capsule's segment and radius, a mesh's or convex's vertices; the
local bounding box of any other shape, which contains it). Projection onto a line shortens
no distance, so the gap between the two intervals, if they are disjoint, is a lower bound
of the pair's distance in every configuration (the SCARA upper arm turning about joint 1
above its pedestal).

Prismatic joints stop both proofs. Tolerances: :data:`.coaxial.AXIS_TOL`.
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from pinarms.robots.coaxial import AXIS_TOL, revolute_axis, symmetry

__all__ = ["joint_path", "invariant_pair", "axial_gap", "interval_on_line", "neutral_distance"]

#: [m] subtracted from coal's distance and from an axial gap before it becomes a bound.
SAFETY = 1e-9


def _chain(model: pin.Model, j: int) -> list[int]:
    out = []
    while j > 0:
        out.append(j)
        j = int(model.parents[j])
    return out


def joint_path(model: pin.Model, ja: int, jb: int) -> tuple[list[int], list[int]]:
    """The joints between joint frames ``ja`` and ``jb``: those from ``ja`` up to (not including) the joint both
    chains share, and those from ``jb`` up to it (each list in upward order)."""
    ca, cb = _chain(model, ja), _chain(model, jb)
    common = set(ca) & set(cb)
    return [j for j in ca if j not in common], [j for j in cb if j not in common]


def _absorbed(model: pin.Model, data: pin.Data, geometry, placement: pin.SE3, up: list[int], down: list[int]) -> int:
    """How many joints of the walk (``up`` from the shape's own joint, then ``down`` towards the other shape, that
    list in upward order) the shape turns about its own symmetry axis, counted from its own end."""
    sym = symmetry(geometry, placement)
    steps = [(j, True) for j in up] + [(j, False) for j in reversed(down)]
    n = 0
    for j, upward in steps:
        if sym is None:
            break
        u = revolute_axis(data, j)
        if u is None:
            break
        M = model.jointPlacements[j]
        if upward:  # the shape in joint j's frame: the axis passes through its origin
            point, direction, move = np.zeros(3), u, M
        else:  # the shape in the parent's frame: the axis passes through joint j's origin
            point, direction, move = np.asarray(M.translation), np.asarray(M.rotation) @ u, M.inverse()
        centre, axis = sym
        off = centre - point
        if np.linalg.norm(off - (off @ direction) * direction) > AXIS_TOL:
            break
        if axis is not None and np.linalg.norm(np.cross(axis, direction)) > AXIS_TOL:
            break
        sym = (move.act(centre), None if axis is None else np.asarray(move.rotation) @ axis)
        n += 1
    return n


def invariant_pair(model: pin.Model, data: pin.Data, obj_a, obj_b) -> bool:
    """Whether no joint angle changes the placement of ``obj_a``'s shape relative to ``obj_b``'s (as sets of points):
    every joint between them is absorbed by one shape or the other (module docstring); a prismatic joint
    between them: ``False``."""
    up_a, up_b = joint_path(model, int(obj_a.parentJoint), int(obj_b.parentJoint))
    total = len(up_a) + len(up_b)
    if total == 0:
        return True
    na = _absorbed(model, data, obj_a.geometry, obj_a.placement, up_a, up_b)
    if na >= total:
        return True
    nb = _absorbed(model, data, obj_b.geometry, obj_b.placement, up_b, up_a)
    return na + nb >= total


def neutral_distance(shape_a, a_to_world: pin.SE3, shape_b, b_to_world: pin.SE3) -> float:
    """coal's distance [m] of two shapes at the given placements (``nan`` when coal cannot measure them)."""
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    request.gjk_tolerance = 1e-12
    try:
        d = float(coal.distance(shape_a, coal.Transform3s(a_to_world.rotation, a_to_world.translation),
                                shape_b, coal.Transform3s(b_to_world.rotation, b_to_world.translation), request, result))
    except Exception:  # a pair of shapes coal cannot measure: no constant from it
        return float("nan")
    return d


def _disc(centre: np.ndarray, normal: np.ndarray, radius: float, u: np.ndarray) -> tuple[float, float]:
    c, s = float(centre @ u), radius * float(np.sqrt(max(0.0, 1.0 - float(normal @ u) ** 2)))
    return c - s, c + s


def interval_on_line(geometry, to_world: pin.SE3, u: np.ndarray) -> tuple[float, float]:
    """``(lo, hi)``: the projection of the shape placed at ``to_world`` onto the unit direction ``u`` [m]."""
    R, t = np.asarray(to_world.rotation), np.asarray(to_world.translation)
    z = R[:, 2]
    if isinstance(geometry, coal.Sphere):
        c, r = float(t @ u), float(geometry.radius)
        return c - r, c + r
    if isinstance(geometry, (coal.Cylinder, coal.Cone)):
        h, r = float(geometry.halfLength), float(geometry.radius)
        lo, hi = _disc(t - h * z, z, r, u)
        top = _disc(t + h * z, z, r, u) if isinstance(geometry, coal.Cylinder) else (float((t + h * z) @ u),) * 2
        return min(lo, top[0]), max(hi, top[1])
    if isinstance(geometry, coal.Capsule):
        h, r = float(geometry.halfLength), float(geometry.radius)
        ends = [float((t + s * h * z) @ u) for s in (-1.0, 1.0)]
        return min(ends) - r, max(ends) + r
    if isinstance(geometry, coal.Box):
        half = np.asarray(geometry.halfSide, dtype=float)
        reach = float(np.abs(R.T @ u) @ half)
        return float(t @ u) - reach, float(t @ u) + reach
    points = None
    try:
        points = np.asarray(geometry.vertices(), dtype=float).reshape(-1, 3) if hasattr(geometry, "vertices") else None
    except Exception:  # not a mesh after all: the bounding box below
        points = None
    if points is None or points.size == 0:
        geometry.computeLocalAABB()
        lo, hi = np.asarray(geometry.aabb_local.min_), np.asarray(geometry.aabb_local.max_)
        points = np.array([[x, y, w] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for w in (lo[2], hi[2])])
    s = (points @ R.T + t) @ u
    return float(s.min()), float(s.max())


def axial_gap(model: pin.Model, data: pin.Data, obj_a, a_to_world: pin.SE3, obj_b, b_to_world: pin.SE3) -> float:
    """A proven lower bound [m] of the pair's distance when every joint between them that neither shape absorbs is
    revolute about one line (at least one such joint) and
    their projections onto it are disjoint (module docstring); ``-inf`` otherwise. ``data``: the neutral configuration."""
    up_a, up_b = joint_path(model, int(obj_a.parentJoint), int(obj_b.parentJoint))
    walk = up_a + up_b[::-1]  # from a's joint to b's
    na = _absorbed(model, data, obj_a.geometry, obj_a.placement, up_a, up_b)
    nb = _absorbed(model, data, obj_b.geometry, obj_b.placement, up_b, up_a)
    joints = walk[na: len(walk) - nb]
    if not joints:
        return -np.inf
    line = None
    for j in joints:
        u = revolute_axis(data, j)
        if u is None:
            return -np.inf
        point, direction = np.asarray(data.oMi[j].translation), np.asarray(data.oMi[j].rotation) @ u
        if line is None:
            line = (point, direction)
            continue
        off = point - line[0]
        if (np.linalg.norm(np.cross(direction, line[1])) > AXIS_TOL
                or np.linalg.norm(off - (off @ line[1]) * line[1]) > AXIS_TOL):
            return -np.inf
    lo_a, hi_a = interval_on_line(obj_a.geometry, a_to_world, line[1])
    lo_b, hi_b = interval_on_line(obj_b.geometry, b_to_world, line[1])
    gap = max(lo_b - hi_a, lo_a - hi_b) - SAFETY
    return gap if gap > 0.0 else -np.inf
