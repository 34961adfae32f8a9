"""The joint-space cycle: pick, lift, transfer, lower, place, and back, time-optimal.

What a packing-line engineer optimises is not one move but the whole cycle::

    pick ─lift─▶ above pick ─(via …)─▶ above place ─lower─▶ place      (move "to place")
    place ─lift─▶ above place ─(… via)─▶ above pick ─lower─▶ pick      (move "to pick")

with the gripper closing at the pick and opening at the place (``dwell`` s each).
:func:`joint_cycle` turns a :class:`CycleRequest` into

* the Cartesian waypoints of one full cycle (tcp → base poses, m): the lift points are the
  pick and place poses moved ``lift`` m along the base's +z (vertical approach/retreat);
* the joint via points, by IK on ONE branch (:func:`pinarms.planning.joint_waypoints`: each
  waypoint keeps the previous waypoint's branch; without ``q_start`` the pick's solutions
  are tried in turn until one keeps a single branch through every waypoint, see
  :attr:`CycleResult.branches`). The return move runs through the same joint via points
  in reverse, so the cycle closes exactly;
* the time-optimal timing of each move (:func:`pinarms.optim.minimize_time` under the given
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

from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from pinarms.optim.cycle.request import CycleRequest
from pinarms.optim.cycle.spec import CycleResult
from pinarms.optim.cycle.vertical import at_rest, line_deviation, vertical_segments
from pinarms.optim.timing.segments import TimingRequest, TimingResult, minimize_time
from pinarms.optim.torque import torque_constraint
from pinarms.planning import joint_waypoints
from pinarms.errors import UnreachableTarget
from pinarms.robots.ties import argmin_tied

if TYPE_CHECKING:
    from pinarms.planning.trajectory import Trajectory
    from pinarms.robots import Robot

__all__ = ["joint_cycle", "via_points"]


def joint_cycle(request: CycleRequest, *, via: tuple[np.ndarray, np.ndarray] | None = None,
                there_clear: Callable[[Trajectory], bool] | None = None) -> CycleResult | None:
    """Plan and time the cycle of ``request`` in joint space, ignoring its approach and cell (module doc).

    ``via``: the joint via points and branch labels of the move to place, when the caller has
    them (:func:`via_points` of the request: the same). ``there_clear``: called with the move
    to place's trajectory once it is timed; when it says False the move back is not timed and
    None is returned (:mod:`pinarms.optim.cycle.in_cell` screens an attempt so).

    Raises:
        UnreachableTarget: a waypoint has no IK solution; the message names it (pick,
            above pick, via k, above place, place), its position and why
            (``robot.ik_failure_reason``).
        InfeasibleProblem: no timing found (from :func:`pinarms.optim.minimize_time`).
    """
    robot, spec = request.robot, request.spec
    poses = spec.poses(robot)
    q_out, branches = via_points(robot, poses, spec.names, request.q_start) if via is None else via
    there = _timed_move(request, q_out, back=False)
    if there_clear is not None and not there_clear(there.trajectory):
        return None
    moves = (there, _timed_move(request, q_out, back=True))
    parts = [moves[0].trajectory, moves[1].trajectory]
    if spec.dwell > 0.0:
        parts = [at_rest(q_out[0], spec.dwell), parts[0], at_rest(q_out[-1], spec.dwell), parts[1]]
    trajectory = parts[0]
    for part in parts[1:]:
        trajectory = trajectory.concatenated(part)
    names = spec.names
    loaded = request.torque
    return CycleResult(
        robot=str(robot.name),
        spec=spec,
        names=names + names[-2::-1],
        waypoints=np.concatenate([poses, poses[-2::-1]]),
        q_via=np.concatenate([q_out, q_out[-2::-1]]),
        moves=moves,
        trajectory=trajectory,
        peaks=trajectory.peaks(),
        vmax=request.vmax,
        amax=request.amax,
        jmax=request.jmax,
        line_deviation=line_deviation(robot, moves, vertical_segments(poses)),
        branches=np.concatenate([branches, branches[-2::-1]]),
        payload=None if loaded is None else loaded.robot.payload,
        torque_limit=None if loaded is None else loaded.limit.copy(),
    )


def via_points(robot: Robot, poses: np.ndarray, names: tuple[str, ...],
               q_start: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Joint via points (k, nq) on one branch through tcp ``poses`` (k, 4, 4) (base frame) named ``names``, the
    nearest ``q_start`` at the pick, and their branch labels; an unreachable waypoint named, with why."""
    try:
        return _one_branch_waypoints(robot, poses, q_start)
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


def _timed_move(request: CycleRequest, q_out: np.ndarray, back: bool) -> TimingResult:
    """The move to place (carrying the payload) or, ``back``, the move back (empty), timed optimally."""
    t = request.timing
    v, a, j = request.vmax, request.amax, request.jmax
    options = {"velocities": "heuristic"} if t.kind == "multi-quintic" else None
    q = q_out[::-1] if back else q_out
    loaded = request.torque
    if loaded is None:
        return minimize_time(TimingRequest(q, t.kind, v, a, j, method=t.method, seed=t.seed,
                                           trajectory_options=options))
    if back:
        empty = torque_constraint(request.robot, loaded.limit)  # the same limits, nothing in the gripper
        return minimize_time(TimingRequest(q, t.kind, v, a, j, method=t.method, seed=t.seed, trajectory_options=options,
                             robot=empty.robot, torque_limits=empty.limit))
    return minimize_time(TimingRequest(q, t.kind, v, a, j, method=t.method, seed=t.seed, trajectory_options=options,
                         robot=loaded.robot, torque_limits=loaded.limit))


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

    With ``q_start`` the branch is the one :func:`pinarms.planning.joint_waypoints` takes from it. Without,
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
