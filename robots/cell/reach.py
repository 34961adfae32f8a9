"""Tighter proven bounds for the ``"out of reach"`` pairs: the solid cylinder an arm's first joint sweeps.

An arm whose first joint is revolute turns everything it carries about one fixed axis. In
that joint's frame, a geometry's points keep their height ``z`` along the axis and their
distance ``ρ`` from it whatever the first joint does, so over every configuration the
geometry stays inside the solid cylinder ``z_lo ≤ z ≤ z_hi, ρ ≤ ρ_max`` about the axis:

- a geometry carried by the first joint itself: its bounding box's 8 corners give
  ``z_lo, z_hi, ρ_max`` exactly (``z`` is linear and ``ρ`` convex, so the extremes are at
  corners);
- a geometry further down: its points stay within ``R`` of the next joint's origin ``c``
  (fixed in the first joint's frame; ``R`` the joint offsets, strokes and bounding sphere
  below, by the triangle inequality), so ``z ∈ a·c ± R`` and ``ρ ≤ |c − (a·c) a| + R``.

coal's exact distance between that cylinder and a fixture's own shape (or another arm's
cylinder) is a proven lower bound of the pair's distance; the classification keeps the
larger of it and the reach-ball gap (:mod:`.pairs`). Computed only for pairs already proven
apart whose ball gap is below :data:`TIGHTEN_BELOW` (the bounds that can matter to a check).
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

__all__ = ["root_cylinders", "tighter_bound", "TIGHTEN_BELOW"]

#: Ball gaps [m] below which the cylinder bound is computed too.
TIGHTEN_BELOW = 0.25
_EPS = 1e-9  # [m] subtracted from coal's distances; also the thinnest cylinder


def _frame_with_z(axis: np.ndarray) -> np.ndarray:
    z = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _revolute_axis(model: pin.Model, data: pin.Data, j: int) -> np.ndarray | None:
    if "Mimic" in model.joints[j].shortname():
        return None
    motion = np.array(data.joints[j].S).reshape(6, -1)[:, 0]
    if np.linalg.norm(motion[:3]) > 1e-12 or np.linalg.norm(motion[3:]) < 1e-12:
        return None  # prismatic or helical: no fixed-axis sweep
    return motion[3:] / np.linalg.norm(motion[3:])


def root_cylinders(model: pin.Model, data: pin.Data, objs: list, joint: list[int], ball_radius: np.ndarray) -> list:
    """Per geometry, ``(coal.Cylinder, coal.Transform3s)`` in the world containing every place it can be, or ``None``."""
    out: list = [None] * len(objs)
    for k, g in enumerate(objs):
        j = joint[k]
        if j == 0:
            continue
        chain = [j]
        while model.parents[chain[-1]] > 0:
            chain.append(model.parents[chain[-1]])
        root = chain[-1]
        axis = _revolute_axis(model, data, root)
        if axis is None:
            continue
        if j == root:
            g.geometry.computeLocalAABB()
            lo, hi = np.asarray(g.geometry.aabb_local.min_), np.asarray(g.geometry.aabb_local.max_)
            corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
            pts = corners @ g.placement.rotation.T + g.placement.translation  # in the root joint's frame
            z = pts @ axis
            rho = np.linalg.norm(pts - np.outer(z, axis), axis=1)
            z_lo, z_hi, rho_max = float(z.min()), float(z.max()), float(rho.max())
        else:
            c = np.asarray(model.jointPlacements[chain[-2]].translation)
            R = float(ball_radius[k]) - float(np.linalg.norm(c))
            zc = float(c @ axis)
            z_lo, z_hi = zc - R, zc + R
            rho_max = float(np.linalg.norm(c - zc * axis)) + R
        M = data.oMi[root]
        axis_w = M.rotation @ axis
        center = M.translation + axis_w * (z_lo + z_hi) / 2.0
        shape = coal.Cylinder(max(rho_max, _EPS), max(z_hi - z_lo, _EPS))
        out[k] = (shape, coal.Transform3s(_frame_with_z(axis_w), center))
    return out


def _distance(shape_a, a_to_world, shape_b, b_to_world) -> float:
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    request.gjk_tolerance = 1e-10
    try:
        d = float(coal.distance(shape_a, a_to_world, shape_b, b_to_world, request, result))
    except Exception:  # a pair of shapes coal cannot measure: no bound from it
        return -np.inf
    return d - _EPS if np.isfinite(d) else -np.inf


def tighter_bound(gap: float, a: int, b: int, objs: list, joint: list[int], ball_center, ball_radius,
                  placement_of, cylinders: list) -> float:
    """The largest proven lower bound of the pair's distance: ``gap`` (reach balls), the cylinders, a ball vs a fixture's shape."""
    if gap >= TIGHTEN_BELOW:
        return gap
    best = gap
    if joint[a] > 0 and joint[b] > 0:
        if cylinders[a] is not None and cylinders[b] is not None:
            best = max(best, _distance(*cylinders[a], *cylinders[b]))
        return best
    m, s = (a, b) if joint[a] > 0 else (b, a)
    shape_to_world = placement_of(s)
    if not isinstance(objs[s].geometry, coal.Box):  # against a box the ball gap is already exact
        ball = coal.Transform3s(np.eye(3), np.asarray(ball_center[m], dtype=float))
        best = max(best, _distance(coal.Sphere(float(ball_radius[m])), ball, objs[s].geometry, shape_to_world))
    if cylinders[m] is not None:
        best = max(best, _distance(*cylinders[m], objs[s].geometry, shape_to_world))
    return best
