"""The input of :func:`.plan.plan_motion`: one :class:`MotionRequest`, checked when built.

The ruckig shape (an input object, one call, a result with a status)::

    request = MotionRequest(cell, "aubo", start, goal,
                            options=MotionOptions(margin=0.01, time_limit=2.0, seed=0),
                            limits=MotionLimits(amax=5.0))
    plan = plan_motion(request)          # MotionPlan; plan.status is a MotionStatus

Each part checks its own values in its constructor: :class:`MotionOptions` the search and
check settings, :class:`MotionLimits` the limits the motion is timed under (each value alone),
and :class:`MotionRequest` what needs the cell: the arm names, the start and the goal as
joint vectors of the planned arms (or a tool pose), the limits' sizes and the torque limits
against the arms' inertials. A request that exists is a valid one; what is left for planning
is what only planning finds out (:class:`.result.MotionStatus`).

Units: m, rad, s (m/… for prismatic joints); poses are tool → world (the cell's root).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np

from pinarms.optim.errors import InvalidLimits, InvalidSettings
from pinarms.optim.motion.coal_batches import check_threads
from pinarms.optim.motion.ends import arm_joints, is_pose, planned_arms
from pinarms.optim.motion.search import PLANNERS
from pinarms.planning.path_constraints import JointAccelerationConstraint, JointVelocityConstraint
from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.robots.cell import Cell

__all__ = ["MotionOptions", "MotionLimits", "MotionRequest", "GOAL_CHOICES", "MAX_GRID", "motion_constraints"]

#: Most grid intervals of the time scaling (memory grows about 5.5 kB per interval).
MAX_GRID = 100_000
#: What a goal with several configurations (the IK branches of a pose) keeps (:attr:`MotionOptions.goals`).
GOAL_CHOICES = ("best", "first")


def _finite(value: object) -> bool:
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    return ok and bool(np.isfinite(float(value)))


@dataclass(frozen=True, eq=False)
class MotionOptions:
    """How the motion is searched, proven and reported.

    Attributes:
        margin: clearance [m] kept to fixtures and other arms everywhere along the motion (> 0);
            it also sets the step of the continuous check.
        self_margin: clearance [m] kept between two links of one arm (≥ 0; default 0: no contact).
        planner: an OMPL planner, one of :data:`pinarms.optim.motion.search.PLANNERS` (default RRT-Connect).
        time_limit: seconds the search may take (> 0).
        seed: seed of the search and the shortcutting, 0 to 2**63 − 1 (same seed, same path).
        threads: threads of the batched collision checks (1 to :data:`pinarms.optim.motion.checker.MAX_THREADS`).
        compiled: search RRT-Connect compiled on the sphere cover first where it is tight
            (:mod:`.geometry`); ``False``: OMPL with the exact checker alone.
        recheck: re-check the timed motion by the cell's own continuous check and report its
            clearance profile (``False``: ``check`` and ``clearance`` are ``None``; the path is
            proven by the exact checker either way).
        goals: with several goal configurations (the IK branches of a pose goal): ``"best"``
            (each other goal is also searched, compiled, with the compiled search's share of
            ``time_limit``, in increasing order of its straight move's time bound while it could
            still win, and the path with the shortest time bound is kept) or ``"first"`` (the
            path to the first one reached: a little less planning time).

    Raises:
        InvalidSettings: an unknown planner or ``goals``, a time limit that is not a positive
            number, a seed outside 0 … 2**63 − 1, ``threads`` out of range.
        InvalidInput: a margin that is not a finite number, ``margin <= 0`` or ``self_margin < 0``.
    """

    margin: float = 0.01
    self_margin: float = 0.0
    planner: str = "rrtconnect"
    time_limit: float = 1.0
    seed: int = 0
    threads: int = 1
    compiled: bool = True
    recheck: bool = True
    goals: str = "best"

    def __post_init__(self) -> None:
        key = str(self.planner).lower()
        if key not in PLANNERS:
            raise InvalidSettings(f"unknown planner {self.planner!r}; use one of {', '.join(PLANNERS)}")
        if not _finite(self.time_limit) or float(self.time_limit) <= 0.0:
            raise InvalidSettings(f"time_limit must be a positive number of seconds, got {self.time_limit!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or \
                not 0 <= int(self.seed) < 2**63:
            raise InvalidSettings(f"seed must be an integer from 0 to 2**63 - 1, got {self.seed!r}")
        if self.goals not in GOAL_CHOICES:
            raise InvalidSettings(f"goals must be 'first' or 'best', got {self.goals!r}")
        for name in ("margin", "self_margin"):
            if not _finite(getattr(self, name)) or float(getattr(self, name)) < 0.0:
                raise InvalidInput(f"{name} must be a finite number >= 0 [m], got {getattr(self, name)!r}")
        if float(self.margin) <= 0.0:
            raise InvalidInput("margin must be > 0 m: it also sets the step of the continuous edge check")
        object.__setattr__(self, "planner", key)
        object.__setattr__(self, "time_limit", float(self.time_limit))
        object.__setattr__(self, "seed", int(self.seed))
        object.__setattr__(self, "threads", check_threads(self.threads))
        object.__setattr__(self, "margin", float(self.margin))
        object.__setattr__(self, "self_margin", float(self.self_margin))
        object.__setattr__(self, "compiled", bool(self.compiled))
        object.__setattr__(self, "recheck", bool(self.recheck))


def _limit_values(value: float | np.ndarray | None, what: str) -> np.ndarray | None:
    """A limit as a float array, every value finite and > 0 (its size is checked by the request)."""
    if value is None:
        return None
    try:
        arr = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise InvalidLimits(f"{what} must be one positive number or one per planned joint, got {value!r}") from exc
    if arr.size == 0 or not np.all(np.isfinite(arr)) or np.any(arr <= 0.0):
        raise InvalidLimits(f"{what} must be one positive number or one per planned joint, got {value!r}")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class MotionLimits:
    """The limits the motion is timed under, and the grid of the time scaling.

    Attributes:
        vmax: joint velocity limits [rad/s or m/s], one number or one per planned joint
            (default ``None``: the URDF's).
        amax: joint acceleration limits [rad/s² or m/s²], one number or one per planned joint;
            ``None`` (default): the arms' ``Robot.acceleration_limit`` (velocity limit / 0.25 s
            unless set); ``False``: none (torques alone). ``plan.limits["amax_source"]`` says which.
        torque: ``True``: the URDF's effort limits where the arm has inertials; limits per
            planned joint [N·m or N]; ``False``: none.
        grid: grid intervals of the time scaling (1 to :data:`MAX_GRID`).

    Raises:
        InvalidLimits: a limit that is not finite and > 0, ``amax=True``.
        InvalidSettings: ``grid`` not an integer from 1 to :data:`MAX_GRID`.
    """

    vmax: float | np.ndarray | None = None
    amax: float | np.ndarray | bool | None = None
    torque: float | np.ndarray | bool = True
    grid: int = 200

    def __post_init__(self) -> None:
        if self.amax is True:
            raise InvalidLimits("amax must be None (the arms' limits), False (none) or limits [rad/s² or m/s²], "
                                "got True")
        object.__setattr__(self, "vmax", _limit_values(self.vmax, "vmax"))
        if self.amax is not False:
            object.__setattr__(self, "amax", _limit_values(self.amax, "amax"))
        if self.torque is None:
            object.__setattr__(self, "torque", False)
        elif self.torque is not True and self.torque is not False:
            object.__setattr__(self, "torque", _limit_values(self.torque, "torque"))
        grid = self.grid
        if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or not 1 <= int(grid) <= MAX_GRID:
            raise InvalidSettings(f"grid must be an integer from 1 to {MAX_GRID} (intervals of the time scaling; "
                                  f"about 5.5 kB each), got {grid!r}")
        object.__setattr__(self, "grid", int(grid))


def _sized(value: np.ndarray, n: int, what: str) -> np.ndarray:
    if value.size == 1:
        return np.full(n, float(value[0]))
    if value.size != n:
        raise InvalidLimits(f"{what} must be one positive number or {n} (one per planned joint), got {value.size}")
    return np.array(value, dtype=float)


def motion_constraints(cell: Cell, arms: Sequence[str], limits: MotionLimits) -> tuple[list, dict]:
    """The path constraints of the planned ``arms`` under ``limits`` (velocity, acceleration, torque, in
    that order) and the values used: ``{"vmax", "amax", "torque", "amax_source"}`` (arrays per planned
    joint, or ``None``).

    Raises:
        InvalidLimits: a limit of the wrong size, no URDF velocity or acceleration limit where one is
            needed, or velocity limits alone (infinite accelerations).
        MissingInertials: torque limits given for an arm without masses.
    """
    from pinarms.planning.torque import JointTorqueConstraint
    from pinarms.robots.dynamics import MissingInertials, check_inertials

    robots = [cell.arm(a).robot for a in arms]
    n = sum(r.nq for r in robots)
    v = _sized(limits.vmax, n, "vmax") if limits.vmax is not None else \
        np.concatenate([r.velocity_limit for r in robots])
    if not np.all(v > 0.0):
        raise InvalidLimits("the URDF gives no velocity limit for some planned joint: pass vmax [rad/s or m/s]")
    if limits.amax is None:  # the arms' acceleration limits (the stated default rule unless set on the robot)
        a = np.concatenate([np.asarray(r.acceleration_limit, dtype=float) for r in robots])
        a_source = "; ".join(dict.fromkeys(r.acceleration_source for r in robots))
        if not np.all(a > 0.0):
            raise InvalidLimits("some planned joint has no acceleration limit (its URDF gives no velocity limit): "
                                "pass amax [rad/s² or m/s²], or amax=False to time under torques alone")
    elif limits.amax is False:
        a, a_source = None, "none (amax=False)"
    else:
        a, a_source = _sized(limits.amax, n, "amax"), "given (amax)"
    cons = [JointVelocityConstraint(v)]
    if a is not None:
        cons.append(JointAccelerationConstraint(a))
    tau_used = None
    if limits.torque is not False:
        explicit = limits.torque is not True
        tau = _sized(limits.torque, n, "torque") if explicit else None
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


def _pose(value: np.ndarray) -> np.ndarray:
    T = np.array(value, dtype=float)
    if not np.all(np.isfinite(T)) or np.abs(T[:3, :3] @ T[:3, :3].T - np.eye(3)).max() > 1e-6 or \
            np.abs(T[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-9:
        raise InvalidInput("goal pose must be a finite homogeneous transform (4, 4): tool → world [m]")
    return T


@dataclass(frozen=True, eq=False)
class MotionRequest:
    """One motion to plan: where, which arm(s), from where to where, and how (module doc).

    Attributes:
        cell: the :class:`pinarms.robots.Cell` the motion is planned in.
        arm: the arm's name, or two names to plan both arms together in their joint space.
        start: the planned arms' joint coordinates ``(n,)`` (two arms: concatenated, or
            ``{arm: q}``); stored as the ``(n,)`` array.
        goal: joint coordinates like ``start``, or a tcp pose ``(4, 4)`` tool → world (one arm):
            every clear IK branch is a goal.
        options: :class:`MotionOptions` (margins, planner, time limit, seed, ...).
        limits: :class:`MotionLimits` (velocity, acceleration and torque limits, time grid).
        hold: cell configuration ``(nq,)`` of the arms not planned (default :attr:`Cell.hold`,
            each arm's hold pose from the cell description, else neutral).
        frame: the tool frame of a pose goal (default the arm's tcp).
        arms: the planned arms' names (set when built); ``constraints``, ``limit_values``: the
            path constraints and the limit values the motion is timed under (set when built,
            :func:`motion_constraints`).

    Raises:
        InvalidInput: an unknown arm, a start or goal of the wrong size or not finite, a pose
            goal for two arms or that is not a homogeneous transform, a frame other than the
            tcp, a joint goal equal to the start, ``options``/``limits`` of the wrong type.
        InvalidLimits, MissingInertials: as :func:`motion_constraints`.
    """

    cell: Cell
    arm: str | tuple[str, ...]
    start: np.ndarray | Mapping[str, np.ndarray]
    goal: np.ndarray | Mapping[str, np.ndarray]
    options: MotionOptions = field(default_factory=MotionOptions)
    limits: MotionLimits = field(default_factory=MotionLimits)
    hold: np.ndarray | None = None
    frame: str | None = None
    arms: tuple[str, ...] = field(init=False)
    constraints: tuple = field(init=False, repr=False)
    limit_values: dict = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not hasattr(self.cell, "arm") or not hasattr(self.cell, "check_motion"):
            raise InvalidInput(f"cell must be a robots.Cell, got {type(self.cell).__name__}")
        for name, kind in (("options", MotionOptions), ("limits", MotionLimits)):
            if not isinstance(getattr(self, name), kind):
                raise InvalidInput(f"{name} must be a {kind.__name__}, got {type(getattr(self, name)).__name__}")
        arms = planned_arms(self.cell, self.arm)
        object.__setattr__(self, "arms", arms)
        start = arm_joints(self.cell, arms, self.start, "start")
        start.setflags(write=False)
        object.__setattr__(self, "start", start)
        if is_pose(self.goal):
            if len(arms) != 1:
                raise InvalidInput("a pose goal needs one planned arm; give two arms' goals as joint vectors {arm: q}")
            robot = self.cell.arm(arms[0]).robot
            if self.frame is not None and self.frame not in ("tcp", robot.tcp_frame):
                raise InvalidInput(f"frame {self.frame!r}: pose goals are for the arm's tcp ({robot.tcp_frame!r})")
            goal = _pose(self.goal)
        else:
            goal = arm_joints(self.cell, arms, self.goal, "goal")
            if np.abs(goal - start).max() <= 1e-9:
                raise InvalidInput(f"the start already is the goal (joints {np.round(start, 6).tolist()}): there is "
                                   "nothing to plan; give a goal different from the start")
        goal.setflags(write=False)
        object.__setattr__(self, "goal", goal)
        if self.hold is not None:
            try:
                hold = np.array(self.cell.robot.check_q(self.hold)[0][0], dtype=float)
            except InvalidInput as exc:
                raise InvalidInput(f"hold (the cell configuration of the arms not planned): {exc}") from exc
            hold.setflags(write=False)
            object.__setattr__(self, "hold", hold)
        constraints, values = motion_constraints(self.cell, arms, self.limits)
        object.__setattr__(self, "constraints", tuple(constraints))
        object.__setattr__(self, "limit_values", values)

    @property
    def pose_goal(self) -> bool:
        """Whether the goal is a tool pose ``(4, 4)`` (else the planned arms' joints)."""
        return self.goal.ndim == 2
