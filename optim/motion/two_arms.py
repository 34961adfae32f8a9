"""Two arms: plan one arm around the other's timed trajectory, or both together.

:func:`plan_around` plans arm B while arm A follows its own trajectory:

1. **Path.** B's path is planned (:func:`plan_motion`'s search, shortcut and smoothing)
   with A parked at the **end** of its trajectory, where it stays once its move is done:
   B's path can never be blocked by A for good.
2. **Time.** B's path is timed optimally (:func:`pinarms.optim.time_optimal`), and B leaves its start
   at the earliest instant ``t0 + d`` (``d`` in steps of ``delay_step``) for which the
   continuous proof with A **at the same instants** accepts the whole motion: B waiting at
   its start, then moving, against A moving (:meth:`MotionChecker.trajectory_valid`: samples
   every ``margin`` of the two arms' combined travel, A's travel bounded from its exact
   speeds and accelerations). A start inside A's sweep has no such instant. The delays are
   first screened in batches of :data:`DELAY_BLOCK` (:data:`DELAY_SAMPLES` instants each, the
   sphere cover then coal, :meth:`MotionChecker.batch_collides`): a delay with an instant
   closer than the margin is proven not to clear and skips its proof.

:func:`plan_two_arms` tries :func:`plan_around` and, when it finds nothing (no path, or no
start instant up to A's end), plans both arms in their joint space (:func:`plan_motion`
with two arms: A from its trajectory's start to its end, B from its start to its goal).
Every result is re-checked by the cell's own continuous time check with both arms moving
(:func:`pinarms.robots.cell.check_motion`).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence

import numpy as np

from pinarms.optim.errors import InvalidSettings, NoPathFound, PlanningError
from pinarms.optim.motion.checker import MotionChecker, TimedArm
from pinarms.optim.motion.ends import check_end
from pinarms.optim.motion.plan import plan_motion
from pinarms.optim.motion.request import MotionRequest
from pinarms.optim.motion.result import MotionPlan, MotionStatus
from pinarms.planning import Trajectory
from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.robots.cell import Cell
    from pinarms.robots.cell.motion_report import MotionCheck

__all__ = ["AroundPlan", "TwoArmPlan", "plan_around", "plan_two_arms", "DELAY_SAMPLES"]

#: Instants per start delay at which :func:`plan_around` screens the delays before proving them.
DELAY_SAMPLES = 64
#: Start delays screened in one batch (the first that clears is usually among the first few blocks).
DELAY_BLOCK = 8


@dataclass(frozen=True, eq=False)
class AroundPlan:
    """Arm B planned around timed arms (see the module docstring).

    Attributes:
        arm: B's name; ``moving``: the :class:`TimedArm` s it avoids; ``t0``: when B may
            leave [s, cell time]; ``delay``: how long it waits there for them [s].
        plan: B's geometric path and its time-optimal timing (a :class:`MotionPlan` made
            with the moving arms parked at their ends).
        trajectory: B's joint trajectory in cell time (``start_time = t0``: the wait, then
            the move).
        check: the cell's continuous check with B and the moving arms together.
        delays_tried: the start delays proven not to clear, before the one used.
    """

    cell: Cell = field(repr=False)
    arm: str
    moving: tuple
    t0: float
    delay: float
    plan: MotionPlan = field(repr=False)
    trajectory: Trajectory = field(repr=False)
    check: MotionCheck = field(repr=False)
    delays_tried: int
    seconds: dict = field(repr=False)

    @property
    def end_time(self) -> float:
        """When B arrives [s, cell time]."""
        return float(self.trajectory.end_time)

    @property
    def duration(self) -> float:
        """B's motion time without the wait [s]."""
        return float(self.plan.duration)


@dataclass(frozen=True, eq=False)
class TwoArmPlan:
    """The outcome of :func:`plan_two_arms`: which method worked and each arm's trajectory.

    Attributes:
        method: ``"around"`` (B planned around A's trajectory, A unchanged) or ``"joint"``
            (both planned together; A's path changed, its ends kept).
        trajectories: ``{arm: Trajectory}``; ``offsets``: ``{arm: offset}`` [s] to play them
            with (:class:`pinarms.robots.cell.ArmMotion`: the cell time at which each trajectory's
            ``start_time`` is played).
        around: the :class:`AroundPlan` (``None`` when it failed); ``joint``: the two-arm
            :class:`MotionPlan` (``None`` when not needed).
        attempts: ``(method, outcome)`` in order.
        check: the cell's continuous check of both arms together.
    """

    method: str
    trajectories: dict
    offsets: dict
    around: AroundPlan | None = field(repr=False)
    joint: MotionPlan | None = field(repr=False)
    attempts: tuple
    check: MotionCheck = field(repr=False)

    @property
    def end_time(self) -> float:
        """When the last arm arrives [s, cell time]."""
        return max(self.offsets[a] + t.duration for a, t in self.trajectories.items())


def _timed_arms(cell: Any, moving: Any) -> tuple[TimedArm, ...]:
    if isinstance(moving, TimedArm):
        return (moving,)
    if isinstance(moving, Mapping):
        out = []
        for name, value in moving.items():
            traj, offset = (value if isinstance(value, tuple) else (value, 0.0))
            out.append(TimedArm(cell.arm(name).name, traj, float(offset)))
        return tuple(out)
    return tuple(moving)


def _waiting(trajectory: Trajectory, q0: np.ndarray, t0: float, delay: float) -> Trajectory:
    """``trajectory`` played from ``t0 + delay``, the arm at rest at ``q0`` from ``t0`` (cell time)."""
    knots = trajectory.knot_times - trajectory.start_time
    C = trajectory.coefficients
    if delay <= 0.0:
        return Trajectory(knots + t0, C)
    wait = np.zeros((1, C.shape[1], C.shape[2]))
    wait[0, 0] = q0
    return Trajectory(np.concatenate([[t0], knots + t0 + delay]), np.concatenate([wait, C]))


def _screened_delays(together: MotionChecker, trajectory: Trajectory, x0: np.ndarray, t0: float,
                     delays: np.ndarray, t_end: float) -> np.ndarray:
    """``(K,)`` bool: the start delays with an instant (of :data:`DELAY_SAMPLES` from ``t0`` to the
    later end) at which B, leaving after that delay, is closer than the margin to something (A
    at the same instant included): proven not to clear. One batch for every delay."""
    rows = []
    for d in delays:
        moved = _waiting(trajectory, x0, float(t0), float(d))
        t = np.linspace(float(t0), max(float(moved.end_time), float(t_end)), DELAY_SAMPLES)
        q = np.asarray(moved.sample(np.minimum(t, moved.end_time))[0], dtype=float).reshape(t.size, -1)
        rows.append(np.column_stack([q, t]))
    X = np.concatenate(rows)
    return together.batch_collides(together.full(X)).reshape(len(delays), DELAY_SAMPLES).any(axis=1)


def plan_around(request: MotionRequest,
                moving: Mapping[str, Trajectory | tuple[Trajectory, float]] | Sequence[TimedArm], *,
                t0: float = 0.0, delay_step: float = 0.05, screen: bool = True,
                progress: Callable[[str], None] | None = None) -> AroundPlan:
    """Plan the request's arm (B) from its start (ready at cell time ``t0``) to its goal around the ``moving`` arms.

    Args:
        request: B's motion (one arm; :class:`.request.MotionRequest`: its options and limits,
            ``hold`` the cell configuration of the arms neither planned nor moving).
        moving: ``{arm: trajectory}``, ``{arm: (trajectory, offset)}`` or :class:`TimedArm` s:
            the arms that follow their own trajectories meanwhile (cell time = offset +
            trajectory time − its start; they hold their ends outside).
        t0: when B may leave its start [s, cell time].
        delay_step: resolution of the start delay [s].
        screen: screen the delays in batches before proving them (module docstring; proofs of
            failure only, the same delay kept); ``False``: every delay proven in turn.

    Raises:
        InvalidInput: a request for two arms, no moving arm.
        StartInCollision: B's start touches a moving arm at ``t0``.
        NoPathFound: no path around the moving arms' end configuration, or no start delay up
            to their end that clears their motion (the message says which).
        GoalInCollision, ...: the other statuses of :func:`plan_motion`, raised
            (:meth:`.result.MotionPlan.raise_for_status`).
    """
    t_all = time.perf_counter()
    say = progress or (lambda _m: None)
    if not isinstance(request, MotionRequest) or len(request.arms) != 1:
        raise InvalidInput("plan_around takes the MotionRequest of one arm (plan both together with plan_motion)")
    cell, arms, o = request.cell, request.arms, request.options
    timed = _timed_arms(cell, moving)
    if not timed:
        raise InvalidInput("plan_around needs at least one moving arm (use plan_motion otherwise)")
    ok = isinstance(delay_step, (int, float)) and not isinstance(delay_step, bool) and np.isfinite(delay_step)
    if not ok or delay_step <= 0.0:
        raise InvalidSettings(f"delay_step must be a positive number of seconds, got {delay_step!r}")
    base = cell.hold if request.hold is None else np.array(request.hold)
    parked = base.copy()
    for m in timed:
        parked[cell.arm(m.arm).q_slice] = m.trajectory.sample(m.trajectory.end_time)[0]
    together = MotionChecker(cell, arms, margin=o.margin, self_margin=o.self_margin, hold=base, moving=timed)
    x0 = np.array(request.start)
    together.span_turns(x0[None])  # continuous joints at any angle (docs/motion.md), as in plan_motion
    check_end(together, np.append(x0, t0), "start")
    say("planning the path around the other arm(s) parked at the end of their motion")
    # no re-check of the motion against A parked: the motion kept is checked against A moving
    plan = plan_motion(dataclasses.replace(request, hold=parked, options=dataclasses.replace(o, recheck=False)))
    if plan.status is MotionStatus.START_IN_COLLISION:
        raise NoPathFound(f"arm {arms[0]!r} starts where {[m.arm for m in timed]} end their motion ({plan.reason}): "
                          "it cannot wait there; plan both arms together", planner="",
                          time_limit=o.time_limit) from plan.error
    plan.raise_for_status()
    together.span_turns(plan.trajectory.position_range())  # the path's continuous joints: within the box
    t = time.perf_counter()
    t_end = max(m.offset + m.trajectory.duration for m in timed)
    delays = np.arange(0.0, max(t_end - t0, 0.0) + delay_step, delay_step)
    chosen = None
    rejected = np.zeros(0, dtype=bool)
    for k, d in enumerate(delays):
        if k == rejected.size:  # the next block of delays screened at once
            block = delays[k : k + DELAY_BLOCK]
            more = (_screened_delays(together, plan.trajectory, x0, float(t0), block, t_end) if screen
                    else np.zeros(block.size, dtype=bool))
            rejected = np.append(rejected, more)
        if rejected[k]:
            continue
        candidate = _waiting(plan.trajectory, x0, float(t0), float(d))
        if together.trajectory_valid(candidate, float(t0)).ok:
            chosen = (k, float(d), candidate)
            break
    seconds = dict(plan.seconds)
    seconds["delay"] = time.perf_counter() - t
    if chosen is None:
        raise NoPathFound(
            f"arm {arms[0]!r}: its path around {[m.arm for m in timed]} parked at their ends is clear, but no start "
            f"delay from 0 to {delays[-1]:.2f} s (step {delay_step:g} s) keeps the margin while they move: its start "
            "lies in their sweep", planner=plan.planner, time_limit=o.time_limit, seconds=plan.seconds["search"],
            states=plan.states, goals=1)
    k, d, trajectory = chosen
    say(f"leaves {d:.2f} s after {t0:.2f} s; checking both arms together")
    t = time.perf_counter()
    check = _check_together(cell, {arms[0]: (trajectory, trajectory.start_time)}, timed, together)
    seconds["check_together"] = time.perf_counter() - t
    seconds["total"] = time.perf_counter() - t_all
    return AroundPlan(cell=cell, arm=arms[0], moving=timed, t0=float(t0), delay=d, plan=plan, trajectory=trajectory,
                      check=check, delays_tried=k, seconds=seconds)


def _check_together(cell: Any, planned: Mapping[str, tuple], timed: tuple, checker: MotionChecker) -> Any:
    from pinarms.robots.cell.motion import ArmMotion

    motions = [ArmMotion(name, traj, offset) for name, (traj, offset) in planned.items()]
    motions += [ArmMotion(m.arm, m.trajectory, m.offset) for m in timed]
    check = cell.check_motion(motions, margin=checker.margin, clearance=0.0, hold=checker.hold)
    if not check.collision_free:
        raise PlanningError(f"the two-arm motion failed the cell's continuous check: {check.summary()}")
    return check


def plan_two_arms(request: MotionRequest, other: str, other_trajectory: Trajectory, *, other_offset: float = 0.0,
                  t0: float = 0.0, progress: Callable[[str], None] | None = None) -> TwoArmPlan:
    """Plan the request's arm (B) while ``other`` (A) follows ``other_trajectory``; both together if that fails.

    First :func:`plan_around` (A keeps its trajectory). If it finds nothing, both arms are
    planned in their joint space with :func:`plan_motion` (the request's options and limits),
    both leaving at ``t0``: A from where its trajectory has it at ``t0`` to the trajectory's
    last configuration, B from its start to its goal (a joint goal). A's own path and timing
    are then replaced.

    Raises:
        InvalidInput: a request for two arms, or a pose goal when both must be planned together.
        NoPathFound, GoalInCollision, ...: the joint plan's status, raised
            (:meth:`.result.MotionPlan.raise_for_status`).
    """
    if not isinstance(request, MotionRequest) or len(request.arms) != 1:
        raise InvalidInput("plan_two_arms takes the MotionRequest of one arm (B); A is other and other_trajectory")
    cell, arm = request.cell, request.arms[0]
    attempts = []
    try:
        around = plan_around(request, {other: (other_trajectory, other_offset)}, t0=t0, progress=progress)
        attempts.append(("around", f"leaves after {around.delay:.2f} s, arrives at {around.end_time:.3f} s"))
        return TwoArmPlan("around", {arm: around.trajectory, other: other_trajectory},
                          {arm: around.trajectory.start_time, other: other_offset}, around, None, tuple(attempts),
                          around.check)
    except NoPathFound as exc:
        attempts.append(("around", str(exc)))
    if progress:
        progress("planning both arms together")
    tr = other_trajectory
    now = float(np.clip(t0 - other_offset + tr.start_time, tr.start_time, tr.end_time))
    a_start = np.asarray(tr.sample(now)[0], dtype=float)  # where A is when both leave
    a_end = np.asarray(tr.sample(tr.end_time)[0], dtype=float)
    both = MotionRequest(cell, (other, arm), {other: a_start, arm: np.array(request.start)},
                         {other: a_end, arm: np.array(request.goal)}, options=request.options, hold=request.hold,
                         limits=request.limits)
    joint = plan_motion(both, progress=progress).raise_for_status()
    attempts.append(("joint", f"both arms together, {joint.duration:.3f} s"))
    na = cell.arm(other).nq
    traj = joint.trajectory
    ta = Trajectory(traj.knot_times + t0, traj.coefficients[:, :, :na])
    tb = Trajectory(traj.knot_times + t0, traj.coefficients[:, :, na:])
    return TwoArmPlan("joint", {other: ta, arm: tb}, {other: t0, arm: t0}, None, joint, tuple(attempts), joint.check)
