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
5. **Time.** :func:`optim.time_optimal` along the smooth path (TOPP-RA written here) under
   the joint velocity limits, joint acceleration limits if given, and joint torque limits
   (the URDF's efforts, the arm's inertials) by default: the time-optimal ``s(t)`` of the
   fixed path (bang–bang: jerk is not limited).
6. **Check and report.** The timed motion is re-checked by the cell's own continuous time
   check (:func:`robots.cell.check_motion`, an independent code path: contact-free must be
   proven) and its clearance is reported over time: the smallest distance to a fixture or
   another arm, and between links of the arm, with the pairs (:class:`ClearanceProfile`).

Frames: poses in the world (the cell's root), joint coordinates in rad or m, times in s.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from pinarms.optim.errors import (GoalInCollision, InfeasibleProblem, InvalidLimits, InvalidSettings, NoPathFound,
                                  StartInCollision)
from pinarms.optim.motion.checker import MotionChecker, check_threads
from pinarms.optim.motion.goals import GoalCandidate, describe_pair, ik_candidates, point_in_fixture
from pinarms.optim.motion.search import PLANNERS, search, shortcut
from pinarms.optim.motion.smoothing import smooth_path
from pinarms.planning import JointPath, Trajectory
from pinarms.robots.errors import InvalidInput, UnreachableTarget

__all__ = ["MotionPlan", "ClearanceProfile", "plan_motion", "plan_geometry", "SIMPLIFIER", "MAX_GRID", "time_path",
           "clearance_profile", "cell_trajectory"]

#: Most grid intervals of the time scaling (memory grows about 5.5 kB per interval).
MAX_GRID = 100_000

#: What shortcuts the path (said in every result).
SIMPLIFIER = "OMPL PathSimplifier (reduceVertices, partialShortcutPath, ropeShortcutPath), edges proven by pinarms"


@dataclass(frozen=True, eq=False)
class ClearanceProfile:
    """Distances along a timed motion, sampled every ``margin`` of travel of the fastest point.

    Attributes:
        times: ``(M,)`` [s]; ``environment``: ``(M,)`` smallest distance [m] between a planned
            arm and a fixture or another arm; ``environment_pair``: its pair index into
            ``pairs`` (−1 when there is none); ``own``: ``(M,)`` smallest distance between
            two links of one planned arm [m].
        pairs: the pairs checked (those involving a planned arm); ``required``: the margin [m].

    ``viz.plot_clearance(path, profile)`` draws it over time.
    """

    times: np.ndarray
    environment: np.ndarray
    environment_pair: np.ndarray
    own: np.ndarray
    pairs: tuple
    required: float = 0.0

    # what viz.plot_clearance reads: viz.plot_clearance("clearance.png", plan.clearance)
    @property
    def clearance(self) -> np.ndarray:
        """``environment`` (the name the clearance plot reads)."""
        return self.environment

    @property
    def exact(self) -> np.ndarray:
        """Every sample is an exact distance (coal)."""
        return np.ones(self.times.size, dtype=bool)

    @property
    def min_clearance_pair(self) -> str | None:
        """``"body_a – body_b"`` of the closest pair to the environment."""
        pair = self.min_pair
        return None if pair is None else f"{pair[0]} – {pair[1]}"

    @property
    def min_environment(self) -> float:
        """Smallest distance to a fixture or another arm over the motion [m]."""
        return float(np.min(self.environment)) if self.environment.size else float("inf")

    @property
    def min_time(self) -> float:
        """When it occurs [s]."""
        return float(self.times[int(np.argmin(self.environment))]) if self.environment.size else 0.0

    @property
    def min_pair(self) -> tuple[str, str] | None:
        """``(body_a, body_b)`` of that pair."""
        if not self.environment.size:
            return None
        k = int(self.environment_pair[int(np.argmin(self.environment))])
        return None if k < 0 else self.pairs[k].bodies

    @property
    def min_own(self) -> float:
        """Smallest distance between two links of one planned arm [m]."""
        return float(np.min(self.own)) if self.own.size else float("inf")


@dataclass(frozen=True, eq=False)
class MotionPlan:
    """A planned, proven and timed motion (see the module docstring).

    Attributes:
        arms: the planned arms; ``start``/``goal``: their joint coordinates ``(n,)``.
        goals: every goal configuration tried (:class:`GoalCandidate`: valid or why not).
        raw_path: ``(M, n)`` the planner's path; ``simplified``: ``(K, n)`` after shortcutting
            (:data:`SIMPLIFIER`); ``path``: the smooth :class:`planning.JointPath` that was
            timed, ``smoothing`` how it was made (``"cubic spline"``, ``"straight line"`` or
            ``"polyline with stops"``).
        timing: the :class:`optim.PathTiming`; ``trajectory``: the arms' joint trajectory
            (:class:`planning.Trajectory`, the planned arms' joints in order).
        check: the cell's continuous check of the timed motion (:class:`robots.cell.MotionCheck`).
        clearance: the distances along it (:class:`ClearanceProfile`).
        hold: the cell configuration of the arms not planned.
        planner, seed, time_limit, margin, self_margin: what was asked; ``states``: states the
            planner explored; ``seconds``: time per step (``"search"``, ``"shortcut"``,
            ``"smooth"``, ``"time"``, ``"check"``, ``"total"``); ``limits``: the limits timed under.
    """

    cell: Any = field(repr=False)
    arms: tuple[str, ...]
    start: np.ndarray = field(repr=False)
    goal: np.ndarray = field(repr=False)
    goals: tuple[GoalCandidate, ...] = field(repr=False)
    raw_path: np.ndarray = field(repr=False)
    simplified: np.ndarray = field(repr=False)
    path: JointPath = field(repr=False)
    smoothing: str
    timing: Any = field(repr=False)
    trajectory: Trajectory = field(repr=False)
    check: Any = field(repr=False)
    clearance: ClearanceProfile = field(repr=False)
    hold: np.ndarray = field(repr=False)
    planner: str
    seed: int
    time_limit: float
    margin: float
    self_margin: float
    states: int
    seconds: dict = field(repr=False)
    limits: dict = field(repr=False)
    simplifier: str = SIMPLIFIER

    @property
    def duration(self) -> float:
        """Time of the motion [s]."""
        return float(self.trajectory.duration)

    @property
    def path_length(self) -> float:
        """Joint-space length of the shortcut path [rad or m, Euclidean]."""
        return float(np.linalg.norm(np.diff(self.simplified, axis=0), axis=1).sum())

    @property
    def raw_length(self) -> float:
        """Joint-space length of the planner's path [rad or m]."""
        return float(np.linalg.norm(np.diff(self.raw_path, axis=0), axis=1).sum())

    def cell_trajectory(self) -> Trajectory:
        """The motion as a trajectory of the whole cell joint vector (arms not planned held)."""
        return cell_trajectory(self.cell, self.arms, self.trajectory, self.hold)

    def tool_path(self, arm: str | None = None, samples: int = 200) -> np.ndarray:
        """tcp positions ``(samples, 3)`` [m, world] of ``arm`` (default the first planned arm) along the motion."""
        name = self.arms[0] if arm is None else arm
        t = np.linspace(self.trajectory.start_time, self.trajectory.end_time, samples)
        q = self.cell_trajectory().sample(t)[0]
        return self.cell.world_pose(q, self.cell.arm(name).prefix + "tcp")[:, :3, 3]

    def as_dict(self) -> dict[str, Any]:
        """JSON-able summary (SI units)."""
        c = self.clearance
        return {
            "arms": list(self.arms),
            "planner": self.planner,
            "seed": self.seed,
            "time_limit_s": self.time_limit,
            "margin_m": self.margin,
            "self_margin_m": self.self_margin,
            "start": self.start.tolist(),
            "goal": self.goal.tolist(),
            "goal_candidates": [{"q": g.q.tolist(), "valid": g.valid, "reason": g.reason, "branch": g.branch}
                                for g in self.goals],
            "states_explored": self.states,
            "raw_path": self.raw_path.tolist(),
            "simplified_path": self.simplified.tolist(),
            "raw_length": self.raw_length,
            "path_length": self.path_length,
            "simplifier": self.simplifier,
            "smoothing": self.smoothing,
            "duration_s": self.duration,
            "timing": self.timing.as_dict(),
            "limits": {k: (None if v is None else np.asarray(v).tolist()) for k, v in self.limits.items()},
            "collision_free": bool(self.check.collision_free),
            "min_clearance_environment_m": c.min_environment,
            "min_clearance_time_s": c.min_time,
            "min_clearance_pair": None if c.min_pair is None else list(c.min_pair),
            "min_clearance_own_links_m": c.min_own,
            "seconds": {k: round(v, 6) for k, v in self.seconds.items()},
        }


# ------------------------------------------------------------------ helpers
def _arms(cell: Any, arm: Any) -> tuple[str, ...]:
    names = (arm,) if isinstance(arm, str) else tuple(arm)
    if not names or not all(isinstance(a, str) for a in names):
        raise InvalidInput(f"arm must be an arm name or a sequence of arm names, got {arm!r}")
    return tuple(cell.arm(a).name for a in names)


def _joints(cell: Any, arms: tuple[str, ...], value: Any, what: str) -> np.ndarray:
    """The planned arms' coordinates from an array (concatenated) or ``{arm: q}``."""
    sizes = [cell.arm(a).nq for a in arms]
    if isinstance(value, Mapping):
        missing = [a for a in arms if a not in value]
        if missing:
            raise InvalidInput(f"{what} gives no joints for arm(s) {missing}")
        parts = [np.asarray(value[a], dtype=float).reshape(-1) for a in arms]
        if any(p.size != n for p, n in zip(parts, sizes)):
            raise InvalidInput(f"{what}: arm joint counts must be {dict(zip(arms, sizes))}")
        x = np.concatenate(parts)
    else:
        try:
            x = np.asarray(value, dtype=float).reshape(-1)
        except (TypeError, ValueError) as exc:
            raise InvalidInput(f"{what} must be joint coordinates, got {value!r}") from exc
    if x.size != sum(sizes) or not np.all(np.isfinite(x)):
        raise InvalidInput(f"{what} must be {sum(sizes)} finite joint coordinates (arms {list(arms)}), got {value!r}")
    return x


def _is_pose(value: Any) -> bool:
    if isinstance(value, Mapping):
        return False
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return arr.shape == (4, 4)


def _check_start(checker: MotionChecker, x: np.ndarray, label: str = "start") -> None:
    if not checker.within_limits(x[None])[0]:
        names = checker.cell.joint_names
        bad = [f"{names[c]} = {x[i]:.4g} outside [{checker.lower[i]:.4g}, {checker.upper[i]:.4g}]"
               for i, c in enumerate(checker.cols) if not checker.lower[i] - 1e-12 <= x[i] <= checker.upper[i] + 1e-12]
        raise InvalidInput(f"the {label} is outside the joint limits: {'; '.join(bad)}")
    if not checker.state_valid(x):
        e, pair, d = checker.closest(x)
        m = checker.self_margin if pair is not None and pair.kind == "self" else checker.margin
        err = StartInCollision if label == "start" else GoalInCollision
        raise err(f"the {label} configuration is in collision: {describe_pair(pair, d, m)}; move it clear or lower "
                  f"the margin", which=label, pairs=(None if pair is None else pair.bodies,), distances=(d,))


def _goal_candidates(checker: MotionChecker, arms: tuple[str, ...], goal: Any, start: np.ndarray, seed: int,
                     frame: str | None) -> list[GoalCandidate]:
    cell = checker.cell
    if not _is_pose(goal):
        x = _joints(cell, arms, goal, "goal")
        _check_start(checker, x, "goal")
        return [GoalCandidate(x, True)]
    if len(arms) != 1:
        raise InvalidInput("a pose goal needs one planned arm; give two arms' goals as joint vectors {arm: q}")
    T = np.asarray(goal, dtype=float)
    if not np.all(np.isfinite(T)) or np.abs(T[:3, :3] @ T[:3, :3].T - np.eye(3)).max() > 1e-6 or \
            np.abs(T[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-9:
        raise InvalidInput("goal pose must be a finite homogeneous transform (4, 4): tool → world [m]")
    inside = point_in_fixture(cell, T[:3, 3])
    if inside is not None:
        raise GoalInCollision(f"the goal point {np.round(T[:3, 3], 4).tolist()} m lies inside fixture {inside[0]!r} "
                              f"({inside[1] * 1e3:.1f} mm deep): no configuration can reach it clear",
                              which="goal", pairs=(("tcp", inside[0]),), distances=(-inside[1],))
    arm = cell.arm(arms[0])
    robot = arm.robot
    if frame is not None and frame not in ("tcp", robot.tcp_frame):
        raise InvalidInput(f"frame {frame!r}: pose goals are for the arm's tcp ({robot.tcp_frame!r})")
    T_base = arm.to_base(T)
    q, branch = ik_candidates(robot, T_base, start, seed=seed)
    if q.shape[0] == 0:
        reason = robot.ik_failure_reason(T_base) or "no IK solution within the joint limits"
        raise UnreachableTarget(f"the goal pose at {np.round(T[:3, 3], 4).tolist()} m is unreachable for arm "
                                f"{arm.name!r}: {reason}")
    out = []
    for qi, bi in zip(q, branch):
        if checker.state_valid(qi):
            out.append(GoalCandidate(qi, True, "", int(bi)))
            continue
        e, pair, d = checker.closest(qi)
        m = checker.self_margin if pair is not None and pair.kind == "self" else checker.margin
        out.append(GoalCandidate(qi, False, describe_pair(pair, d, m), int(bi),
                                 () if pair is None else pair.bodies, d))
    if not any(g.valid for g in out):
        lines = "; ".join(f"branch {g.branch}: {g.reason}" if g.branch >= 0 else g.reason for g in out)
        raise GoalInCollision(f"every IK solution of the goal pose is in collision ({len(out)} tried): {lines}",
                              which="goal", pairs=tuple(g.pair for g in out), distances=tuple(g.distance for g in out))
    return out


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
    a = vec(amax, "amax")
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
        raise InvalidLimits("the motion would be timed under velocity limits alone (infinite accelerations): give amax "
                            "[rad/s² or m/s²], or torque limits on an arm with inertials")
    return cons, {"vmax": v, "amax": a, "torque": tau_used}


def time_path(path: JointPath, constraints: Sequence[Any], grid: int = 200) -> Any:
    """:func:`optim.time_optimal` of ``path`` (a clear error if the limits cannot be met)."""
    from pinarms.optim.topp.path_timing import time_optimal

    try:
        return time_optimal(path, constraints, grid=grid)
    except InfeasibleProblem as exc:
        raise InfeasibleProblem(f"the planned path cannot be timed under the limits: {exc}") from exc


def cell_trajectory(cell: Any, arms: Sequence[str], trajectory: Trajectory, hold: np.ndarray) -> Trajectory:
    """A trajectory of the planned arms' joints as one of the whole cell (the other arms held at ``hold``)."""
    C = trajectory.coefficients
    out = np.zeros((C.shape[0], C.shape[1], cell.nq))
    out[:, 0, :] = hold
    cols = np.concatenate([np.arange(cell.nq)[cell.arm(a).q_slice] for a in arms])
    out[:, :, cols] = C
    return Trajectory(trajectory.knot_times, out)


def clearance_profile(checker: MotionChecker, trajectory: Trajectory, *, samples: int | None = None) -> ClearanceProfile:
    """Distances along ``trajectory`` (planned arms' joints; time last for none): one sample per
    ``margin`` of travel of the fastest point (at least 20, at most 4000)."""
    t0, t1 = trajectory.start_time, trajectory.end_time
    peaks = np.asarray(trajectory.peaks().velocity, dtype=float)
    travel = float(peaks @ checker.levers) * (t1 - t0)
    n = samples or int(np.clip(np.ceil(travel / checker.margin), 20, 4000))
    t = np.linspace(t0, t1, n + 1)
    X = np.asarray(trajectory.sample(t)[0], dtype=float).reshape(t.size, -1)
    if checker.timed:
        X = np.column_stack([X, t])
    Q = checker.full(X)
    own = np.array([p.kind == "self" for p in checker.pairs])
    env_e, env_k, env_d = checker.excess(Q, mask=~own)
    own_e, own_k, own_d = checker.excess(Q, mask=own) if own.any() else (None, None, np.full(t.size, np.inf))
    return ClearanceProfile(t, env_d, env_k, own_d, checker.pairs, checker.margin)


# ------------------------------------------------------------------ the planner
def plan_motion(cell: Any, arm: Any, start: Any, goal: Any, *, margin: float = 0.01, self_margin: float = 0.0,
                planner: str = "rrtconnect", time_limit: float = 1.0, seed: int = 0, hold: Any = None,
                frame: str | None = None, vmax: Any = None, amax: Any = None, torque: Any = True,
                grid: int = 200, threads: int = 1,
                progress: Callable[[str], None] | None = None) -> MotionPlan:
    """Plan a collision-free move of ``arm`` from ``start`` to ``goal`` in ``cell`` (module docstring).

    Args:
        cell: a :class:`robots.Cell`.
        arm: the arm's name, or two names to plan both arms together in their joint space.
        start: the arm's joint coordinates ``(n,)`` (two arms: concatenated or ``{arm: q}``).
        goal: joint coordinates like ``start``, or a tcp pose ``(4, 4)`` in the world (one arm):
            every clear IK branch is a goal.
        margin: clearance [m] kept to fixtures and other arms everywhere along the motion (> 0);
            it also sets the step of the continuous check.
        self_margin: clearance [m] kept between two links of one arm (default 0: no contact).
        planner: an OMPL planner, one of :data:`optim.motion.search.PLANNERS` (default RRT-Connect).
        time_limit: seconds the search may take.
        seed: seed of the search and the shortcutting (same seed, same path).
        hold: cell configuration of the arms not planned (default the cell's neutral).
        frame: the tool frame of a pose goal (default the arm's tcp).
        vmax, amax: joint velocity [rad/s or m/s] (default the URDF's) and acceleration
            [rad/s² or m/s²] (default none) limits, scalar or per planned joint.
        torque: ``True``: the URDF's effort limits where the arm has inertials; limits per
            planned joint [N·m or N]; ``False``: none.
        grid: grid intervals of the time scaling (1 to :data:`MAX_GRID`).
        threads: threads of the batched collision checks (1 to :data:`optim.motion.checker.MAX_THREADS`).
        progress: called with a short line at each step.

    Raises:
        InvalidInput: unknown arm, malformed start/goal, a start outside the joint limits.
        StartInCollision, GoalInCollision: an end that is itself too close to something
            (the pair named; a pose goal lists every IK branch and why).
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
    key = str(planner).lower()
    if key not in PLANNERS:
        raise InvalidSettings(f"unknown planner {planner!r}; use one of {', '.join(PLANNERS)}")
    ok = isinstance(time_limit, (int, float, np.integer, np.floating)) and not isinstance(time_limit, bool)
    if not ok or not np.isfinite(float(time_limit)) or float(time_limit) <= 0.0:
        raise InvalidSettings(f"time_limit must be a positive number of seconds, got {time_limit!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise InvalidSettings(f"seed must be an integer, got {seed!r}")
    threads = check_threads(threads)
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or not 1 <= int(grid) <= MAX_GRID:
        raise InvalidSettings(f"grid must be an integer from 1 to {MAX_GRID} (intervals of the time scaling; "
                              f"about 5.5 kB each), got {grid!r}")
    checker = MotionChecker(cell, arms, margin=margin, self_margin=self_margin, hold=hold, threads=threads)
    constraints, limits = _limits(cell, arms, vmax, amax, torque)
    x0 = _joints(cell, arms, start, "start")
    _check_start(checker, x0, "start")
    geo = plan_geometry(checker, arms, x0, goal, planner=key, time_limit=float(time_limit), seed=int(seed), frame=frame,
                        say=say)
    seconds = dict(geo["seconds"])
    path, method = geo["path"], geo["smoothing"]
    t = time.perf_counter()
    say(f"smoothed ({method}); timing")
    timing = time_path(path, constraints, grid)
    seconds["time"] = time.perf_counter() - t
    t = time.perf_counter()
    say(f"timed: {timing.duration:.3f} s; checking the timed motion")
    from pinarms.robots.cell.motion import ArmMotion

    traj = timing.trajectory
    motions = []
    start_col = 0
    for a in arms:
        n = cell.arm(a).nq
        motions.append(ArmMotion(a, _columns(traj, start_col, n)))
        start_col += n
    check = cell.check_motion(motions, margin=checker.margin, clearance=0.0, hold=checker.hold)
    if not check.collision_free:
        from pinarms.optim.errors import PlanningError

        raise PlanningError(f"the timed motion failed the cell's continuous check: {check.summary()}")
    profile = clearance_profile(checker, traj)
    seconds["check"] = time.perf_counter() - t
    seconds["total"] = time.perf_counter() - t_all
    return MotionPlan(cell=cell, arms=arms, start=x0, goal=geo["simplified"][-1], goals=tuple(geo["goals"]),
                      raw_path=geo["raw"], simplified=geo["simplified"], path=path, smoothing=method, timing=timing,
                      trajectory=traj, check=check, clearance=profile, hold=checker.hold.copy(), planner=geo["planner"],
                      seed=int(seed), time_limit=float(time_limit), margin=checker.margin,
                      self_margin=checker.self_margin, states=geo["states"], seconds=seconds, limits=limits)


def plan_geometry(checker: MotionChecker, arms: tuple[str, ...], x0: np.ndarray, goal: Any, *, planner: str,
                  time_limit: float, seed: int, frame: str | None = None,
                  say: Callable[[str], None] = lambda _m: None) -> dict:
    """Steps 1-4 of the module docstring for a checked start: goals, search, shortcut, smoothing.

    Returns a dict: ``goals``, ``raw``, ``simplified``, ``path``, ``smoothing``, ``planner``,
    ``states``, ``seconds``.
    """
    cell = checker.cell
    goals = _goal_candidates(checker, arms, goal, x0, int(seed), frame)
    G = np.array([g.q for g in goals if g.valid])
    same = np.flatnonzero(np.abs(G - x0).max(axis=1) <= 1e-9)
    if same.size:
        raise InvalidInput(f"the start already is the goal (joints {np.round(x0, 6).tolist()}): there is nothing to "
                           "plan; give a goal different from the start")
    seconds: dict[str, float] = {}
    say(f"{len(G)} clear goal configuration(s) of {len(goals)}; searching")
    result = search(checker, x0, G, planner=planner, time_limit=float(time_limit), seed=int(seed))
    seconds["search"] = result.seconds
    if result.path is None:
        raise NoPathFound(
            f"{result.planner} found no collision-free path in {float(time_limit):g} s ({result.states} states "
            f"explored, {len(G)} goal configuration(s), margin {checker.margin * 1e3:.1f} mm): raise time_limit, try "
            "another planner or seed, or lower the margin", planner=result.planner, time_limit=float(time_limit),
            seconds=result.seconds, states=result.states, goals=len(G))
    t = time.perf_counter()
    say(f"path found by {result.planner} in {result.seconds:.3f} s ({result.states} states); shortcutting")
    simplified = shortcut(checker, result.path, seed=int(seed))
    seconds["shortcut"] = time.perf_counter() - t
    t = time.perf_counter()
    robot = cell.arm(arms[0]).robot if len(arms) == 1 else None
    path, method, _ = smooth_path(checker, simplified, robot)
    seconds["smooth"] = time.perf_counter() - t
    return {"goals": goals, "raw": result.path, "simplified": simplified, "path": path, "smoothing": method,
            "planner": result.planner, "states": result.states, "seconds": seconds}


def _columns(traj: Trajectory, start: int, n: int) -> Trajectory:
    if start == 0 and n == traj.n_joints:
        return traj
    return Trajectory(traj.knot_times, traj.coefficients[:, :, start:start + n])
