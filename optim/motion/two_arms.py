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

Both take one frozen request (:class:`AroundRequest`, :class:`TwoArmRequest`, checked when
built: bad input raises there) and return a plan whose ``status`` is a
:class:`~pinarms.optim.motion.result.MotionStatus` as :func:`plan_motion`'s: ``solved``, or what
planning found (start in collision with a moving arm, no path, no start delay that clears the
moving arms' sweep, goal in collision, limits not met, the re-check failed), with the ``reason``
in words; ``raise_for_status()`` raises it as the project's error.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence

import numpy as np

from pinarms.optim.errors import EndpointInCollision, InfeasibleProblem, InvalidSettings, NoPathFound, PlanningError
from pinarms.optim.motion.checker import MotionChecker, TimedArm
from pinarms.optim.motion.ends import check_end
from pinarms.optim.motion.plan import plan_motion
from pinarms.optim.motion.request import MotionRequest
from pinarms.optim.motion.result import MotionPlan, MotionStatus
from pinarms.planning import Trajectory
from pinarms.errors import InvalidInput, UnreachableTarget

if TYPE_CHECKING:
    from pinarms.robots.cell import Cell
    from pinarms.robots.cell.motion_report import MotionCheck

__all__ = ["AroundRequest", "AroundPlan", "TwoArmRequest", "TwoArmPlan", "plan_around", "plan_two_arms",
           "DELAY_SAMPLES"]

#: Instants per start delay at which :func:`plan_around` screens the delays before proving them.
DELAY_SAMPLES = 64
#: Start delays screened in one batch (the first that clears is usually among the first few blocks).
DELAY_BLOCK = 8


@dataclass(frozen=True, eq=False)
class AroundRequest:
    """Arm B's motion around arms that follow their own timed trajectories (:func:`plan_around`).

    Attributes:
        motion: B's motion (one arm; :class:`.request.MotionRequest`: its options and limits,
            ``hold`` the cell configuration of the arms neither planned nor moving).
        moving: ``{arm: trajectory}``, ``{arm: (trajectory, offset)}`` or :class:`TimedArm` s:
            the arms that follow their own trajectories meanwhile (cell time = offset +
            trajectory time − its start; they hold their ends outside); kept as :class:`TimedArm` s.
        t0: when B may leave its start [s, cell time].
        delay_step: resolution of the start delay [s].
        screen: screen the delays in batches before proving them (module docstring; proofs of
            failure only, the same delay kept); ``False``: every delay proven in turn.

    Raises:
        InvalidInput: a motion that is not one arm's :class:`MotionRequest`, no moving arm.
        InvalidSettings: ``delay_step`` not a positive number of seconds.
    """

    motion: MotionRequest
    moving: Mapping[str, Trajectory | tuple[Trajectory, float]] | Sequence[TimedArm]
    t0: float = 0.0
    delay_step: float = 0.05
    screen: bool = True

    def __post_init__(self) -> None:
        if not isinstance(self.motion, MotionRequest) or len(self.motion.arms) != 1:
            raise InvalidInput("plan_around takes the MotionRequest of one arm (plan both together with plan_motion)")
        timed = _timed_arms(self.motion.cell, self.moving)
        if not timed:
            raise InvalidInput("plan_around needs at least one moving arm (use plan_motion otherwise)")
        object.__setattr__(self, "moving", timed)
        step = self.delay_step
        ok = isinstance(step, (int, float)) and not isinstance(step, bool) and np.isfinite(step)
        if not ok or step <= 0.0:
            raise InvalidSettings(f"delay_step must be a positive number of seconds, got {step!r}")
        if not np.isfinite(float(self.t0)):
            raise InvalidInput(f"t0 must be a finite time [s], got {self.t0!r}")


@dataclass(frozen=True, eq=False)
class AroundPlan:
    """Arm B planned around timed arms (see the module docstring), or why not.

    Attributes:
        status: a :class:`MotionStatus` (``solved``, or what planning found); ``reason``: why it is
            not solved, in words; ``error``: that failure as the exception :meth:`raise_for_status` raises.
            Not solved: ``cell``, ``arm`` and ``moving`` are set, the others may be None.
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
    t0: float | None = None
    delay: float | None = None
    plan: MotionPlan | None = field(default=None, repr=False)
    trajectory: Trajectory | None = field(default=None, repr=False)
    check: MotionCheck | None = field(default=None, repr=False)
    delays_tried: int | None = None
    seconds: dict | None = field(default=None, repr=False)
    status: MotionStatus = MotionStatus.SOLVED
    reason: str = ""
    error: Exception | None = field(default=None, repr=False)

    def raise_for_status(self) -> AroundPlan:
        """The plan itself when solved; else raise its failure (:class:`pinarms.optim.StartInCollision`,
        :class:`pinarms.optim.NoPathFound`, ...; the message is :attr:`reason`)."""
        if self.status is MotionStatus.SOLVED:
            return self
        if self.error is not None:
            raise self.error
        raise PlanningError(f"{self.status.value}: {self.reason}")

    @property
    def end_time(self) -> float:
        """When B arrives [s, cell time]."""
        return float(self.raise_for_status().trajectory.end_time)

    @property
    def duration(self) -> float:
        """B's motion time without the wait [s]."""
        return float(self.raise_for_status().plan.duration)


@dataclass(frozen=True, eq=False)
class TwoArmRequest:
    """Arm B's motion (``motion``, one arm) while ``other`` (A) follows ``other_trajectory``, played from cell
    time ``other_offset`` [s]; B may leave at ``t0`` [s] (:func:`plan_two_arms`).

    Raises:
        InvalidInput: a motion that is not one arm's :class:`MotionRequest`, ``other`` not another arm
            of the cell, a trajectory that is not one, an offset or ``t0`` that is not a finite time.
    """

    motion: MotionRequest
    other: str
    other_trajectory: Trajectory
    other_offset: float = 0.0
    t0: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.motion, MotionRequest) or len(self.motion.arms) != 1:
            raise InvalidInput("plan_two_arms takes the MotionRequest of one arm (B); A is other and other_trajectory")
        names = [a.name for a in self.motion.cell.arms]
        if self.other not in names or self.other == self.motion.arms[0]:
            raise InvalidInput(f"other must be another arm of cell {self.motion.cell.name!r} than "
                               f"{self.motion.arms[0]!r}; arms: {', '.join(names)}, got {self.other!r}")
        if not isinstance(self.other_trajectory, Trajectory):
            raise InvalidInput(f"other_trajectory must be a pinarms.planning.Trajectory, got "
                               f"{type(self.other_trajectory).__name__}")
        for name in ("other_offset", "t0"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                    or not np.isfinite(value):
                raise InvalidInput(f"{name} must be a finite time [s], got {value!r}")


@dataclass(frozen=True, eq=False)
class TwoArmPlan:
    """The outcome of :func:`plan_two_arms`: which method worked and each arm's trajectory, or why none.

    Attributes:
        status: a :class:`MotionStatus` (``solved``, or the joint plan's / the first failure's status);
            ``reason`` in words; ``error``: the exception :meth:`raise_for_status` raises.
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

    method: str | None = None
    trajectories: dict | None = None
    offsets: dict | None = None
    around: AroundPlan | None = field(default=None, repr=False)
    joint: MotionPlan | None = field(default=None, repr=False)
    attempts: tuple = ()
    check: MotionCheck | None = field(default=None, repr=False)
    status: MotionStatus = MotionStatus.SOLVED
    reason: str = ""
    error: Exception | None = field(default=None, repr=False)

    def raise_for_status(self) -> TwoArmPlan:
        """The plan itself when solved; else raise its failure (:meth:`AroundPlan.raise_for_status`)."""
        if self.status is MotionStatus.SOLVED:
            return self
        if self.error is not None:
            raise self.error
        raise PlanningError(f"{self.status.value}: {self.reason}")

    @property
    def end_time(self) -> float:
        """When the last arm arrives [s, cell time]."""
        plan = self.raise_for_status()
        return max(plan.offsets[a] + t.duration for a, t in plan.trajectories.items())


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


def plan_around(request: AroundRequest, *, progress: Callable[[str], None] | None = None) -> AroundPlan:
    """Plan the request's arm (B) from its start (ready at cell time ``request.t0``) to its goal around the
    ``request.moving`` arms (:class:`AroundRequest`; module docstring).

    Returns:
        :class:`AroundPlan`; its ``status`` says ``solved`` or why not, with the reason: B's start
        touching a moving arm at ``t0`` (``start in collision``), no path around the moving arms'
        end configuration or no start delay up to their end that clears their motion (``no path``;
        the reason says which), or the other statuses of :func:`plan_motion` (goal in collision,
        limits not met, ...), or the check of both arms together failing (``recheck failed``).
    """
    t_all = time.perf_counter()
    timed, arm = request.moving, request.motion.arms[0]
    try:
        return _around(request, progress or (lambda _m: None), t_all)
    except (PlanningError, UnreachableTarget, InfeasibleProblem) as exc:
        return AroundPlan(cell=request.motion.cell, arm=arm, moving=timed, t0=float(request.t0),
                          status=_status_of(exc), reason=str(exc), error=exc)


def _status_of(exc: Exception) -> MotionStatus:
    """The :class:`MotionStatus` of a planning failure (as :func:`plan_motion` reports it)."""
    if isinstance(exc, EndpointInCollision):
        return {"start": MotionStatus.START_IN_COLLISION, "hold": MotionStatus.HOLD_IN_COLLISION}.get(
            exc.which, MotionStatus.GOAL_IN_COLLISION)
    if isinstance(exc, UnreachableTarget):
        return MotionStatus.GOAL_UNREACHABLE
    if isinstance(exc, NoPathFound):
        return MotionStatus.NO_PATH
    if isinstance(exc, InfeasibleProblem):
        return MotionStatus.LIMITS_NOT_MET
    return MotionStatus.RECHECK_FAILED


def _around(around: AroundRequest, say: Callable[[str], None], t_all: float) -> AroundPlan:
    """:func:`plan_around`'s work; its failures raised (the caller makes them statuses)."""
    request, timed, t0, delay_step = around.motion, around.moving, float(around.t0), float(around.delay_step)
    cell, arms, o = request.cell, request.arms, request.options
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
            more = (_screened_delays(together, plan.trajectory, x0, float(t0), block, t_end) if around.screen
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


def plan_two_arms(request: TwoArmRequest, *, progress: Callable[[str], None] | None = None) -> TwoArmPlan:
    """Plan the request's arm (B) while ``request.other`` (A) follows its trajectory; both together if that fails.

    First :func:`plan_around` (A keeps its trajectory). If it finds no path (``no path``: no path
    around A's end, or no start instant that clears A's sweep), both arms are planned in their
    joint space with :func:`plan_motion` (the request's options and limits), both leaving at
    ``t0``: A from where its trajectory has it at ``t0`` to the trajectory's last configuration,
    B from its start to its goal (a joint goal). A's own path and timing are then replaced.

    Returns:
        :class:`TwoArmPlan`; ``status`` ``solved`` (``method`` says which worked), else the status of
        :func:`plan_around` when it failed otherwise than ``no path`` (e.g. B's start in collision
        with A), or the joint plan's status, with the reason.

    Raises:
        InvalidInput: a pose goal when both must be planned together (bad requests raise when built:
            :class:`TwoArmRequest`).
    """
    motion, other, tr, other_offset, t0 = (request.motion, request.other, request.other_trajectory,
                                           float(request.other_offset), float(request.t0))
    cell, arm = motion.cell, motion.arms[0]
    attempts = []
    around = plan_around(AroundRequest(motion, {other: (tr, other_offset)}, t0=t0), progress=progress)
    if around.status is MotionStatus.SOLVED:
        attempts.append(("around", f"leaves after {around.delay:.2f} s, arrives at {around.end_time:.3f} s"))
        return TwoArmPlan("around", {arm: around.trajectory, other: tr},
                          {arm: around.trajectory.start_time, other: other_offset}, around, None, tuple(attempts),
                          around.check)
    attempts.append(("around", around.reason))
    if around.status is not MotionStatus.NO_PATH:
        return TwoArmPlan(around=around, attempts=tuple(attempts), status=around.status, reason=around.reason,
                          error=around.error)
    if progress:
        progress("planning both arms together")
    now = float(np.clip(t0 - other_offset + tr.start_time, tr.start_time, tr.end_time))
    a_start = np.asarray(tr.sample(now)[0], dtype=float)  # where A is when both leave
    a_end = np.asarray(tr.sample(tr.end_time)[0], dtype=float)
    both = MotionRequest(cell, (other, arm), {other: a_start, arm: np.array(motion.start)},
                         {other: a_end, arm: np.array(motion.goal)}, options=motion.options, hold=motion.hold,
                         limits=motion.limits)
    joint = plan_motion(both, progress=progress)
    if joint.status is not MotionStatus.SOLVED:
        attempts.append(("joint", joint.reason))
        return TwoArmPlan(around=around, joint=joint, attempts=tuple(attempts), status=joint.status,
                          reason=joint.reason, error=joint.error)
    attempts.append(("joint", f"both arms together, {joint.duration:.3f} s"))
    na = cell.arm(other).nq
    traj = joint.trajectory
    ta = Trajectory(traj.knot_times + t0, traj.coefficients[:, :, :na])
    tb = Trajectory(traj.knot_times + t0, traj.coefficients[:, :, na:])
    return TwoArmPlan("joint", {other: ta, arm: tb}, {other: t0, arm: t0}, around, joint, tuple(attempts), joint.check)
