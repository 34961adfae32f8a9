"""``plan_motion``: a collision-free move of one arm (or two arms together) in a cell, timed optimally.

The steps, each reported in :class:`MotionPlan`:

1. **Ends.** The start is checked at once (joint limits, every pair at its margin); a start
   too close to something is :class:`StartInCollision` naming the pair. A joint goal is
   checked the same way; a tool pose goal is first tested against the fixtures (a target
   point inside a box, cylinder, sphere or capsule is refused before any IK), then solved
   for every IK branch (closed form: each branch once; numerical: seeded restarts), and
   every branch that is clear becomes a goal state; the others are kept with the reason
   (:class:`GoalCandidate`). No clear branch: :class:`GoalInCollision` listing them.
2. **Search.** OMPL (RRT-Connect by default) with pinarms' state and continuous, batched
   edge validity (:mod:`.checker`, :mod:`.search`), seeded; no path within ``time_limit``
   is :class:`NoPathFound` with the planner, the time and the states explored.
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
from typing import Any, Callable, Sequence

import numpy as np

from pinarms.optim.errors import InfeasibleProblem, InvalidLimits, InvalidSettings
from pinarms.optim.motion.checker import MotionChecker, check_threads
from pinarms.optim.motion.ends import arm_joints as _joints, check_end as _check_start, check_hold as _check_hold, \
    planned_arms as _arms
from pinarms.optim.motion.geometry import plan_geometry
from pinarms.optim.motion.report import SIMPLIFIER, ClearanceProfile, MotionPlan, cell_trajectory, clearance_profile
from pinarms.optim.motion.search import PLANNERS
from pinarms.planning import JointPath, Trajectory

__all__ = ["MotionPlan", "ClearanceProfile", "plan_motion", "plan_geometry", "SIMPLIFIER", "MAX_GRID", "time_path",
           "clearance_profile", "cell_trajectory"]

#: Most grid intervals of the time scaling (memory grows about 5.5 kB per interval).
MAX_GRID = 100_000


def _limits(cell: Any, arms: tuple[str, ...], vmax: Any, amax: Any, torque: Any) -> tuple[list, dict]:
    from pinarms.planning.path_constraints import JointAccelerationConstraint, JointVelocityConstraint
    from pinarms.planning.torque import JointTorqueConstraint
    from pinarms.robots.dynamics import MissingInertials, check_inertials

    robots = [cell.arm(a).robot for a in arms]
    n = sum(r.nq for r in robots)

    def vec(value: Any, what: str) -> np.ndarray | None:
        if value is None:
            return None
        arr = np.asarray(value, dtype=float)
        arr = np.broadcast_to(arr, (n,)).astype(float) if arr.ndim == 0 or arr.size == 1 else arr.reshape(-1)
        if arr.size != n or not np.all(np.isfinite(arr)) or np.any(arr <= 0.0):
            raise InvalidLimits(f"{what} must be one positive number or {n} (one per planned joint), got {value!r}")
        return arr

    v = vec(vmax, "vmax") if vmax is not None else np.concatenate([r.velocity_limit for r in robots])
    if not np.all(v > 0.0):
        raise InvalidLimits("the URDF gives no velocity limit for some planned joint: pass vmax [rad/s or m/s]")
    if amax is None:  # the arms' acceleration limits (the stated default rule unless set on the robot)
        a = np.concatenate([np.asarray(r.acceleration_limit, dtype=float) for r in robots])
        a_source = "; ".join(dict.fromkeys(r.acceleration_source for r in robots))
        if not np.all(a > 0.0):
            raise InvalidLimits("some planned joint has no acceleration limit (its URDF gives no velocity limit): "
                                "pass amax [rad/s² or m/s²], or amax=False to time under torques alone")
    elif amax is True:
        raise InvalidLimits("amax must be None (the arms' limits), False (none) or limits [rad/s² or m/s²], got True")
    elif amax is False:
        a, a_source = None, "none (amax=False)"
    else:
        a, a_source = vec(amax, "amax"), "given (amax)"
    cons = [JointVelocityConstraint(v)]
    if a is not None:
        cons.append(JointAccelerationConstraint(a))
    tau_used = None
    if torque is not False and torque is not None:
        explicit = torque is not True
        if explicit:
            tau = np.asarray(torque, dtype=float)
            tau = np.broadcast_to(tau, (n,)).astype(float) if tau.ndim == 0 or tau.size == 1 else tau.reshape(-1)
            if tau.size != n or not np.all(np.isfinite(tau)) or np.any(tau <= 0.0):
                raise InvalidLimits(f"torque must be True, False, one positive number or {n} [N·m or N], got {torque!r}")
        parts = []
        col = 0
        for r in robots:
            cols = np.arange(col, col + r.nq)
            col += r.nq
            if explicit:
                check_inertials(r)  # MissingInertials: torque limits asked on an arm without masses
                limit = tau[cols]
            else:
                try:
                    check_inertials(r)
                except MissingInertials:
                    continue
                limit = np.asarray(r.effort_limit, dtype=float)
                if not np.all(limit > 0.0):
                    continue
            cons.append(JointTorqueConstraint(r, limit, cols))
            parts.append(limit)
        tau_used = np.concatenate(parts) if len(parts) == len(robots) else None
    if a is None and len(cons) == 1:
        raise InvalidLimits("the motion would be timed under velocity limits alone (infinite accelerations): give amax= "
                            "[rad/s² or m/s²] (on the command line --amax), or torque limits on an arm with inertials")
    return cons, {"vmax": v, "amax": a, "torque": tau_used, "amax_source": a_source}


def time_path(path: JointPath, constraints: Sequence[Any], grid: int = 200) -> Any:
    """:func:`pinarms.optim.time_optimal` of ``path`` (a clear error if the limits cannot be met)."""
    from pinarms.optim.topp.path_timing import time_optimal

    try:
        return time_optimal(path, constraints, grid=grid)
    except InfeasibleProblem as exc:
        raise InfeasibleProblem(f"the planned path cannot be timed under the limits: {exc}") from exc


# ------------------------------------------------------------------ the planner
def _check_settings(planner: Any, time_limit: Any, seed: Any, grid: Any) -> str:
    key = str(planner).lower()
    if key not in PLANNERS:
        raise InvalidSettings(f"unknown planner {planner!r}; use one of {', '.join(PLANNERS)}")
    ok = isinstance(time_limit, (int, float, np.integer, np.floating)) and not isinstance(time_limit, bool)
    if not ok or not np.isfinite(float(time_limit)) or float(time_limit) <= 0.0:
        raise InvalidSettings(f"time_limit must be a positive number of seconds, got {time_limit!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) < 2**63:
        raise InvalidSettings(f"seed must be an integer from 0 to 2**63 - 1, got {seed!r}")
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or not 1 <= int(grid) <= MAX_GRID:
        raise InvalidSettings(f"grid must be an integer from 1 to {MAX_GRID} (intervals of the time scaling; "
                              f"about 5.5 kB each), got {grid!r}")
    return key


def _recheck(cell: Any, arms: tuple[str, ...], checker: MotionChecker, traj: Trajectory) -> tuple[Any, Any]:
    """The cell's own continuous check of the timed motion (contact-free must be proven) and its clearance profile."""
    from pinarms.optim.errors import PlanningError
    from pinarms.robots.cell.motion import ArmMotion

    motions = []
    start_col = 0
    for a in arms:
        n = cell.arm(a).nq
        motions.append(ArmMotion(a, _columns(traj, start_col, n)))
        start_col += n
    # the path was proven on the cover: the re-check shares no code with it (broad phase and coal alone)
    check = cell.check_motion(motions, margin=checker.margin, clearance=0.0, hold=checker.hold, cover=False)
    if not check.collision_free:
        raise PlanningError(f"the timed motion failed the cell's continuous check: {check.summary()}")
    return check, clearance_profile(checker, traj)


def plan_motion(cell: Any, arm: Any, start: Any, goal: Any, *, margin: float = 0.01, self_margin: float = 0.0,
                planner: str = "rrtconnect", time_limit: float = 1.0, seed: int = 0, hold: Any = None,
                frame: str | None = None, vmax: Any = None, amax: Any = None, torque: Any = True,
                grid: int = 200, threads: int = 1, compiled: bool = True, recheck: bool = True,
                goals: str = "best", progress: Callable[[str], None] | None = None) -> MotionPlan:
    """Plan a collision-free move of ``arm`` from ``start`` to ``goal`` in ``cell`` (module docstring).

    Args:
        cell: a :class:`pinarms.robots.Cell`.
        arm: the arm's name, or two names to plan both arms together in their joint space.
        start: the arm's joint coordinates ``(n,)`` (two arms: concatenated or ``{arm: q}``).
        goal: joint coordinates like ``start``, or a tcp pose ``(4, 4)`` in the world (one arm):
            every clear IK branch is a goal.
        margin: clearance [m] kept to fixtures and other arms everywhere along the motion (> 0);
            it also sets the step of the continuous check.
        self_margin: clearance [m] kept between two links of one arm (default 0: no contact).
        planner: an OMPL planner, one of :data:`pinarms.optim.motion.search.PLANNERS` (default RRT-Connect).
        time_limit: seconds the search may take.
        seed: seed of the search and the shortcutting, 0 to 2**63 − 1 (same seed, same path).
        hold: cell configuration of the arms not planned (default :attr:`Cell.hold`, each arm's
            hold pose from the cell description, else neutral).
        frame: the tool frame of a pose goal (default the arm's tcp).
        vmax, amax: joint velocity [rad/s or m/s] (default the URDF's) and acceleration
            [rad/s² or m/s²] limits, scalar or per planned joint; ``amax`` default: the arms'
            ``Robot.acceleration_limit`` (velocity limit / 0.25 s unless set), ``False``: none
            (torques alone). ``plan.limits["amax_source"]`` says which.
        torque: ``True``: the URDF's effort limits where the arm has inertials; limits per
            planned joint [N·m or N]; ``False``: none.
        grid: grid intervals of the time scaling (1 to :data:`MAX_GRID`).
        threads: threads of the batched collision checks (1 to :data:`pinarms.optim.motion.checker.MAX_THREADS`).
        compiled: search RRT-Connect compiled on the sphere cover first where it is tight
            (:mod:`.geometry`); ``False``: OMPL with the exact checker alone, as before.
        recheck: re-check the timed motion by the cell's own continuous check and report its
            clearance profile (``False``: ``check`` and ``clearance`` are ``None``; the path is
            proven by the exact checker either way).
        goals: with several goal configurations (the IK branches of a pose goal): ``"best"``
            (default), each other goal is also searched
            (compiled, each with the compiled search's share of ``time_limit``, in increasing order
            of its straight move's time bound, while it could still win) and the path with the
            shortest time bound (each edge at its slowest joint's speed limit) is kept;
            ``"first"``, the path to the first one reached (a little less planning time).
        progress: called with a short line at each step.

    Raises:
        InvalidInput: unknown arm, malformed start/goal, a start outside the joint limits.
        StartInCollision, GoalInCollision: an end that is itself too close to something
            (the pair named, and the idle arm when it is one of the pair; a pose goal lists
            every IK branch and why). ``StartInCollision`` with ``which="hold"``: an arm
            not planned touches something at its hold pose (named, before any search).
        UnreachableTarget: a pose goal without any IK solution.
        NoPathFound: no path within ``time_limit`` (planner, time and states explored said).
        InvalidLimits, InfeasibleProblem: limits missing, or not met along the path.
        InvalidSettings: an unknown planner, a non-positive time limit, ``grid`` or ``threads``
            out of their range.
        InvalidInput: also a goal equal to the start (nothing to plan).
    """
    t_all = time.perf_counter()
    say = progress or (lambda _m: None)
    arms = _arms(cell, arm)
    key = _check_settings(planner, time_limit, seed, grid)
    if goals not in ("first", "best"):
        raise InvalidSettings(f"goals must be 'first' or 'best', got {goals!r}")
    threads = check_threads(threads)
    checker = MotionChecker(cell, arms, margin=margin, self_margin=self_margin, hold=hold, threads=threads)
    constraints, limits = _limits(cell, arms, vmax, amax, torque)
    x0 = _joints(cell, arms, start, "start")
    _check_hold(checker)  # an idle arm in collision: named now, not after the search
    _check_start(checker, x0, "start")
    speed = constraints[0].vmax if goals == "best" else None  # the joint velocity limits come first
    geo = plan_geometry(checker, arms, x0, goal, planner=key, time_limit=float(time_limit), seed=int(seed), frame=frame,
                        compiled=bool(compiled), say=say, best_goal=speed)
    seconds = dict(geo["seconds"])
    path, method = geo["path"], geo["smoothing"]
    t = time.perf_counter()
    say(f"smoothed ({method}); timing")
    timing = time_path(path, constraints, grid)
    seconds["time"] = time.perf_counter() - t
    t = time.perf_counter()
    traj = timing.trajectory
    check, profile = None, None
    if recheck:
        say(f"timed: {timing.duration:.3f} s; checking the timed motion")
        check, profile = _recheck(cell, arms, checker, traj)
    seconds["check"] = time.perf_counter() - t
    seconds["total"] = time.perf_counter() - t_all
    return MotionPlan(cell=cell, arms=arms, start=x0, goal=geo["simplified"][-1], goals=tuple(geo["goals"]),
                      raw_path=geo["raw"], simplified=geo["simplified"], path=path, smoothing=method, timing=timing,
                      trajectory=traj, check=check, clearance=profile, hold=checker.hold.copy(), planner=geo["planner"],
                      seed=int(seed), time_limit=float(time_limit), margin=checker.margin,
                      self_margin=checker.self_margin, states=geo["states"], seconds=seconds, limits=limits,
                      simplifier=geo["simplifier"], compiled=geo["compiled"])


def _columns(traj: Trajectory, start: int, n: int) -> Trajectory:
    if start == 0 and n == traj.n_joints:
        return traj
    return Trajectory(traj.knot_times, traj.coefficients[:, :, start:start + n])
