"""The pick-and-place cycle's input and output: :class:`PickPlace` (the spec) and :class:`CycleResult`.

The data of :mod:`pinarms.optim.cycle` (planned by :func:`pinarms.optim.plan_cycle`), in a module of
their own so that every way of planning a cycle (joint space, straight vertical approach,
in a cell, around obstacles) shares them without importing the planner back (the helpers
they share, a hold at rest and the tcp's distance from the vertical segments, are in
:mod:`pinarms.optim.cycle.vertical`).

Units: m, rad, s (rad/s … or m/s … for prismatic joints).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from pinarms.optim.caps import MAX_DWELL, number_setting
from pinarms.optim.timing.segments import TimingResult
from pinarms.planning import Trajectory
from pinarms.planning.trajectory import Peaks
from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.optim.cycle.cell_report import CellCycleReport
    from pinarms.robots import Robot
    from pinarms.robots.payload import Payload

__all__ = ["CYCLE_KINDS", "CYCLE_APPROACHES", "CycleStatus", "LINE_NAMES", "LINE_SAMPLES", "CycleResult",
           "PickPlace"]

#: Trajectory families a cycle can be timed with (``"3-5-3"`` only without transfer vias).
CYCLE_KINDS = ("multi-quintic", "quintic-bspline", "3-5-3")

#: How the tcp approaches and leaves pick and place: through the lift points in joint space, or on
#: straight vertical lines (:mod:`pinarms.optim.cycle.straight`).
CYCLE_APPROACHES = ("joint", "straight")


class CycleStatus(enum.Enum):
    """How a cycle was planned (:attr:`CycleResult.status`; the value is the word the reports print).

    A cycle that cannot be planned raises instead (no IK solution at a waypoint, no timing, no
    re-planned cycle that keeps the cell's clearance: :func:`pinarms.optim.plan_cycle`).
    """

    #: as asked (without a cell, or its first check in the cell passed)
    OK = "ok"
    #: in a cell, the lift was raised or via points added to keep the clearance
    REPLANNED = "re-planned"
    #: in a cell, the transfer was planned round what blocks (:mod:`pinarms.optim.motion.transfer`)
    TRANSFER_PLANNED = "transfer planned"


#: The four vertical segments whose straightness :class:`CycleResult` reports, in cycle order.
LINE_NAMES = ("lift from pick", "lower to place", "lift from place", "lower to pick")

#: Samples per vertical segment for the straightness deviation.
LINE_SAMPLES = 201

_UP = np.array([0.0, 0.0, 1.0])


def _finite_number(value: Any, what: str) -> float:
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    x = float(value) if ok else float("nan")
    if not np.isfinite(x):
        raise InvalidInput(f"{what} must be a finite number, got {value!r}")
    return x


def _point(value: Any, what: str) -> np.ndarray:
    """A position (3,) [m] or a pose (4, 4) tcp → base [m], finite, as a float array."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be a position (3,) or a pose (4, 4) in m, got {value!r}") from exc
    if arr.shape not in ((3,), (4, 4)):
        raise InvalidInput(f"{what} must be a position (3,) or a pose (4, 4) in m, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InvalidInput(f"{what} holds NaN or inf: give finite coordinates in m")
    if arr.shape == (4, 4):
        R = arr[:3, :3]
        if np.abs(R @ R.T - np.eye(3)).max() > 1e-6 or np.linalg.det(R) < 0.0 or \
                np.abs(arr[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-9:
            raise InvalidInput(f"{what} is not a homogeneous transform (proper rotation, last row 0 0 0 1)")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class PickPlace:
    """One pick-and-place task of a packing line (the spec of :func:`plan_cycle`).

    Attributes:
        pick: where the tcp grasps: a position (3,) [m] in the robot's base frame, or a pose
            (4, 4) tcp → base [m].
        place: where the tcp releases, same form.
        lift: height [m] of the vertical approach and retreat at pick and place (> 0),
            along the base's +z.
        dwell: time [s] the arm stays at rest at the pick and at the place for the gripper
            (0 to :data:`pinarms.optim.caps.MAX_DWELL`).
        via: transfer waypoints between "above pick" and "above place" (positions (3,) or
            poses (4, 4), in order); the return move passes them in reverse.
        orientation: tool orientation (3, 3) of the targets given as positions; default
            :func:`pinarms.robots.reach.layout.default_orientation` (tool pointing down on six-axis arms,
            the neutral orientation on SCARA, gantry and koji arm).

    Raises:
        InvalidInput: a malformed point, NaN/inf, ``lift <= 0``; ``SettingOutOfRange`` (an
            ``InvalidInput``): ``dwell`` outside 0 … :data:`pinarms.optim.caps.MAX_DWELL`.
    """

    pick: np.ndarray
    place: np.ndarray
    lift: float = 0.05
    dwell: float = 0.2
    via: tuple = ()
    orientation: np.ndarray | None = field(default=None)

    def __post_init__(self) -> None:
        object.__setattr__(self, "pick", _point(self.pick, "pick"))
        object.__setattr__(self, "place", _point(self.place, "place"))
        lift = _finite_number(self.lift, "lift [m]")
        if lift <= 0.0:
            raise InvalidInput(f"lift [m] must be > 0 (the vertical approach/retreat height), got {self.lift!r}")
        dwell = number_setting(self.dwell, "dwell (gripper time at pick and place)", 0.0, MAX_DWELL, unit="s")
        object.__setattr__(self, "lift", lift)
        object.__setattr__(self, "dwell", dwell)
        via = self.via
        if isinstance(via, np.ndarray) and via.ndim in (2, 3):
            via = list(via)
        if not isinstance(via, (list, tuple)):
            raise InvalidInput(f"via must be a sequence of positions (3,) or poses (4, 4), got {type(via).__name__}")
        object.__setattr__(self, "via", tuple(_point(v, f"via point {k + 1}") for k, v in enumerate(via)))
        if self.orientation is not None:
            R = np.array(self.orientation, dtype=float) if np.ndim(self.orientation) == 2 else np.zeros(0)
            if R.shape != (3, 3) or not np.all(np.isfinite(R)) or np.abs(R @ R.T - np.eye(3)).max() > 1e-6 \
                    or np.linalg.det(R) < 0.0:
                raise InvalidInput(f"orientation must be a (3, 3) proper rotation matrix, got {self.orientation!r}")
            R.setflags(write=False)
            object.__setattr__(self, "orientation", R)

    @property
    def names(self) -> tuple[str, ...]:
        """Labels of the waypoints of the move to place: pick, above pick, via 1 …, above place, place."""
        return ("pick", "above pick", *(f"via {k + 1}" for k in range(len(self.via))), "above place", "place")

    def poses(self, robot: Robot) -> np.ndarray:
        """Waypoints (4 + len(via), 4, 4) of the move to place, tcp → base [m], in :attr:`names` order."""
        R = self.orientation
        if R is None and any(p.shape == (3,) for p in (self.pick, self.place, *self.via)):
            from pinarms.robots.reach.layout import default_orientation

            R = default_orientation(robot)

        def pose(p: np.ndarray) -> np.ndarray:
            if p.shape == (4, 4):
                return np.array(p)
            T = np.eye(4)
            T[:3, :3] = R
            T[:3, 3] = p
            return T

        pick, place = pose(self.pick), pose(self.place)
        up_pick, up_place = pick.copy(), place.copy()
        up_pick[:3, 3] += self.lift * _UP
        up_place[:3, 3] += self.lift * _UP
        return np.stack([pick, up_pick, *(pose(v) for v in self.via), up_place, place])


@dataclass(frozen=True, eq=False)
class CycleResult:
    """One planned pick-and-place cycle (see the module docstring).

    Attributes:
        robot: name of the robot.
        spec: the :class:`PickPlace` planned.
        names: labels of the cycle's waypoints, pick … place … pick (2 k - 1 of them).
        waypoints: (2 k - 1, 4, 4) tcp → base poses [m] of the full cycle.
        q_via: (2 k - 1, nq) joint via points [rad or m] (one IK branch; the return move's
            are the move to place's in reverse).
        moves: the timings of the move to place and the move to pick (:class:`pinarms.optim.TimingResult`).
        trajectory: the whole cycle: dwell at pick, move to place, dwell at place, move to pick.
        peaks: exact peaks of ``trajectory`` (velocity, acceleration, jerk per joint).
        vmax, amax, jmax: the limits used (nq,) (None: not limited).
        line_deviation: (4,) largest tcp distance [m] from the straight vertical segment
            while travelling it, per :data:`LINE_NAMES`.
        branches: (2 k - 1,) closed-form IK branch label of each joint via point
            (``robot.ik_branches``; -1 for arms solved numerically).
        approach: ``"joint"`` or ``"straight"`` (straight vertical lines at pick and place;
            ``moves`` are then :class:`pinarms.optim.cycle.straight.StraightMove`).
        joint_cycle_time: with ``approach="straight"``, the joint-space cycle's time [s] under
            the same limits (None otherwise).
        payload: the payload carried on the move to place (:class:`pinarms.robots.Payload`), or None.
        torque_limit: torque limits (nq,) [N·m or N] the moves were timed under, or None.
        cell_report: planned in a cell (:class:`pinarms.optim.CellSettings`), how the cycle keeps its clearance
            (:class:`pinarms.optim.cycle.in_cell.CellCycleReport`); else None.
        status: how it was planned (:class:`CycleStatus`).
    """

    robot: str
    spec: PickPlace
    names: tuple[str, ...]
    waypoints: np.ndarray = field(repr=False)
    q_via: np.ndarray = field(repr=False)
    moves: tuple[TimingResult, TimingResult] = field(repr=False)
    trajectory: Trajectory = field(repr=False)
    peaks: Peaks = field(repr=False)
    vmax: np.ndarray = field(repr=False)
    amax: np.ndarray | None = field(repr=False)
    jmax: np.ndarray | None = field(repr=False)
    line_deviation: np.ndarray = field(repr=False)
    branches: np.ndarray = field(repr=False)
    payload: Payload | None = None
    torque_limit: np.ndarray | None = field(default=None, repr=False)
    approach: str = "joint"
    joint_cycle_time: float | None = None

    @property
    def straight_cost(self) -> float | None:
        """Time [s] the straight approach adds to the joint-space cycle (None for a joint-space cycle)."""
        return None if self.joint_cycle_time is None else self.cycle_time - self.joint_cycle_time

    @property
    def line_cost(self) -> float | None:
        """Time [s] the four straight lines take beyond joint-space lines between the same configurations
        (same limits, same time scaling; None for a joint-space cycle)."""
        return None if self.approach != "straight" else float(sum(m.line_cost for m in self.moves))

    @property
    def torque_ratios(self) -> np.ndarray | None:
        """Refined torque peak / limit per joint (nq,) over both moves (loaded and empty), or None."""
        if self.torque_limit is None:
            return None
        return np.maximum(*(m.torque_ratios for m in self.moves))
    cell_report: CellCycleReport | None = field(default=None, repr=False)
    status: CycleStatus = CycleStatus.OK

    @property
    def one_branch(self) -> bool:
        """Every waypoint's IK solution on the same closed-form branch (False also when unknown)."""
        return bool(self.branches[0] >= 0 and np.all(self.branches == self.branches[0]))

    @property
    def move_times(self) -> np.ndarray:
        """(2,) durations [s] of the move to place and the move to pick."""
        return np.array([m.total for m in self.moves])

    @property
    def cycle_time(self) -> float:
        """Time [s] of one full cycle: both moves plus a dwell at pick and at place."""
        return float(self.move_times.sum() + 2.0 * self.spec.dwell)

    @property
    def picks_per_minute(self) -> float:
        """60 / :attr:`cycle_time`: one pick per cycle."""
        return 60.0 / self.cycle_time

    @property
    def max_line_deviation(self) -> float:
        """Largest of :attr:`line_deviation` [m]."""
        return float(np.max(self.line_deviation))

    @property
    def limit_ratios(self) -> dict[str, np.ndarray]:
        """Peak / limit per joint for each limit given (``"velocity"``, ``"acceleration"``, ``"jerk"``)."""
        out = {"velocity": self.peaks.velocity / self.vmax}
        if self.amax is not None:
            out["acceleration"] = self.peaks.acceleration / self.amax
        if self.jmax is not None:
            out["jerk"] = self.peaks.jerk / self.jmax
        return out

    def as_dict(self) -> dict[str, Any]:
        """JSON-able summary (SI units)."""
        return {
            "status": self.status.value,
            "robot": self.robot,
            "waypoints": [{"name": n, "position_m": T[:3, 3].tolist()} for n, T in zip(self.names, self.waypoints)],
            "q_via": self.q_via.tolist(),
            "move_times_s": self.move_times.tolist(),
            "segment_durations_s": [m.durations.tolist() for m in self.moves],
            "dwell_s": self.spec.dwell,
            "lift_m": self.spec.lift,
            "cycle_time_s": self.cycle_time,
            "picks_per_minute": self.picks_per_minute,
            "peaks": self.peaks.as_dict(),
            "limits": {"vmax": self.vmax.tolist(), "amax": None if self.amax is None else self.amax.tolist(),
                       "jmax": None if self.jmax is None else self.jmax.tolist()},
            "limit_ratios": {k: v.tolist() for k, v in self.limit_ratios.items()},
            "line_deviation_m": dict(zip(LINE_NAMES, self.line_deviation.tolist())),
            "max_line_deviation_m": self.max_line_deviation,
            "branches": self.branches.tolist(),
            "one_branch": self.one_branch,
            "payload": None if self.payload is None else self.payload.as_dict(),
            "torque_limit": None if self.torque_limit is None else self.torque_limit.tolist(),
            "torque_ratios": None if self.torque_limit is None else self.torque_ratios.tolist(),
            **({"cell": self.cell_report.as_dict()} if self.cell_report is not None else {}),
            "approach": self.approach,
            "joint_cycle_time_s": self.joint_cycle_time,
            "straight_cost_s": self.straight_cost,
            "line_cost_s": self.line_cost,
        }

