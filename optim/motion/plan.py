"""``plan_motion``: a collision-free move of one arm (or two arms together) in a cell, timed optimally.

One :class:`.request.MotionRequest` in (checked when built), one call, one
:class:`.result.MotionPlan` out whose :class:`.result.MotionStatus` says how it ended (the
ruckig shape: input parameters, ``calculate``, a result with a status). Bad input is an
exception; what planning finds out is a status (the rule: :mod:`.result`). The steps:

1. **Ends.** The start is checked at once (joint limits, every pair at its margin); a start
   too close to something is ``START_IN_COLLISION`` naming the pair. A joint goal is
   checked the same way; a tool pose goal is first tested against the fixtures (a target
   point inside a box, cylinder, sphere or capsule is refused before any IK), then solved
   for every IK branch (closed form: each branch once; numerical: seeded restarts), and
   every branch that is clear becomes a goal state; the others are kept with the reason
   (:class:`GoalCandidate`). No clear branch: ``GOAL_IN_COLLISION`` listing them.
   Continuous joints: any start angle; each goal's angle at its 2π equivalent nearest the
   start, the search box half a turn beyond both (the short way across ±π; the other way
   round when the short way finds no path; docs/motion.md).
2. **Search.** OMPL (RRT-Connect by default) with pinarms' state and continuous, batched
   edge validity (:mod:`.checker`, :mod:`.search`), seeded; no path within ``time_limit``
   is ``NO_PATH`` with the planner, the time and the states explored.
3. **Shortcut.** OMPL's path simplifier, every new edge proven by the same rule.
4. **Smooth.** The cubic spline through the shortcut path, proven again; vertices are
   added where it strays, the polyline with stops is the fallback (:mod:`.smoothing`).
5. **Time.** :func:`pinarms.optim.time_optimal` along the smooth path (TOPP-RA written here) under
   the joint velocity limits, joint acceleration limits (the arms' by default), and joint torque limits
   (the URDF's efforts, the arm's inertials) by default: the time-optimal ``s(t)`` of the
   fixed path (bang–bang: jerk is not limited).
6. **Check and report.** The timed motion is re-checked by the cell's own continuous time
   check (:func:`pinarms.robots.cell.check_motion`, an independent code path: contact-free must be
   proven) and its clearance is reported over time: the smallest distance to a fixture or
   another arm, and between links of the arm, with the pairs (:class:`ClearanceProfile`).

Frames: poses in the world (the cell's root), joint coordinates in rad or m, times in s.
"""

from __future__ import annotations

import time
from typing import Callable, Sequence

import numpy as np

from pinarms.optim.errors import EndpointInCollision, InfeasibleProblem, NoPathFound, PlanningError
from pinarms.optim.motion.checker import MotionChecker
from pinarms.optim.motion.coal_batches import CheckRoute
from pinarms.optim.motion.ends import check_end, check_hold
from pinarms.optim.motion.geometry import plan_geometry
from pinarms.optim.motion.report import clearance_profile
from pinarms.optim.motion.request import MotionRequest
from pinarms.optim.motion.result import MotionPlan, MotionStatus
from pinarms.optim.topp.path_timing import PathTiming
from pinarms.planning import JointPath, Trajectory
from pinarms.planning.path_constraints import PathConstraint
from pinarms.robots.cell.motion_report import MotionCheck
from pinarms.errors import InvalidInput, UnreachableTarget

__all__ = ["plan_motion", "time_path"]


def time_path(path: JointPath, constraints: Sequence[PathConstraint], grid: int = 200) -> PathTiming:
    """:func:`pinarms.optim.time_optimal` of ``path`` (a clear error if the limits cannot be met)."""
    from pinarms.optim.topp.path_timing import time_optimal

    try:
        return time_optimal(path, constraints, grid=grid)
    except InfeasibleProblem as exc:
        raise InfeasibleProblem(f"the planned path cannot be timed under the limits: {exc}") from exc


def _recheck(request: MotionRequest, checker: MotionChecker, traj: Trajectory) -> tuple[MotionCheck, object]:
    """The cell's own continuous check of the timed motion (contact-free must be proven) and its clearance profile."""
    from pinarms.robots.cell.motion import ArmMotion

    cell, motions, start_col = request.cell, [], 0
    for a in request.arms:
        n = cell.arm(a).nq
        motions.append(ArmMotion(a, _columns(traj, start_col, n)))
        start_col += n
    # the path was proven on the cover: the re-check shares no code with it (broad phase and coal alone)
    check = cell.check_motion(motions, margin=checker.margin, clearance=0.0, hold=checker.hold, cover=False)
    if not check.collision_free:
        raise PlanningError(f"the timed motion failed the cell's continuous check: {check.summary()}")
    return check, clearance_profile(checker, traj)


def _failed(request: MotionRequest, checker: MotionChecker, exc: PlanningError | UnreachableTarget,
            seconds: dict) -> MotionPlan:
    """The plan of a request that planning could not solve: its status, reason and data."""
    o = request.options
    common = dict(cell=request.cell, arms=request.arms, start=np.array(request.start), reason=str(exc),
                  goal=None if request.pose_goal else np.array(request.goal), hold=checker.hold.copy(),
                  seed=o.seed, time_limit=o.time_limit, margin=checker.margin, self_margin=checker.self_margin,
                  seconds=seconds, limits=dict(request.limit_values), error=exc)
    if isinstance(exc, EndpointInCollision):
        status = {"start": MotionStatus.START_IN_COLLISION, "hold": MotionStatus.HOLD_IN_COLLISION}.get(
            exc.which, MotionStatus.GOAL_IN_COLLISION)
        return MotionPlan(status=status, which=exc.which, pairs=exc.pairs, distances=exc.distances,
                          configurations=exc.configurations, **common)
    if isinstance(exc, UnreachableTarget):
        return MotionPlan(status=MotionStatus.GOAL_UNREACHABLE, **common)
    if isinstance(exc, NoPathFound):
        return MotionPlan(status=MotionStatus.NO_PATH, planner=exc.planner, states=exc.states,
                          **{**common, "seconds": {**seconds, "search": exc.seconds}})
    if isinstance(exc, InfeasibleProblem):
        return MotionPlan(status=MotionStatus.LIMITS_NOT_MET, **common)
    return MotionPlan(status=MotionStatus.RECHECK_FAILED, **common)


def plan_motion(request: MotionRequest, *, progress: Callable[[str], None] | None = None) -> MotionPlan:
    """Plan the collision-free move of ``request`` (module docstring).

    Args:
        request: the cell, the arm(s), the start, the goal and how (:class:`.request.MotionRequest`,
            :class:`.request.MotionOptions`, :class:`.request.MotionLimits`).
        progress: called with a short line at each step.

    Returns:
        :class:`.result.MotionPlan`; ``plan.status`` is ``SOLVED``, or says what planning found
        (``START_IN_COLLISION``, ``GOAL_IN_COLLISION``, ``HOLD_IN_COLLISION``, ``GOAL_UNREACHABLE``,
        ``NO_PATH``, ``LIMITS_NOT_MET``, ``RECHECK_FAILED``) with ``plan.reason`` and the pairs and
        joint values concerned; ``plan.raise_for_status()`` raises it as the project's error.

    Raises:
        InvalidInput: ``request`` is not a :class:`MotionRequest`, a start outside the joint
            limits, a bad hold configuration, a pose goal whose only clear IK solution is the start.
        (Building the request raises the other input errors: :class:`.request.MotionRequest`.)
    """
    if not isinstance(request, MotionRequest):
        raise InvalidInput(f"plan_motion takes one MotionRequest, got {type(request).__name__}: "
                           "plan_motion(MotionRequest(cell, arm, start, goal, options=MotionOptions(...)))")
    t_all = time.perf_counter()
    say = progress or (lambda _m: None)
    o, arms, x0 = request.options, request.arms, np.array(request.start)
    checker = MotionChecker(request.cell, arms, margin=o.margin, self_margin=o.self_margin, hold=request.hold,
                            route=CheckRoute(threads=o.threads))
    seconds: dict = {}
    try:
        check_hold(checker)  # an idle arm in collision: named now, not after the search
        checker.span_turns(x0[None])  # a continuous joint may start at any angle (the goal widens it again)
        check_end(checker, x0, "start")
        speed = request.constraints[0].vmax if o.goals == "best" else None  # the velocity limits come first
        geo = plan_geometry(checker, arms, x0, np.array(request.goal), o, frame=request.frame, say=say, best_goal=speed)
        seconds = dict(geo["seconds"])
        path, method = geo["path"], geo["smoothing"]
        t = time.perf_counter()
        say(f"smoothed ({method}); timing")
        timing = time_path(path, list(request.constraints), request.limits.grid)
        seconds["time"] = time.perf_counter() - t
        t = time.perf_counter()
        traj = timing.trajectory
        check, profile = None, None
        if o.recheck:
            say(f"timed: {timing.duration:.3f} s; checking the timed motion")
            check, profile = _recheck(request, checker, traj)
        seconds["check"] = time.perf_counter() - t
    except (PlanningError, UnreachableTarget, InfeasibleProblem) as exc:
        seconds["total"] = time.perf_counter() - t_all
        say(f"not solved: {exc}")
        return _failed(request, checker, exc, seconds)
    seconds["total"] = time.perf_counter() - t_all
    return MotionPlan(cell=request.cell, arms=arms, status=MotionStatus.SOLVED, start=x0, goal=geo["simplified"][-1],
                      goals=tuple(geo["goals"]), raw_path=geo["raw"], simplified=geo["simplified"], path=path,
                      smoothing=method, timing=timing, trajectory=traj, check=check, clearance=profile,
                      hold=checker.hold.copy(), planner=geo["planner"], seed=o.seed, time_limit=o.time_limit,
                      margin=checker.margin, self_margin=checker.self_margin, states=geo["states"], seconds=seconds,
                      limits=dict(request.limit_values), simplifier=geo["simplifier"], compiled=geo["compiled"])


def _columns(traj: Trajectory, start: int, n: int) -> Trajectory:
    if start == 0 and n == traj.n_joints:
        return traj
    return Trajectory(traj.knot_times, traj.coefficients[:, :, start:start + n])
