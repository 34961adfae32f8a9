"""A delta's pick as a motion: its actuated angles over time, for the line's page and session.

:func:`~.delta_tracking.delta_pick_times` times a delta's pick; :func:`delta_pick_motion` gives the
same pick as samples of the actuated coordinates (three motor angles, and the tool angle of the
fourth axis), on the same paths and profiles:

- **approach** (``times[0]``): the platform on its cubic Hermite from rest above the box to the
  pre-grasp point, arriving with the belt, along the time-optimal profile
  (:func:`~.delta_tracking.platform_move_profile`, sampled by
  :func:`pinarms.optim.standard_cycle.timing.profile_position`); the tool turns rest to rest from 0 to the item's yaw
  (:func:`~.tracking.tool_yaw`) in :func:`~.delta_tracking.tool_turn_time`. The longer of the two sets
  the approach: the platform then waits at the box first (as the task maps time it);
- **tracking** (``times[1]``): :func:`~.delta_tracking.tracking_platform`, the tool at the yaw;
- **leave** (``times[2]``): to rest at the box with the item as payload, the tool turning back;
- **release** (``times[3]``): at rest at the box.

Motor angles from the closed-form IK (primary branch). Units: m, s, rad; platform positions in the
station's base frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinarms.optim.errors import InfeasibleProblem
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.delta_tracking import DeltaArm, platform_move_profile, tool_turn_time, tracking_platform
from pinarms.optim.line.station import Station
from pinarms.optim.line.tracking import TrackingSpec, tool_yaw
from pinarms.optim.standard_cycle.delta_cycle import turn_angle
from pinarms.optim.standard_cycle.timing import profile_position
from pinarms.robots.delta import inverse_position

__all__ = ["DeltaPickMotion", "delta_pick_motion", "delta_rest"]


@dataclass(frozen=True, eq=False)
class DeltaPickMotion:
    """One pick of a delta (module doc): ``times`` approach, tracking, leave, release [s]; ``t`` (N,) [s]
    from the start of the approach; ``actuated`` (N, 3|4) motor angles (and tool angle) [rad]."""

    station: str
    times: tuple[float, float, float, float]
    t: np.ndarray
    actuated: np.ndarray

    @property
    def duration(self) -> float:
        return float(sum(self.times))

    def sample(self, t: np.ndarray) -> np.ndarray:
        """Actuated coordinates at ``t`` (F,) [s] (linear between samples, held at the ends): (F, 3|4)."""
        return np.stack([np.interp(t, self.t, col) for col in self.actuated.T], axis=1)


def delta_rest(station: Station) -> np.ndarray:
    """Actuated coordinates (3,) or (4,) of the delta at rest above its box (tool at 0)."""
    arm = _arm(station)
    box = station.world_to_base(station.place.position) - arm.tcp_offset
    theta = inverse_position(arm.delta.geometry, box[None])[0]
    if not np.all(np.isfinite(theta)):
        raise InfeasibleProblem(f"{station.name}: the delta cannot reach its box {station.place.name!r}")
    return np.append(theta, 0.0) if arm.can_yaw else theta


def _arm(station: Station) -> DeltaArm:
    if not isinstance(station.robot, DeltaArm):
        raise TypeError(f"station {station.name!r} holds no DeltaArm")
    return station.robot


def delta_pick_motion(station: Station, belt: Belt, spec: TrackingSpec, u: float, w: float, *, mass: float,
                      item_height: float, yaw: float = 0.0, n: int = 24, hz: float = 100.0) -> DeltaPickMotion:
    """The pick whose pre-grasp point is at belt coordinates (``u``, ``w``) as a motion (module doc),
    sampled at ``hz`` [1/s] (segment ends included).

    Raises:
        InfeasibleProblem: a point out of the workspace or the motors' range.
    """
    arm = _arm(station)
    R = station.base_to_world[:3, :3]
    pre = station.world_to_base(belt.to_world(u, w, item_height + spec.lift))
    velocity = belt.speed * (R.T @ belt.direction)
    box = station.world_to_base(station.place.position) - arm.tcp_offset
    d = R.T @ belt.direction
    start = pre - arm.tcp_offset
    end = start + velocity * spec.track_time
    approach, into = platform_move_profile(arm, box, start, d, belt.speed, True, 0.0, n)
    leave, out = platform_move_profile(arm, end, box, d, belt.speed, False, mass, n)
    turn = tool_yaw(station, spec, yaw) if arm.can_yaw else 0.0
    t_turn = tool_turn_time(turn, arm.velocity_limit[-1], arm.acceleration_limit[-1]) if turn else 0.0
    t_a, t_l = max(approach.duration, t_turn), max(leave.duration, t_turn)
    times = (float(t_a), float(spec.track_time), float(t_l), float(spec.release))
    edges = np.cumsum((0.0,) + times)
    t = np.union1d(np.arange(0.0, edges[-1], 1.0 / hz), edges)
    p = np.empty((t.size, 3))
    tool = np.zeros(t.size)
    seg = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, 3)
    for k in range(4):
        sel = seg == k
        tau = t[sel] - edges[k]
        if k == 0:
            p[sel] = into(profile_position(approach, tau - (t_a - approach.duration)))[0]
            tool[sel] = turn_angle(turn, arm.velocity_limit[-1], arm.acceleration_limit[-1], tau) if turn else 0.0
        elif k == 1:
            p[sel] = tracking_platform(arm, pre, velocity, spec, tau)
            tool[sel] = turn
        elif k == 2:
            p[sel] = out(profile_position(leave, tau))[0]
            tool[sel] = turn - (turn_angle(turn, arm.velocity_limit[-1], arm.acceleration_limit[-1], tau)
                                if turn else 0.0)
        else:
            p[sel] = box
    theta = inverse_position(arm.delta.geometry, p)
    if not np.all(np.isfinite(theta)):
        raise InfeasibleProblem(f"{station.name}: the pick leaves the delta's workspace")
    actuated = np.column_stack([theta, tool]) if arm.can_yaw else theta
    return DeltaPickMotion(station.name, times, t, actuated)
