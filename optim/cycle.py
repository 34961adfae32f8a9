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

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pinarms.optim.caps import LIFT_STEP_RANGE, MAX_CLEARANCE, MAX_DWELL, MIN_MARGIN, number_setting
from pinarms.optim.errors import InvalidLimits, InvalidSettings
from pinarms.optim.problem import check_limit
from pinarms.optim.timing import TimingResult, minimize_time
from pinarms.planning import Trajectory, joint_waypoints
from pinarms.planning.trajectory import Peaks
from pinarms.robots.errors import InvalidInput, UnreachableTarget
from pinarms.robots.ties import argmin_tied

__all__ = ["CYCLE_KINDS", "CYCLE_APPROACHES", "LINE_NAMES", "CycleResult", "PickPlace", "plan_cycle"]

#: Trajectory families a cycle can be timed with (``"3-5-3"`` only without transfer vias).
CYCLE_KINDS = ("multi-quintic", "quintic-bspline", "3-5-3")

#: How the tcp approaches and leaves pick and place: through the lift points in joint space, or on
#: straight vertical lines (:mod:`optim.straight_approach`).
CYCLE_APPROACHES = ("joint", "straight")

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
            (0 to :data:`optim.caps.MAX_DWELL`).
        via: transfer waypoints between "above pick" and "above place" (positions (3,) or
            poses (4, 4), in order); the return move passes them in reverse.
        orientation: tool orientation (3, 3) of the targets given as positions; default
            :func:`robots.layout.default_orientation` (tool pointing down on six-axis arms,
            the neutral orientation on SCARA, gantry and koji arm).

    Raises:
        InvalidInput: a malformed point, NaN/inf, ``lift <= 0``; ``SettingOutOfRange`` (an
            ``InvalidInput``): ``dwell`` outside 0 … :data:`optim.caps.MAX_DWELL`.
    """

    pick: Any
    place: Any
    lift: float = 0.05
    dwell: float = 0.2
    via: tuple = ()
    orientation: Any = field(default=None)

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

    def poses(self, robot: Any) -> np.ndarray:
        """Waypoints (4 + len(via), 4, 4) of the move to place, tcp → base [m], in :attr:`names` order."""
        R = self.orientation
        if R is None and any(p.shape == (3,) for p in (self.pick, self.place, *self.via)):
            from pinarms.robots.layout import default_orientation

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
        moves: the timings of the move to place and the move to pick (:class:`optim.TimingResult`).
        trajectory: the whole cycle: dwell at pick, move to place, dwell at place, move to pick.
        peaks: exact peaks of ``trajectory`` (velocity, acceleration, jerk per joint).
        vmax, amax, jmax: the limits used (nq,) (None: not limited).
        line_deviation: (4,) largest tcp distance [m] from the straight vertical segment
            while travelling it, per :data:`LINE_NAMES`.
        branches: (2 k - 1,) closed-form IK branch label of each joint via point
            (``robot.ik_branches``; -1 for arms solved numerically).
        approach: ``"joint"`` or ``"straight"`` (straight vertical lines at pick and place;
            ``moves`` are then :class:`optim.straight_approach.StraightMove`).
        joint_cycle_time: with ``approach="straight"``, the joint-space cycle's time [s] under
            the same limits (None otherwise).
        payload: the payload carried on the move to place (:class:`robots.Payload`), or None.
        torque_limit: torque limits (nq,) [N·m or N] the moves were timed under, or None.
        cell_report: with ``plan_cycle(..., cell=...)``, how the cycle keeps its clearance
            (:class:`optim.cell_cycle.CellCycleReport`); else None.
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
    payload: Any = None
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
    cell_report: Any = field(default=None, repr=False)

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


def _hold(q: np.ndarray, seconds: float) -> Trajectory:
    """The arm at rest at ``q`` for ``seconds``."""
    return Trajectory([0.0, seconds], np.asarray(q, dtype=float)[None, None, :])


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance [m] of points p (..., 3) from the segments a–b (..., 3)."""
    ab = b - a
    s = np.clip(np.sum((p - a) * ab, axis=-1) / np.sum(ab * ab, axis=-1), 0.0, 1.0)
    return np.linalg.norm(p - (a + s[..., None] * ab), axis=-1)


def _line_deviation(robot: Any, moves: tuple[TimingResult, TimingResult], ends: np.ndarray) -> np.ndarray:
    """(4,) max tcp distance [m] from the vertical segments, all samples in one batched FK."""
    samples = []
    for move in moves:
        t = move.knot_times
        for k in (0, len(t) - 2):  # first and last segment of each move
            samples.append(move.trajectory.sample(np.linspace(t[k], t[k + 1], LINE_SAMPLES))[0])
    q = np.concatenate(samples)
    p = np.asarray(robot.fk(q))[:, :3, 3].reshape(4, LINE_SAMPLES, 3)
    a = ends[:, 0][:, None]
    b = ends[:, 1][:, None]
    return _segment_distance(p, a, b).max(axis=1)


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
        from pinarms.optim.cell_cycle import plan_cycle_in_cell

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
        from pinarms.optim.straight_approach import straight_cycle

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

