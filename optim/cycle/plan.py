"""The pick-and-place cycle: pick, lift, transfer, lower, place, and back, time-optimal.

What a packing-line engineer optimises is not one move but the whole cycle::

    pick ─lift─▶ above pick ─(via …)─▶ above place ─lower─▶ place      (move "to place")
    place ─lift─▶ above place ─(… via)─▶ above pick ─lower─▶ pick      (move "to pick")

with the gripper closing at the pick and opening at the place (``dwell`` s each).
:func:`plan_cycle` turns a :class:`PickPlace` spec into

* the Cartesian waypoints of one full cycle (tcp → base poses, m): the lift points are the
  pick and place poses moved ``lift`` m along the base's +z (vertical approach/retreat);
* the joint via points, by IK on ONE branch (:func:`planning.joint_waypoints`: each
  waypoint keeps the previous waypoint's branch; without ``q_start`` the pick's solutions
  are tried in turn until one keeps a single branch through every waypoint, see
  :attr:`CycleResult.branches`). The return move runs through the same joint via points
  in reverse, so the cycle closes exactly;
* the time-optimal timing of each move (:func:`optim.minimize_time` under the given
  velocity/acceleration/jerk limits): at rest at the pick and the place, moving through the
  lift points and the transfer vias (``"multi-quintic"`` uses the sign-of-slopes via
  velocities, ``velocities="heuristic"``: a joint keeps moving through a via point unless it
  turns back there; ``"quintic-bspline"`` passes them smoothly by construction);
* the joint trajectory of the whole cycle (dwell at pick, move to place, dwell at place,
  move to pick), its exact peaks against the limits, the cycle time and picks per minute;
* how straight the joint-space moves are: the largest distance (m) of the tcp from the
  straight vertical segments pick ↔ above pick and place ↔ above place while it travels
  them, sampled with batched FK. A joint-space move is straight only where the
  kinematics make it so (a SCARA's vertical axis, a gantry); on a six-axis arm it bows.

Units: m, rad, s (rad/s … or m/s … for prismatic joints).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms.optim.caps import LIFT_STEP_RANGE, MAX_CLEARANCE, MIN_MARGIN, number_setting
from pinarms.optim.cycle.spec import (  # noqa: F401  (the spec and result, re-exported here)
    CYCLE_APPROACHES,
    CYCLE_KINDS,
    LINE_NAMES,
    LINE_SAMPLES,
    CycleResult,
    PickPlace,
    _hold,
    _line_deviation,
    _segment_distance,
)
from pinarms.optim.errors import InvalidLimits, InvalidSettings
from pinarms.optim.ga.problem import check_limit
from pinarms.optim.timing.segments import minimize_time
from pinarms.planning import joint_waypoints
from pinarms.robots.errors import InvalidInput, UnreachableTarget
from pinarms.robots.ties import argmin_tied

__all__ = ["CYCLE_KINDS", "CYCLE_APPROACHES", "LINE_NAMES", "CycleResult", "PickPlace", "plan_cycle"]


def _limits(robot: Any, vmax: Any, amax: Any, jmax: Any) -> tuple[np.ndarray, Any, Any]:
    nq = int(robot.nq)
    if vmax is None:
        v = np.asarray(robot.velocity_limit, dtype=float)
        if not np.all(v > 0.0):
            missing = [n for n, x in zip(robot.joint_names, v) if not x > 0.0]
            raise InvalidLimits(f"robot '{robot.name}' has no velocity limit for joint(s) {missing} in its URDF: "
                                "pass vmax (rad/s or m/s per joint)")
        vmax = v
    return (check_limit(vmax, nq, "vmax", required=True), check_limit(amax, nq, "amax", required=False),
            check_limit(jmax, nq, "jmax", required=False))


def plan_cycle(robot: Any, spec: PickPlace, *, kind: str = "multi-quintic", vmax: Any = None, amax: Any = None,
               jmax: Any = None, method: str = "exact", seed: int = 0, q_start: Any = None,
               payload: Any = None, torque_limits: Any = False, approach: str = "joint",
               tool_speed: float | None = None, cell: Any = None, clearance: float = 0.02,
               arm: str | None = None, hold: Any = None, margin: float = 0.005,
               lift_step: float = 0.02, plan_transfer: bool = True) -> CycleResult:
    """Plan and time one full pick-and-place cycle of ``robot`` (see the module docstring).

    Args:
        robot: a :class:`robots.Robot` (or an object with its IK/FK methods, ``nq``,
            ``name``, ``joint_names``, ``velocity_limit``).
        spec: the :class:`PickPlace` task.
        kind: trajectory family of each move, one of :data:`CYCLE_KINDS` (``"3-5-3"`` needs
            exactly 4 waypoints per move: no transfer vias).
        vmax, amax, jmax: limits per joint (scalar or (nq,)), rad/s, rad/s², rad/s³ (m/… for
            prismatic joints); ``vmax`` defaults to ``robot.velocity_limit``; None leaves
            acceleration or jerk unlimited.
        method: ``"exact"`` (deterministic scaling-law optimiser) or ``"ga"`` (the GA of
            this package), passed to :func:`optim.minimize_time`.
        seed: seed of the optimiser.
        q_start: configuration (nq,) whose nearest IK solution is taken at the pick (it
            selects the branch of the whole cycle).
        payload: what the gripper carries from pick to place: a mass [kg], a
            :class:`robots.Payload` or its dict form. The move to place is timed with the arm
            carrying it, the move back to the pick with the empty gripper.
        torque_limits: ``True`` (the URDF's ``effort`` limits) or limits per joint [N·m or
            N]: both moves are also timed under joint-torque limits (see
            :func:`optim.minimize_time`); ``False``: kinematic limits only.
        cell: a :class:`robots.cell.Cell` holding ``robot`` (``cell.arm(name).robot``): the
            cycle must then keep ``clearance`` [m] from the fixtures and the other arms
            (held at ``hold``, a cell configuration, default neutral), checked continuously
            at resolution ``margin`` [m]; it is re-planned (higher lift by ``lift_step``,
            then via points, then — ``plan_transfer`` — a transfer planned round what
            blocks by :mod:`optim.motion`) until it does (:mod:`optim.cell_cycle`). Points
            stay in the arm's base frame. ``arm`` names the arm when ``robot`` is not the
            cell's object.
        approach: ``"joint"`` (through the lift points in joint space) or ``"straight"``
            (straight vertical lines at pick and place, time-optimal along them, needs
            ``amax``; the joint-space cycle is planned too and its time kept in
            ``joint_cycle_time``: :mod:`optim.straight_approach`).
        tool_speed: with ``approach="straight"``, a tcp speed limit on the lines [m/s].

    Raises:
        InvalidInput: ``spec`` is not a :class:`PickPlace`, or a bad ``q_start``/``kind``.
        InvalidLimits: a limit ≤ 0, NaN/inf or of the wrong shape, or no ``vmax`` and the
            URDF has none.
        InvalidSettings: unknown ``method``; ``SettingOutOfRange``: ``lift_step`` outside
            :data:`optim.caps.LIFT_STEP_RANGE`, ``margin`` below :data:`optim.caps.MIN_MARGIN`,
            a ``clearance`` outside 0 … 1 m, a ``tool_speed`` that is not > 0.
        UnreachableTarget: a waypoint has no IK solution; the message names it (pick,
            above pick, via k, above place, place), its position and why
            (``robot.ik_failure_reason``).
        InfeasibleProblem: no timing found (from :func:`optim.minimize_time`).
        CollisionError: with a cell, the pick or place pose is too close to a fixture, or no
            re-planned cycle keeps the clearance; the message names the blocking bodies.
    """
    _check_cycle_settings(lift_step=lift_step, margin=margin, clearance=clearance, tool_speed=tool_speed)
    if cell is not None:
        from pinarms.optim.cycle.in_cell import plan_cycle_in_cell

        return plan_cycle_in_cell(robot, spec, cell=cell, clearance=clearance, arm=arm, hold=hold, margin=margin,
                                  lift_step=lift_step, plan=plan_cycle, plan_transfer=plan_transfer, kind=kind,
                                  vmax=vmax, amax=amax, jmax=jmax,
                                  method=method, seed=seed, q_start=q_start, payload=payload,
                                  torque_limits=torque_limits, approach=approach, tool_speed=tool_speed)
    if not isinstance(spec, PickPlace):
        raise InvalidInput(f"spec must be a PickPlace, got {type(spec).__name__}")
    if kind not in CYCLE_KINDS:
        raise InvalidInput(f"kind={kind!r} is not a cycle trajectory family: use one of {CYCLE_KINDS}")
    if kind == "3-5-3" and spec.via:
        raise InvalidInput(f"kind='3-5-3' times 4 waypoints per move, the spec has {len(spec.via)} transfer via "
                           "point(s) more: use 'multi-quintic' or 'quintic-bspline'")
    if method not in ("exact", "ga"):
        raise InvalidSettings(f"method={method!r}: use 'exact' or 'ga'")
    if approach not in CYCLE_APPROACHES:
        raise InvalidInput(f"approach={approach!r}: use one of {CYCLE_APPROACHES}")
    if approach == "straight":
        from pinarms.optim.cycle.straight import straight_cycle

        joint = plan_cycle(robot, spec, kind=kind, vmax=vmax, amax=amax, jmax=jmax, method=method, seed=seed,
                           q_start=q_start, payload=payload, torque_limits=torque_limits)
        return straight_cycle(robot, joint, kind=kind, method=method, seed=seed, tool_speed=tool_speed,
                              payload=payload, torque_limits=torque_limits)
    v, a, j = _limits(robot, vmax, amax, jmax)
    from pinarms.optim.torque import torque_constraint

    loaded = torque_constraint(robot, torque_limits, payload)  # the keywords checked before any IK
    poses = spec.poses(robot)
    names = spec.names
    try:
        q_out, branches = _one_branch_waypoints(robot, poses, q_start)
    except UnreachableTarget as exc:
        # name the waypoint that has no solution, and why (a handful of poses, on failure only):
        # the user's points first (pick, place, vias), then the lift points above them
        n = len(poses)
        for k in (0, n - 1, *range(2, n - 2), 1, n - 2):
            pose = poses[k]
            reason = robot.ik_failure_reason(pose)
            if reason is not None:
                where = np.round(pose[:3, 3], 6).tolist()
                hint = " or lower the lift" if names[k].startswith("above") else ""
                raise UnreachableTarget(
                    f"the {names[k]} point {where} m is unreachable for '{robot.name}': {reason}; "
                    f"move it inside the workspace{hint}"
                ) from exc
        raise
    options = {"velocities": "heuristic"} if kind == "multi-quintic" else None
    if loaded is None:
        moves = (
            minimize_time(q_out, kind, v, a, j, method=method, seed=seed, trajectory_options=options),
            minimize_time(q_out[::-1], kind, v, a, j, method=method, seed=seed, trajectory_options=options),
        )
    else:
        empty = torque_constraint(robot, loaded.limit)  # the same limits, nothing in the gripper
        moves = (
            minimize_time(q_out, kind, v, a, j, method=method, seed=seed, trajectory_options=options,
                          robot=loaded.robot, torque_limits=loaded.limit),
            minimize_time(q_out[::-1], kind, v, a, j, method=method, seed=seed, trajectory_options=options,
                          robot=empty.robot, torque_limits=empty.limit),
        )
    parts = [moves[0].trajectory, moves[1].trajectory]
    if spec.dwell > 0.0:
        parts = [_hold(q_out[0], spec.dwell), parts[0], _hold(q_out[-1], spec.dwell), parts[1]]
    trajectory = parts[0]
    for part in parts[1:]:
        trajectory = trajectory.concatenated(part)
    P = poses[:, :3, 3]
    ends = np.array([[P[0], P[1]], [P[-2], P[-1]], [P[-1], P[-2]], [P[1], P[0]]])
    return CycleResult(
        robot=str(robot.name),
        spec=spec,
        names=names + names[-2::-1],
        waypoints=np.concatenate([poses, poses[-2::-1]]),
        q_via=np.concatenate([q_out, q_out[-2::-1]]),
        moves=moves,
        trajectory=trajectory,
        peaks=trajectory.peaks(),
        vmax=v,
        amax=a,
        jmax=j,
        line_deviation=_line_deviation(robot, moves, ends),
        branches=np.concatenate([branches, branches[-2::-1]]),
        payload=None if loaded is None else loaded.robot.payload,
        torque_limit=None if loaded is None else loaded.limit.copy(),
    )


def _check_cycle_settings(*, lift_step: Any, margin: Any, clearance: Any, tool_speed: Any) -> None:
    """The cell and straight-line settings of :func:`plan_cycle`, checked before any work (optim.caps)."""
    number_setting(lift_step, "lift_step (rise per re-planning attempt)", *LIFT_STEP_RANGE, unit="m")
    number_setting(margin, "margin (resolution of the continuous check)", MIN_MARGIN, unit="m")
    number_setting(clearance, "clearance", 0.0, MAX_CLEARANCE, unit="m")
    if tool_speed is not None:
        number_setting(tool_speed, "tool_speed", 0.0, open_low=True, unit="m/s")


def _branch_labels(robot: Any, poses: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Closed-form branch label (robot.ik_branches) of each q row at its pose; -1 where unknown."""
    out = np.full(q.shape[0], -1)
    if not (getattr(robot, "has_analytic_ik", False) and hasattr(robot, "ik_branches")):
        return out
    for i, (pose, qi) in enumerate(zip(poses, q)):  # a handful of waypoints
        sols, labels = robot.ik_branches(pose, q_ref=qi)
        sols = np.asarray(sols, dtype=float).reshape(-1, q.shape[1])
        if sols.shape[0]:
            k = argmin_tied(np.linalg.norm(sols - qi, axis=1))
            if np.linalg.norm(sols[k] - qi) < 1e-6:
                out[i] = int(labels[k])
    return out


def _one_branch_waypoints(robot: Any, poses: np.ndarray, q_start: Any) -> tuple[np.ndarray, np.ndarray]:
    """Joint via points (k, nq) and their branch labels (k,).

    With ``q_start`` the branch is the one :func:`planning.joint_waypoints` takes from it. Without,
    for a closed-form arm, each solution at the pick is tried in the robot's order and the first
    whose path stays on one branch at every waypoint is kept (the limits can force a branch
    switch on the way from one pick solution but not from another); if none does, the first.
    """
    if q_start is not None or not (getattr(robot, "has_analytic_ik", False) and hasattr(robot, "ik_branches")):
        q = joint_waypoints(robot, poses, q_start)
        return q, _branch_labels(robot, poses, q)
    starts, _ = robot.ik_branches(poses[0])
    first = None
    for q0 in np.asarray(starts, dtype=float).reshape(-1, int(robot.nq)):
        q = joint_waypoints(robot, poses, q0)
        labels = _branch_labels(robot, poses, q)
        if first is None:
            first = (q, labels)
        if labels[0] >= 0 and np.all(labels == labels[0]):
            return q, labels
    if first is None:  # no solution at the pick: joint_waypoints names it
        q = joint_waypoints(robot, poses, None)
        return q, _branch_labels(robot, poses, q)
    return first
