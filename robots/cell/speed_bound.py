"""How fast any point of a cell's collision geometry can move: joint levers and approach speeds.

The speed of every point of an arm's collision geometry is at most ``v(t) = Σ_j |q̇_j(t)| · ℓ_j``,
with ``ℓ_j`` the *lever* of joint ``j`` (:func:`joint_levers`: 1 for a prismatic joint; for a
revolute joint, a bound of the distance from its origin to any point of the geometry it
carries, from the joint offsets, strokes and bounding spheres downstream). Two bodies
approach each other at most at ``V(t) = v_1(t) + v_2(t)``, the two fastest arms' bounds (one
moving arm: ``v(t)`` alone): seen from the nearest link both share, a point of either link moves
only by the joints between that link and it, and the two sets of joints are disjoint, so two
links of one arm approach at most at ``v``; an arm and a fixture or a held arm likewise; links
of two arms at most at the sum of theirs. :func:`speed_profile` bounds ``V``
on each step of a time grid (see :mod:`.motion` for the rule and its use), and
:func:`travel_stops` keeps the grid points a sampling needs so that no two neighbours are more
than a given travel apart.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from pinarms.errors import InvalidInput
from pinarms.robots.cell.timeline import ArmMotion

from pinarms.robots.cell.cell_model import CellModel

__all__ = ["joint_levers", "peak_speed", "speed_profile", "travel_stops"]


def joint_levers(cell: "CellModel") -> np.ndarray:
    """``(nq,)`` levers ``ℓ`` [m per rad, or 1 for prismatic]: point speed ≤ ``Σ |q̇_c| ℓ_c``.

    See the module doc; a mimic joint adds ``|scale| ×`` its own lever to its master's. Built once
    per cell (:meth:`Cell.memo`).
    """
    return cell.memo("joint levers", lambda: _levers(cell))


def _levers(cell: "CellModel") -> np.ndarray:
    model, gm = cell.model, cell.collision_model
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    n = model.njoints
    revolute = np.zeros(n, dtype=bool)
    scale = np.ones(n)
    for i in range(1, n):
        jm = model.joints[i]
        s = jm.extract().scaling if "Mimic" in jm.shortname() else 1.0
        scale[i] = s
        motion = np.array(data.joints[i].S).reshape(6, -1)[:, 0]
        revolute[i] = np.linalg.norm(motion[3:]) > 1e-12
    stroke = np.zeros(n)
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    for i in range(1, n):
        if not revolute[i]:
            iq = model.joints[i].idx_q
            stroke[i] = abs(scale[i]) * max(abs(lo[iq]), abs(hi[iq]))
    reach = np.zeros(n)  # bound of |point − origin of joint i| over the geometry joint i carries
    for g in gm.geometryObjects:
        g.geometry.computeLocalAABB()
        lo_g, hi_g = np.asarray(g.geometry.aabb_local.min_), np.asarray(g.geometry.aabb_local.max_)
        own = float(np.linalg.norm(g.placement.act((lo_g + hi_g) / 2.0))) + float(np.linalg.norm((hi_g - lo_g) / 2.0))
        j, acc = int(g.parentJoint), own
        while j > 0:
            reach[j] = max(reach[j], acc)
            acc += float(np.linalg.norm(model.jointPlacements[j].translation)) + stroke[j]
            j = model.parents[j]
    levers = np.zeros(cell.nq)
    for i in range(1, n):
        c = model.joints[i].idx_v
        levers[c] += abs(scale[i]) * (reach[i] if revolute[i] else 1.0)
    return levers


def peak_speed(traj: Any, nq: int, what: str) -> np.ndarray:
    """Peak joint speeds ``(nq,)`` of a trajectory: its exact ``peaks().velocity``, else 4001 samples + 5 %.

    Raises:
        InvalidInput: not ``nq`` finite numbers (``what`` names the trajectory).
    """
    peaks = getattr(traj, "peaks", None)
    if callable(peaks):
        v = np.asarray(peaks().velocity, dtype=float)
    else:
        t = np.linspace(traj.start_time, traj.end_time, 4001)
        v = np.abs(np.asarray(traj.sample(t)[1], dtype=float)).max(axis=0) * 1.05
    if v.shape != (nq,) or not np.all(np.isfinite(v)):
        raise InvalidInput(f"{what}: peak joint speeds must be {nq} finite numbers, got {v!r}")
    return v


def speed_profile(cell: "CellModel", motions: list[ArmMotion], grid: np.ndarray) -> tuple[np.ndarray, float]:
    """Bound of the approach speed ``V`` [m/s] on each step of ``grid`` ``(len(grid) - 1,)``, and the global bound.

    Per arm: the larger end speed plus ``A h / 2`` (``A`` from the exact acceleration peaks),
    never above the cap ``Σ_j max|q̇_j| ℓ_j``; ``V`` is the sum of the two largest over the
    arms (one moving arm: its own), the global bound the sum of the two largest caps.
    """
    levers = joint_levers(cell)
    h = np.diff(grid)
    per_arm = []
    caps_seen = []
    for m in motions:
        arm = cell.arm(m.arm)
        lev = levers[arm.q_slice]
        peak_v = peak_speed(m.trajectory, arm.nq, f"trajectory of arm {m.arm!r}")
        peaks = getattr(m.trajectory, "peaks", None)
        peak_a = np.asarray(peaks().acceleration, dtype=float) if callable(peaks) else None
        v_cap = float(peak_v @ lev)
        caps_seen.append(v_cap)
        qd = np.asarray(m.trajectory.sample(m.local_time(grid))[1], dtype=float).reshape(grid.size, -1)
        v = np.abs(qd) @ lev
        if peak_a is None or not np.all(np.isfinite(peak_a)):
            cell_v = np.full(h.size, v_cap)
        else:
            A = float(np.abs(peak_a) @ lev)
            cell_v = np.minimum(np.maximum(v[:-1], v[1:]) + A * h / 2.0, v_cap)
        # a step holding the trajectory's end (outside [offset, offset + duration]) has v = 0 at
        # both ends and may still straddle a restart: keep the cap where the local time jumps
        tau = m.local_time(grid)
        jump = np.abs(np.diff(tau) - h) > 1e-9 * np.maximum(1.0, h)
        moving = (tau[:-1] > m.trajectory.start_time) | (tau[1:] > m.trajectory.start_time)
        cell_v = np.where(jump & moving, v_cap, cell_v)
        per_arm.append(cell_v)
    if not per_arm:
        return np.zeros(h.size), 0.0
    # the two fastest arms at each step: two links of one arm, or an arm and something held, approach at
    # most at that arm's v; links of two arms at most at the sum of theirs
    fastest = np.sort(np.vstack(per_arm + [np.zeros(h.size)]), axis=0)
    caps = sorted(caps_seen)
    return fastest[-1] + fastest[-2], float(sum(caps[-2:]))


def travel_stops(budget: np.ndarray, step: float) -> np.ndarray:
    """Indices ``(k,)`` (sorted, unique) of the grid points kept so that between two kept neighbours the
    travel bound grows by at most ``step``, where it can: ``budget (N,)`` is the cumulative travel bound
    [m] at the grid points (non-decreasing, ``budget[0] = 0``). Greedy from the start: the last point
    before the budget passes ``step`` is kept (a single grid interval longer than ``step`` keeps both
    its ends); the first and last points always."""
    keep = [0]
    for i in range(1, budget.size):
        if budget[i] - budget[keep[-1]] > step * (1.0 + 1e-12):
            keep.append(i - 1)
    if keep[-1] != budget.size - 1:
        keep.append(budget.size - 1)
    return np.unique(np.asarray(keep, dtype=int))
