"""A delta robot above the belt: conveyor tracking timed in its actuated space.

A delta (:mod:`pinarms.robots.delta`) is not a serial :class:`pinarms.robots.Robot`: its line picks are
timed here, from its closed form and closed-chain dynamics, and stored in the same
:class:`~.task_maps.TaskMap` the simulator reads (:mod:`~.delta_maps`).

A pick is the serial arm's rendezvous (:mod:`~.tracking`), on the platform:

- **approach**: from rest at the box to the pre-grasp point (``lift`` above the item's top) arriving
  *moving with the belt*: the platform centre's path a cubic Hermite in space whose start tangent is
  the chord and end tangent the belt's direction; its motor angles from the closed-form IK
  (primary branch), timed by the project's TOPP-RA under the three motors' speed, acceleration and
  torque limits (closed-chain torques, :func:`pinarms.optim.standard_cycle.delta_path_rows`) with the path
  speed at the end fixed to the belt's;
- **tracking**: the item's path plus a vertical quintic down and up (``descend`` s each, ``grasp``
  s between), checked at 41 instants against the motor range, speed and acceleration (finite
  differences of the closed-form IK in time);
- **leave**: from the end of the tracking segment (moving with the belt) to rest at the box, the
  item as payload at the tcp.

The fourth axis (the tool's turn about the vertical to the item's yaw, when the delta has one) is
driven by its own motor on the base through a telescopic shaft: it turns rest to rest during the
approach (and back during the leave) in the bang-bang time of :func:`tool_turn_time` under its
speed limit and an acceleration limit of :data:`TOOL_ACCELERATION_FACTOR` × that speed (assumed:
the URDF holds none); a move takes the longer of the platform's and the tool's time.
"""

from __future__ import annotations

import numpy as np

from pinarms.optim.errors import InfeasibleProblem
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.station import Station
from pinarms.optim.line.tracking import TrackingSpec
from pinarms.optim.standard_cycle import JointPathRows, delta_path_rows, time_rows
from pinarms.optim.standard_cycle.delta_cycle import TOOL_ACCELERATION_FACTOR, tool_turn_time  # the fourth axis
from pinarms.robots.delta import DeltaRobot, forward_position, inverse_position

__all__ = ["DeltaArm", "delta_pick_times", "platform_move_time", "platform_move_profile", "tracking_platform",
           "hermite_points", "tool_turn_time",
           "TOOL_ACCELERATION_FACTOR", "TRACK_SAMPLES"]

#: Instants at which the tracking segment is checked against the motor limits.
TRACK_SAMPLES = 41


class DeltaArm:
    """A delta as a :class:`~.station.Station`'s arm: ``delta`` the :class:`DeltaRobot`; ``nq`` its
    actuated coordinates (3 motors, + the tool axis), their ``velocity_limit``, ``acceleration_limit``,
    ``effort_limit``; ``can_yaw``: whether it turns its tool (the fourth axis); ``tcp_offset`` (3,)
    [m] the tcp from the platform centre (constant: the platform only translates)."""

    def __init__(self, delta: DeltaRobot) -> None:
        if not isinstance(delta, DeltaRobot):
            raise TypeError(f"DeltaArm takes a DeltaRobot (robots.delta.load_delta), got {type(delta).__name__}")
        self.delta, self.name, self.model = delta, delta.name, delta.model
        lim = delta.limits
        v, a, e = [lim.velocity] * 3, [lim.acceleration] * 3, [lim.torque] * 3
        self.can_yaw = delta.has_tool_axis
        if self.can_yaw:
            tv = float(delta.model.velocityLimit[delta.tool_q])
            v, a, e = v + [tv], a + [TOOL_ACCELERATION_FACTOR * tv], e + [float(delta.model.effortLimit[delta.tool_q])]
        self.nq = len(v)
        self.velocity_limit, self.acceleration_limit, self.effort_limit = (np.array(x, float) for x in (v, a, e))
        home = delta.home()
        self.tcp_offset = delta.tcp_position(home) - forward_position(delta.geometry, home[delta.motor_q])
        self._loaded: dict[float, DeltaRobot] = {}

    def __repr__(self) -> str:
        return f"DeltaArm({self.name!r}, tool axis: {self.can_yaw})"

    def carrying(self, mass: float) -> DeltaRobot:
        """The delta with ``mass`` [kg] at its tcp (cached per mass)."""
        m = float(mass)
        if m not in self._loaded:
            self._loaded[m] = self.delta.with_payload(m) if m > 0 else self.delta
        return self._loaded[m]


def hermite_points(p0: np.ndarray, p1: np.ndarray, m0: np.ndarray, m1: np.ndarray, length: float):
    """Cubic Hermite from p0 to p1 (tangents m0, m1 in t ∈ [0, 1]) as ``points(s)``, s = t · length."""

    def points(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = (np.asarray(s, float) / length)[:, None]
        h = [2 * t ** 3 - 3 * t ** 2 + 1, t ** 3 - 2 * t ** 2 + t, -2 * t ** 3 + 3 * t ** 2, t ** 3 - t ** 2]
        d = [6 * t ** 2 - 6 * t, 3 * t ** 2 - 4 * t + 1, -6 * t ** 2 + 6 * t, 3 * t ** 2 - 2 * t]
        dd = [12 * t - 6, 6 * t - 4, -12 * t + 6, 6 * t - 2]
        terms = (p0, m0, p1, m1)
        return (sum(c * v for c, v in zip(h, terms)), sum(c * v for c, v in zip(d, terms)) / length,
                sum(c * v for c, v in zip(dd, terms)) / length ** 2)

    return points


def platform_move_time(arm: DeltaArm, start: np.ndarray, end: np.ndarray, belt_dir: np.ndarray, speed: float,
                       onto: bool, mass: float, n: int) -> float:
    """Time [s] of the platform's move ``start`` → ``end`` (base frame), onto the belt (arriving with
    it) or off it (leaving with it), rest at the box end."""
    return float(platform_move_profile(arm, start, end, belt_dir, speed, onto, mass, n)[0].duration)


def platform_move_profile(arm: DeltaArm, start: np.ndarray, end: np.ndarray, belt_dir: np.ndarray, speed: float,
                          onto: bool, mass: float, n: int) -> tuple:
    """The time-optimal profile of :func:`platform_move_time` and its path: ``(GateTiming, points)``,
    ``points(s)`` the platform centre, its first and second derivatives along the path (``s`` [m])."""
    chord = end - start
    length = float(np.linalg.norm(chord))
    if length < 1e-6:
        raise InfeasibleProblem(f"{arm.name}: the box is at the pick point; move the box")
    along = length * belt_dir
    tangents = (chord, along) if onto else (along, chord)
    points = hermite_points(start, end, *tangents, length)
    s = np.linspace(0.0, length, n + 1)
    delta = arm.carrying(mass)
    q = inverse_position(delta.geometry, points(s)[0])
    lim = delta.limits
    if not np.all(np.isfinite(q)) or q.min() < lim.lower - 1e-9 or q.max() > lim.upper + 1e-9:
        raise InfeasibleProblem(f"{arm.name}: the move leaves the motors' range or the workspace")
    rows = JointPathRows(s, *delta_path_rows(delta, s, points))
    ends = {"sd_end": speed} if onto else {"sd_start": speed}
    return time_rows(rows, lim.velocity, lim.acceleration, lim.torque, **ends), points


def _check_tracking(arm: DeltaArm, pre: np.ndarray, velocity: np.ndarray, spec: TrackingSpec) -> None:
    """The tracking segment within the motors' range, speed and acceleration (module doc)."""
    t = np.linspace(0.0, spec.track_time, TRACK_SAMPLES)
    h = 1e-4

    def theta(x: np.ndarray) -> np.ndarray:
        return inverse_position(arm.delta.geometry, tracking_platform(arm, pre, velocity, spec, x))

    q, qp, qm = theta(t), theta(t + h), theta(t - h)
    lim = arm.delta.limits
    if not np.all(np.isfinite(q)) or q.min() < lim.lower - 1e-9 or q.max() > lim.upper + 1e-9:
        raise InfeasibleProblem(f"{arm.name}: the tracking segment leaves the motors' range or the workspace")
    for what, value, bound in (("speed", (qp - qm) / (2 * h), lim.velocity),
                               ("acceleration", (qp - 2 * q + qm) / h ** 2, lim.acceleration)):
        peak = float(np.nanmax(np.abs(value)))
        if not peak <= bound:
            raise InfeasibleProblem(f"{arm.name}: a motor's {what} {peak:.3g} exceeds its limit {bound:g} while "
                                    f"tracking: lengthen TrackingSpec.descend or slow the belt")


def tracking_platform(arm: DeltaArm, pre: np.ndarray, velocity: np.ndarray, spec: TrackingSpec,
                      x: np.ndarray) -> np.ndarray:
    """(F, 3) platform centre [m] (base frame) at instants ``x`` (F,) [s] of the tracking segment: the
    pre-grasp point ``pre`` (tcp) moving at the belt's ``velocity``, a vertical quintic down and up."""
    x = np.asarray(x, dtype=float)
    down = np.clip(x / spec.descend, 0.0, 1.0)
    up = np.clip((x - spec.descend - spec.grasp) / spec.descend, 0.0, 1.0)
    quintic = lambda r: 10 * r ** 3 - 15 * r ** 4 + 6 * r ** 5  # noqa: E731
    depth = spec.lift * (quintic(down) - quintic(up))
    return pre[None] + x[:, None] * velocity[None] - depth[:, None] * np.array([0.0, 0.0, 1.0]) - arm.tcp_offset


def delta_pick_times(station: Station, belt: Belt, spec: TrackingSpec, u: float, w: float, *, mass: float,
                     item_height: float, n: int = 24) -> tuple[float, float]:
    """(approach, leave) [s] of a delta's pick whose pre-grasp point is at belt coordinates (``u``, ``w``)
    (module doc), the tool turned by 0 (the item's yaw: :func:`tool_turn_time`).

    Raises:
        InfeasibleProblem: a point out of the workspace or the motors' range, or a limit broken while tracking.
    """
    arm = station.robot
    if not isinstance(arm, DeltaArm):
        raise TypeError(f"station {station.name!r} holds no DeltaArm")
    R = station.base_to_world[:3, :3]
    pre = station.world_to_base(belt.to_world(u, w, item_height + spec.lift))
    velocity = belt.speed * (R.T @ belt.direction)
    _check_tracking(arm, pre, velocity, spec)
    box = station.world_to_base(station.place.position) - arm.tcp_offset
    d = R.T @ belt.direction
    start = pre - arm.tcp_offset
    end = start + velocity * spec.track_time
    t_a = platform_move_time(arm, box, start, d, belt.speed, True, 0.0, n)
    t_c = platform_move_time(arm, end, box, d, belt.speed, False, mass, n)
    return t_a, t_c
