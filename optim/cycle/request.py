"""The input of a cycle plan: one :class:`CycleRequest`, its settings grouped and checked when built.

:func:`pinarms.optim.plan_cycle` takes one request (the ruckig way: an input object, one call, a
result with a status)::

    request = CycleRequest(arm, PickPlace(pick, place),
                           timing=CycleTiming(kind="quintic-bspline", amax=5.0),
                           load=CycleLoad(payload=0.5, torque_limits=True),
                           approach=CycleApproach("straight", tool_speed=0.5),
                           cell=CellSettings(cell, clearance=0.02))
    result = plan_cycle(request)

Each group checks its own values in its constructor (the project's errors, the caps of
:mod:`pinarms.optim.caps`), and the request checks what needs the robot: the limits per joint
(``vmax`` defaults to the URDF's) and the torque limits with the payload. A request that
exists is a valid one; what is left for planning is what only planning can find out (no IK
solution, no timing, no clearance).

Units: m, rad, s (rad/s … or m/s … for prismatic joints).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Mapping

import numpy as np

from pinarms.optim.caps import LIFT_STEP_RANGE, MAX_CLEARANCE, MIN_MARGIN, number_setting
from pinarms.optim.cycle.spec import CYCLE_APPROACHES, CYCLE_KINDS, PickPlace
from pinarms.optim.errors import InvalidLimits, InvalidSettings
from pinarms.optim.ga.problem import check_limit
from pinarms.optim.torque import torque_constraint
from pinarms.planning.torque import JointTorqueConstraint
from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.robots import Robot
    from pinarms.robots.cell import Cell
    from pinarms.robots.payload import Payload

__all__ = ["CycleTiming", "CycleLoad", "CycleApproach", "CellSettings", "CycleRequest"]

#: The optimisers a cycle's moves can be timed with (:func:`pinarms.optim.minimize_time`).
CYCLE_METHODS = ("exact", "ga")


@dataclass(frozen=True, eq=False)
class CycleTiming:
    """How each move is timed.

    Attributes:
        kind: trajectory family of each move, one of :data:`pinarms.optim.cycle.CYCLE_KINDS`
            (``"3-5-3"`` needs exactly 4 waypoints per move: no transfer vias).
        vmax, amax, jmax: limits per joint (scalar or (nq,)), rad/s, rad/s², rad/s³ (m/… for
            prismatic joints); ``vmax`` None: the robot's URDF limits; ``amax``/``jmax`` None:
            not limited. Checked against the robot by :class:`CycleRequest`.
        method: ``"exact"`` (deterministic scaling-law optimiser) or ``"ga"``, as
            :func:`pinarms.optim.minimize_time`; ``seed``: the optimiser's seed.

    Raises:
        InvalidInput: ``kind`` is not a cycle family. InvalidSettings: unknown ``method``.
    """

    kind: str = "multi-quintic"
    vmax: float | np.ndarray | None = None
    amax: float | np.ndarray | None = None
    jmax: float | np.ndarray | None = None
    method: str = "exact"
    seed: int = 0

    def __post_init__(self) -> None:
        if self.kind not in CYCLE_KINDS:
            raise InvalidInput(f"kind={self.kind!r} is not a cycle trajectory family: use one of {CYCLE_KINDS}")
        if self.method not in CYCLE_METHODS:
            raise InvalidSettings(f"method={self.method!r}: use 'exact' or 'ga'")


@dataclass(frozen=True, eq=False)
class CycleLoad:
    """What the arm carries and the torques it may use.

    Attributes:
        payload: what the gripper carries from pick to place: a mass [kg], a
            :class:`pinarms.robots.Payload` or its dict form (the move back is timed empty).
        torque_limits: ``True`` (the URDF's ``effort`` limits) or limits per joint [N·m or N]:
            both moves are also timed under joint-torque limits; ``False``: kinematic limits only.

    Raises:
        InvalidSettings: a payload without torque limits (a payload changes only torques).
    """

    payload: float | Payload | Mapping[str, object] | None = None
    torque_limits: bool | float | np.ndarray = False

    def __post_init__(self) -> None:
        if (self.torque_limits is None or self.torque_limits is False) and self.payload is not None:
            raise InvalidSettings("a payload changes only the torques: pass torque_limits=True (or limits) with it")


@dataclass(frozen=True, eq=False)
class CycleApproach:
    """How the tcp approaches and leaves pick and place.

    Attributes:
        approach: ``"joint"`` (through the lift points in joint space) or ``"straight"``
            (straight vertical lines, time-optimal along them; needs ``amax``:
            :mod:`pinarms.optim.cycle.straight`).
        tool_speed: with ``"straight"``, a tcp speed limit on the lines [m/s], or None.

    Raises:
        SettingOutOfRange: a ``tool_speed`` that is not > 0. InvalidInput: unknown ``approach``.
    """

    approach: str = "joint"
    tool_speed: float | None = None

    def __post_init__(self) -> None:
        _check_tool_speed(self.tool_speed)
        if self.approach not in CYCLE_APPROACHES:
            raise InvalidInput(f"approach={self.approach!r}: use one of {CYCLE_APPROACHES}")


def _check_tool_speed(tool_speed: float | None) -> None:
    if tool_speed is not None:
        number_setting(tool_speed, "tool_speed", 0.0, open_low=True, unit="m/s")


def check_cell_numbers(clearance: float, margin: float, lift_step: float) -> tuple[float, float, float]:
    """``(clearance, margin, lift_step)`` as floats in their ranges (:mod:`pinarms.optim.caps`), lift_step checked first."""
    lift_step = number_setting(lift_step, "lift_step (rise per re-planning attempt)", *LIFT_STEP_RANGE, unit="m")
    margin = number_setting(margin, "margin (resolution of the continuous check)", MIN_MARGIN, unit="m")
    clearance = number_setting(clearance, "clearance", 0.0, MAX_CLEARANCE, unit="m")
    return clearance, margin, lift_step


@dataclass(frozen=True, eq=False)
class CellSettings:
    """The cell a cycle must keep its clearance in (:mod:`pinarms.optim.cycle.in_cell`).

    Attributes:
        cell: a :class:`pinarms.robots.cell.Cell` holding the request's robot (``cell.arm(name).robot``);
            ``arm`` names the arm when the robot is not the cell's object.
        clearance: distance kept from the fixtures and the other arms [m] (0 … 1).
        hold: cell configuration of the other arms (default :attr:`Cell.hold`).
        margin: resolution of the continuous check [m] (≥ :data:`pinarms.optim.caps.MIN_MARGIN`).
        lift_step: rise of the lift per re-planning attempt [m] (:data:`pinarms.optim.caps.LIFT_STEP_RANGE`).
        plan_transfer: when raising the lift and via points cannot clear, plan the transfer
            round what blocks (:mod:`pinarms.optim.motion.transfer`).
        screen: reject an attempt by exact distances at its via points and a few timed states
            before timing it or checking it continuously (proofs of failure only: the same
            verdicts and kept cycle; ``False``: every attempt timed and checked in full).
        recheck: report the kept cycle's clearance from a second continuous check with the
            exact distance at every sample (``False``: from the check that kept it, which
            may stop at a proven bound below the true minimum; a layout search's candidates
            need no more).

    Raises:
        InvalidInput: no cell. SettingOutOfRange: ``lift_step``, ``margin`` or ``clearance``
            outside its range.
    """

    cell: Cell
    clearance: float = 0.02
    arm: str | None = None
    hold: np.ndarray | None = None
    margin: float = 0.005
    lift_step: float = 0.02
    plan_transfer: bool = True
    screen: bool = True
    recheck: bool = True

    def __post_init__(self) -> None:
        if self.cell is None or not hasattr(self.cell, "arms"):
            raise InvalidInput(f"CellSettings.cell must be a robots.cell.Cell, got {type(self.cell).__name__}")
        clearance, margin, lift_step = check_cell_numbers(self.clearance, self.margin, self.lift_step)
        object.__setattr__(self, "clearance", clearance)
        object.__setattr__(self, "margin", margin)
        object.__setattr__(self, "lift_step", lift_step)


def _velocity_limit(robot: Robot, vmax: float | np.ndarray | None) -> float | np.ndarray:
    """``vmax``, or the robot's URDF velocity limits when None (every joint must have one)."""
    if vmax is not None:
        return vmax
    v = np.asarray(robot.velocity_limit, dtype=float)
    if not np.all(v > 0.0):
        missing = [n for n, x in zip(robot.joint_names, v) if not x > 0.0]
        raise InvalidLimits(f"robot '{robot.name}' has no velocity limit for joint(s) {missing} in its URDF: "
                            "pass vmax (rad/s or m/s per joint)")
    return v


@dataclass(frozen=True, eq=False)
class CycleRequest:
    """One cycle to plan: the robot, the task and the settings (module doc).

    Attributes:
        robot: a :class:`pinarms.robots.Robot` (or an object with its IK/FK methods, ``nq``, ``name``,
            ``joint_names``, ``velocity_limit``).
        spec: the :class:`PickPlace` task.
        timing, load, approach: the settings groups (defaults: multi-quintic, exact, the URDF's
            velocity limits, no torque limits, joint-space approach).
        cell: :class:`CellSettings`, or None (the cycle ignores its surroundings).
        q_start: configuration (nq,) whose nearest IK solution is taken at the pick (it
            selects the IK branch of the whole cycle), or None.
        vmax, amax, jmax: the limits per joint the moves are timed under, (nq,) arrays or None
            (set when the request is built).
        torque: the torque limits with the payload carried (:class:`pinarms.planning.JointTorqueConstraint`),
            or None (set when the request is built).

    Raises:
        InvalidInput: ``spec`` is not a :class:`PickPlace`, a group of the wrong type, or
            ``kind="3-5-3"`` with transfer via points.
        InvalidLimits: a limit ≤ 0, NaN/inf or of the wrong shape, no ``vmax`` and the URDF
            has none, ``torque_limits=True`` and the URDF has no effort limit.
        InvalidSettings: torque limits for an object that is not a robot.
    """

    robot: Robot
    spec: PickPlace
    timing: CycleTiming = field(default_factory=CycleTiming)
    load: CycleLoad = field(default_factory=CycleLoad)
    approach: CycleApproach = field(default_factory=CycleApproach)
    cell: CellSettings | None = None
    q_start: np.ndarray | None = None
    vmax: np.ndarray = field(init=False, repr=False)
    amax: np.ndarray | None = field(init=False, repr=False)
    jmax: np.ndarray | None = field(init=False, repr=False)
    torque: JointTorqueConstraint | None = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.spec, PickPlace):
            raise InvalidInput(f"spec must be a PickPlace, got {type(self.spec).__name__}")
        for name, kind in (("timing", CycleTiming), ("load", CycleLoad), ("approach", CycleApproach)):
            if not isinstance(getattr(self, name), kind):
                raise InvalidInput(f"{name} must be a {kind.__name__}, got {type(getattr(self, name)).__name__}")
        if self.cell is not None and not isinstance(self.cell, CellSettings):
            raise InvalidInput(f"cell must be a CellSettings (or None), got {type(self.cell).__name__}")
        t = self.timing
        if t.kind == "3-5-3" and self.spec.via:
            raise InvalidInput(f"kind='3-5-3' times 4 waypoints per move, the spec has {len(self.spec.via)} transfer "
                               "via point(s) more: use 'multi-quintic' or 'quintic-bspline'")
        nq = int(self.robot.nq)
        object.__setattr__(self, "vmax", check_limit(_velocity_limit(self.robot, t.vmax), nq, "vmax", required=True))
        object.__setattr__(self, "amax", check_limit(t.amax, nq, "amax", required=False))
        object.__setattr__(self, "jmax", check_limit(t.jmax, nq, "jmax", required=False))
        object.__setattr__(self, "torque", torque_constraint(self.robot, self.load.torque_limits, self.load.payload))
