"""Conveyor tracking: one pick of a moving item and its place, time-optimal, from FK-checkable joints.

A pick is a **rendezvous**. From rest at its box, the arm moves to the *pre-grasp* point
(``lift`` m above the item's grasp point) and arrives there moving with the belt; then, still
moving with the belt, it descends (``descend`` s), closes the gripper (``grasp`` s), lifts
(``descend`` s): the *tracking segment*, whose tool path is the item's path plus a vertical
quintic (zero vertical speed and acceleration at its ends); then it moves to its box, arriving
at rest, and releases the item (``release`` s)::

    approach (time-optimal)  │ tracking (belt velocity + vertical) │ leave (time-optimal) │ release
    rest at box ─▶ pre-grasp │ descend · grasp · lift               │ ─▶ rest at box        │ hold

Approach and leave are joint-space cubic Hermite paths whose end tangents are the tracking
segment's joint velocities (``q̇ = J⁺ ṗ`` from the Jacobian), timed by the project's
time-optimal TOPP-RA (:func:`pinarms.optim.time_optimal`) with the path speed at that end fixed so
the joint velocities match exactly; limits: joint velocity, acceleration and — where the arm
has inertials — torque, with the item as payload on the leave move. The tracking segment's
joints are the arm's IK at dense instants (one branch, continuous), a clamped cubic spline in
time whose end velocities are the exact ``J⁺ ṗ``; it is checked against the same limits.

Tool orientation: the arm's default tool orientation (:func:`pinarms.robots.reach.layout.default_orientation`,
pointing down on a SCARA) turned about the vertical by the item's yaw (:func:`tool_yaw`, modulo the
gripper's symmetry) through the whole tracking segment; an arm without a hand rotation (a gantry
of three slides) grasps at its own fixed yaw.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.interpolate import CubicSpline

from pinarms.optim.errors import InfeasibleProblem
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.numbers import finite_number
from pinarms.optim.line.station import Station
from pinarms.planning import Trajectory
from pinarms.planning.joint_path import JointPath
from pinarms.errors import InvalidInput, UnreachableTarget

if TYPE_CHECKING:
    from pinarms.optim.topp.path_timing import PathTiming
    from pinarms.planning.path_constraints import PathConstraint
    from pinarms.robots import Robot

__all__ = ["TrackingSpec", "PickPlan", "plan_pick", "tracking_points", "ik_branch_labels", "tool_yaw", "can_yaw",
           "TRACK_SAMPLES", "POSITION_TOL", "PositionLimitError", "hand_joints", "tool_poses", "ik_path", "branch_label",
           "joint_rates", "hermite_path", "move_constraints", "timed_move", "check_rate_limits", "check_positions"]

#: IK instants per tracking segment (spline knots).
TRACK_SAMPLES = 41
#: How far [rad or m] a planned joint trajectory's exact extrema may pass the position limits.
POSITION_TOL = 1e-9

#: Version of the pick planner: stored task maps are keyed on it (raise it when a plan changes,
#: e.g. 2: picks leaving the joint position limits are infeasible), so none built before is reused.
PLAN_VERSION = 2


@dataclass(frozen=True)
class TrackingSpec:
    """How the arm picks (module doc): ``lift`` [m] above the grasp point, ``descend`` [s] each
    way, ``grasp`` [s] gripper closing while tracking, ``release`` [s] at the box,
    ``grid`` TOPP-RA grid intervals per move, ``yaw_period`` [rad] the gripper's symmetry about
    the vertical (π: two fingers grip an item at yaw and yaw + π alike; 2π: none)."""

    lift: float = 0.03
    descend: float = 0.2
    grasp: float = 0.1
    release: float = 0.1
    grid: int = 40
    yaw_period: float = float(np.pi)

    def __post_init__(self) -> None:
        if not (0.0 < finite_number(self.yaw_period, "yaw_period [rad] of the tracking spec") <= 2.0 * np.pi + 1e-12):
            raise InvalidInput(f"yaw_period [rad] of the tracking spec must be in (0, 2π] (π: a two-finger "
                               f"gripper), got {self.yaw_period!r}")
        for name in ("lift", "descend"):
            finite_number(getattr(self, name), f"{name} of the tracking spec", positive=True)
        for name in ("grasp", "release"):
            if finite_number(getattr(self, name), f"{name} [s] of the tracking spec") < 0.0:
                raise InvalidInput(f"{name} [s] of the tracking spec must be >= 0")

    @property
    def track_time(self) -> float:
        """Duration of the tracking segment [s]."""
        return 2.0 * self.descend + self.grasp


@dataclass(eq=False)
class PickPlan:
    """One planned pick (module doc). Times in s from the start of the approach.

    Attributes:
        station: the arm's name; ``u_pre``, ``w``: belt coordinates of the pre-grasp point [m];
        approach, leave: the :class:`pinarms.optim.PathTiming` of the two moves; ``tracking``: the
        tracking segment's :class:`pinarms.planning.Trajectory`; ``q_rest``: the arm at its box;
        :attr:`trajectory`: the whole pick (approach, tracking, leave, release), one
        :class:`pinarms.planning.Trajectory`; ``grasp_window``: (start, end) of the gripper closing [s]; ``times``: approach,
        tracking, leave, release [s].
    """

    station: str
    u_pre: float
    w: float
    approach: Any
    tracking: Trajectory
    leave: Any
    q_rest: np.ndarray
    grasp_window: tuple[float, float]
    times: tuple[float, float, float, float]

    @functools.cached_property
    def trajectory(self) -> Trajectory:
        hold = Trajectory([0.0, max(self.times[3], 1e-6)], self.q_rest[None, None, :])
        return self.approach.trajectory.concatenated(self.tracking, atol=1e-7) \
            .concatenated(self.leave.trajectory, atol=1e-7).concatenated(hold, atol=1e-7)

    @property
    def duration(self) -> float:
        return float(sum(self.times))


def _sigma(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x**3 * (10.0 - 15.0 * x + 6.0 * x * x)


def tracking_points(belt: Belt, spec: TrackingSpec, u_pre: float, w: float, z_grasp: float,
                    tau: np.ndarray) -> np.ndarray:
    """World tool points (N, 3) [m] of the tracking segment at its times ``tau`` [s]."""
    d, g = spec.descend, spec.grasp
    h = np.where(tau < d, 1.0 - _sigma(tau / d), np.where(tau <= d + g, 0.0, _sigma((tau - d - g) / d)))
    return belt.to_world(u_pre + belt.speed * tau, w, z_grasp + spec.lift * h)


def hand_joints(robot: Robot) -> np.ndarray:
    """(nq,) bool: joints that turn the tool without moving its point at neutral (SCARA joint 4)."""
    return np.linalg.norm(robot.jacobian(robot.neutral)[:3], axis=0) < 1e-9


def can_yaw(robot: Any) -> bool:
    """Whether the arm can turn its tool about the vertical (a hand joint: SCARA joint 4), i.e. its
    Jacobian's angular z row is not zero at neutral; a gantry of three slides cannot. An arm that says
    so itself (a ``can_yaw`` attribute: a delta's fourth axis, :class:`~.delta_tracking.DeltaArm`) is taken at its word."""
    own = getattr(robot, "can_yaw", None)
    if isinstance(own, bool):
        return own
    return bool(np.linalg.norm(robot.jacobian(robot.neutral)[5]) > 1e-9)


def tool_yaw(station: Station, spec: "TrackingSpec", yaw: float) -> float:
    """The hand angle [rad] about the vertical, relative to the tool's default, that grasps an item at
    ``yaw`` [rad] (belt frame): ``yaw`` reduced by the gripper's symmetry ``spec.yaw_period`` into
    [-period/2, period/2); 0 for an arm that cannot yaw (:func:`can_yaw`: it grasps at its own yaw)."""
    y = finite_number(yaw, "item yaw [rad]")
    if not can_yaw(station.robot):
        return 0.0
    per = spec.yaw_period
    return float((y + per / 2.0) % per - per / 2.0)


def tool_poses(station: Station, p_world: np.ndarray, yaw: float = 0.0) -> np.ndarray:
    """Tool poses (N, 4, 4) in the station's base frame at world points ``p_world`` (N, 3) [m]: the arm's default
    tool orientation turned by ``yaw`` [rad] about the base's vertical."""
    from pinarms.robots.reach.layout import default_orientation

    c, s = np.cos(yaw), np.sin(yaw)
    Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    R = Rz @ default_orientation(station.robot)  # turned about the base's vertical (upright bases)
    T = np.tile(np.eye(4), (p_world.shape[0], 1, 1))
    T[:, :3, :3] = R
    T[:, :3, 3] = station.world_to_base(p_world)
    return T


def ik_path(station: Station, poses: np.ndarray, q_ref: np.ndarray, branch: int | None = None) -> np.ndarray:
    """Joint configurations (N, nq) on one branch, starting nearest ``q_ref``; raises UnreachableTarget.

    ``branch``: the closed form's branch label to start on (:meth:`pinarms.robots.Robot.ik_branches`);
    None: the rest configuration's branch where it reaches, else the nearest solution."""
    robot = station.robot
    if robot.has_analytic_ik:
        sols = robot.ik_all(poses, q_ref=q_ref)
        out = np.empty((poses.shape[0], robot.nq))
        prev = q_ref
        q0, labels = robot.ik_branches(poses[0], q_ref)
        want = branch_label(robot, q_ref) if branch is None else int(branch)
        same = q0[labels == want]
        if same.shape[0]:  # stay on the rest configuration's branch (maps continuous over the belt)
            prev = same[np.argmin(np.abs(same - q_ref).sum(axis=1))]
        elif branch is not None:
            raise UnreachableTarget(f"arm {station.name!r} cannot reach tool point "
                                    f"{np.round(poses[0, :3, 3], 4).tolist()} (base frame) on IK branch {branch}")
        for k, s in enumerate(sols):
            if s.shape[0] == 0:
                raise UnreachableTarget(f"arm {station.name!r} cannot reach tool point "
                                        f"{np.round(poses[k, :3, 3], 4).tolist()} (base frame)")
            out[k] = s[np.argmin(np.abs(s - prev).sum(axis=1))]
            prev = out[k]
        return out
    out = np.empty((poses.shape[0], robot.nq))
    prev = q_ref
    turn = np.asarray(getattr(robot, "continuous", np.zeros(robot.nq, bool)), bool)
    for k in range(poses.shape[0]):
        q = robot.ik(poses[k], prev)
        # the solver wraps continuous joints into (-π, π]: the turn nearest the previous angle keeps the path continuous
        q[turn] = prev[turn] + (q[turn] - prev[turn] + np.pi) % (2.0 * np.pi) - np.pi
        out[k] = prev = q
    return out


def branch_label(robot: Robot, q: np.ndarray) -> int:
    """The closed-form branch label of configuration ``q`` (-1 when none matches)."""
    sols, labels = robot.ik_branches(robot.fk(q), q)
    if sols.shape[0] == 0:
        return -1
    k = int(np.argmin(np.abs(sols - q).sum(axis=1)))
    return int(labels[k]) if np.abs(sols[k] - q).max() < 1e-6 else -1


def joint_rates(station: Station, q: np.ndarray, v_world: np.ndarray) -> np.ndarray:
    """Joint velocities (nq,) that move the tcp at ``v_world`` [m/s] with no rotation."""
    J = station.robot.jacobian(q)  # (6, nq) in the base frame (linear; angular)
    twist = np.concatenate([station.base_to_world[:3, :3].T @ v_world, np.zeros(3)])
    qd, *_ = np.linalg.lstsq(J, twist, rcond=None)
    return qd


def hermite_path(q0: np.ndarray, m0: np.ndarray, q1: np.ndarray, m1: np.ndarray, robot: Robot) -> JointPath:
    """The cubic Hermite joint path from ``q0`` to ``q1`` (nq,) over s in [0, 1] with end tangents ``m0``, ``m1``."""
    c = np.stack([q0, m0, 3.0 * (q1 - q0) - 2.0 * m0 - m1, 2.0 * (q0 - q1) + m0 + m1])
    return JointPath([0.0, 1.0], c[None], robot=robot)


def move_constraints(station: Station, mass: float) -> list[PathConstraint]:
    """The station's joint velocity and acceleration limits, and its torque limits (with ``mass`` [kg] as payload)
    where its limits say so: the constraints every timed move of a pick keeps."""
    from pinarms.planning.path_constraints import JointAccelerationConstraint, JointVelocityConstraint
    from pinarms.planning.torque import JointTorqueConstraint

    lim = station.limits
    cons = [JointVelocityConstraint(lim["vmax"]), JointAccelerationConstraint(lim["amax"])]
    if lim["torque"]:
        robot = station.robot.with_payload(mass) if mass > 0.0 else station.robot
        cons.append(JointTorqueConstraint(robot, np.asarray(station.robot.effort_limit, float)))
    return cons


def timed_move(station: Station, q0: np.ndarray, qd0: np.ndarray, q1: np.ndarray, qd1: np.ndarray, mass: float,
               grid: int) -> PathTiming:
    """Time-optimal move q0 → q1 starting with joint velocity qd0 and ending with qd1 (one of them 0)."""
    from pinarms.optim.topp.path_timing import time_optimal

    chord = q1 - q0
    arm = ~hand_joints(station.robot)  # the path's scale from the joints that move the tool point,
    if not np.any(arm):                 # so the hand's angle (the item's yaw) leaves their path unchanged
        arm = np.ones(chord.size, bool)
    L = float(np.linalg.norm(chord[arm]))
    moving = qd1 if np.any(qd1) else qd0
    speed = float(np.linalg.norm(moving[arm]))
    k = L / speed if speed > 1e-12 and L > 1e-9 else 1.0
    m0, m1 = (chord, k * qd1) if np.any(qd1) else (k * qd0, chord)
    path = hermite_path(q0, m0, q1, m1, station.robot)
    ends = {"end_speed": 1.0 / k} if np.any(qd1) else {"start_speed": 1.0 / k}
    return time_optimal(path, move_constraints(station, mass), grid=grid, **ends)


def check_rate_limits(station: Station, traj: Trajectory, what: str, spec: TrackingSpec, speed: float) -> None:
    """InfeasibleProblem when ``traj`` (a tracking segment) needs a joint beyond its velocity or
    acceleration limit, with the figures and the descend [s] that would lower the worst of them to
    its limit if it all came from the vertical move (acceleration ∝ 1/descend², velocity ∝ 1/descend)."""
    peaks = traj.peaks()
    lim = station.limits
    ratios = np.stack([peaks.velocity / lim["vmax"], peaks.acceleration / lim["amax"]])
    if not np.any(ratios > 1 + 1e-9):
        return
    kind, j = np.unravel_index(int(np.argmax(ratios)), ratios.shape)
    unit = station.robot.joint_units[j]
    peak, limit, rate = ((peaks.velocity[j], lim["vmax"][j], f"{unit}/s") if kind == 0 else
                         (peaks.acceleration[j], lim["amax"][j], f"{unit}/s²"))
    longer = spec.descend * float(ratios[kind, j]) ** (1.0 if kind == 0 else 0.5)
    longer = np.ceil(longer * 1.05 * 100.0) / 100.0  # 5 % over, to the next 10 ms
    raise InfeasibleProblem(
        f"arm {station.name!r}: the {what} needs joint {j + 1} ({station.robot.joint_names[j]}) at {peak:.3g} {rate} "
        f"against its limit {limit:.3g} {rate} (belt too fast here for its descend): lengthen the descend "
        f"(TrackingSpec.descend, now {spec.descend:g} s) to {longer:g} s or more, or slow the belt (--speed, "
        f"Belt.speed, now {speed:g} m/s); the part of the motion that follows the belt only a slower belt lowers")


class PositionLimitError(InfeasibleProblem):
    """A planned move's joint trajectory leaves the arm's position limits (an infeasible pick)."""


def check_positions(station: Station, traj: Trajectory, what: str) -> None:
    """Raise :class:`PositionLimitError` where the exact extrema of ``traj`` leave the position
    limits by more than :data:`POSITION_TOL` (never clamps)."""
    lo, hi = traj.position_range()
    robot = station.robot
    lower, upper = robot.position_limits  # continuous joints: none
    over = np.flatnonzero((lo < lower - POSITION_TOL) | (hi > upper + POSITION_TOL))
    if over.size:
        j = int(over[0])
        value = lo[j] if lo[j] < lower[j] - POSITION_TOL else hi[j]
        raise PositionLimitError(
            f"arm {station.name!r}: the {what} takes joint {j + 1} ({robot.joint_names[j]}) to {value:.6g}, "
            f"outside its position limits [{lower[j]:.6g}, {upper[j]:.6g}]: no pick here on this "
            "IK branch (try another branch, or move the arm or its box)")


def plan_pick(station: Station, belt: Belt, spec: TrackingSpec, u_pre: float, w: float, *,
              item_height: float = 0.04, mass: float = 0.0, q_rest: Any = None, branch: int | None = None,
              yaw: float = 0.0) -> PickPlan:
    """Plan one pick whose pre-grasp point is at belt coordinates (``u_pre``, ``w``) (module doc).

    ``q_rest``: the arm's configuration at its box (default: IK of the place point nearest neutral).
    ``branch``: the closed-form IK branch of the tracking segment (:func:`ik_branch_labels`; what a
    task map chose there, :meth:`pinarms.optim.line.TaskMap.branch_at`); None: the rest configuration's
    branch where it reaches the pre-grasp point, else the nearest solution; when that plan leaves the
    position limits, the other branches reaching the pre-grasp point are tried in label order and
    the first within them is returned. ``yaw`` [rad]: the
    item's yaw on the belt; the hand turns to :func:`tool_yaw` for the whole tracking segment.

    Raises:
        UnreachableTarget: a point of the tracking segment or the box out of reach.
        InfeasibleProblem: the belt is too fast for the arm there, a move cannot meet its limits, or
            the planned joint trajectory leaves the arm's position limits (:data:`POSITION_TOL`) on
            every IK branch tried.
    """
    robot = station.robot
    q_rest = rest_configuration(station) if q_rest is None else np.asarray(q_rest, float)
    tau = np.linspace(0.0, spec.track_time, TRACK_SAMPLES)
    p = tracking_points(belt, spec, u_pre, w, item_height, tau)
    poses = tool_poses(station, p, tool_yaw(station, spec, yaw))
    args = (station, belt, spec, u_pre, w, poses, mass, q_rest)
    try:
        return _plan_on_branch(*args, branch)
    except PositionLimitError as exc:
        if branch is not None or not robot.has_analytic_ik:
            raise
        first = exc
    for label in ik_branch_labels(station, p[:1]):  # the other branches at the pre-grasp point
        try:
            return _plan_on_branch(*args, label)
        except (UnreachableTarget, InfeasibleProblem):
            continue
    raise first


def _plan_on_branch(station: Station, belt: Belt, spec: TrackingSpec, u_pre: float, w: float, poses: np.ndarray,
                    mass: float, q_rest: np.ndarray, branch: int | None) -> PickPlan:
    """:func:`plan_pick` on one IK branch (None: as :func:`ik_path` chooses), position limits checked."""
    robot = station.robot
    tau = np.linspace(0.0, spec.track_time, TRACK_SAMPLES)
    q = ik_path(station, poses, q_rest, branch)
    qd_in = joint_rates(station, q[0], belt.velocity)
    qd_out = joint_rates(station, q[-1], belt.velocity)
    spline = CubicSpline(tau, q, axis=0, bc_type=((1, qd_in), (1, qd_out)))
    tracking = Trajectory(tau, np.ascontiguousarray(spline.c[::-1].transpose(1, 0, 2)))
    check_rate_limits(station, tracking, "tracking segment", spec, belt.speed)
    check_positions(station, tracking, "tracking segment")
    approach = timed_move(station, q_rest, np.zeros(robot.nq), q[0], qd_in, 0.0, spec.grid)
    check_positions(station, approach.trajectory, "approach move")
    leave = timed_move(station, q[-1], qd_out, q_rest, np.zeros(robot.nq), mass, spec.grid)
    check_positions(station, leave.trajectory, "leave move")
    tA = float(approach.duration)
    times = (tA, spec.track_time, float(leave.duration), spec.release)
    return PickPlan(station.name, float(u_pre), float(w), approach, tracking, leave, q_rest,
                    (tA + spec.descend, tA + spec.descend + spec.grasp), times)


def ik_branch_labels(station: Station, points_world: np.ndarray) -> tuple[int, ...]:
    """The closed-form IK branch labels reaching any of the tool points (N, 3) [m] (world) in
    the pick's orientation; ``(-1,)`` for an arm without a closed form (one branch)."""
    robot = station.robot
    if not robot.has_analytic_ik:
        return (-1,)
    poses = tool_poses(station, np.asarray(points_world, float).reshape(-1, 3))
    found: set[int] = set()
    for T in poses:
        found.update(int(b) for b in robot.ik_branches(T, robot.neutral)[1])
    return tuple(sorted(found)) or (-1,)


def rest_configuration(station: Station) -> np.ndarray:
    """The arm's configuration at rest at its box (IK of the place point, nearest neutral)."""
    pose = tool_poses(station, station.place.position[None])
    try:
        return ik_path(station, pose, station.robot.neutral)[0]
    except UnreachableTarget:
        raise UnreachableTarget(f"arm {station.name!r} cannot reach its place box {station.place.name!r} at "
                                f"{station.place.position.tolist()} m (world): move the box into its reach") from None
