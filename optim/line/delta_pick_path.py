"""The path of a delta's pick, as one motion the cell's continuous check proves against the fixtures.

A delta's pick (:mod:`~.delta_tracking`) runs its platform along three pieces: the approach (a cubic
Hermite from the box to the pre-grasp point), the tracking segment (the item's path with the
vertical quintic down and up) and the leave (a Hermite back to the box). Against fixtures only the
path matters, not its timing: :func:`delta_pick_path` plays the three pieces one after the other on
a parameter ``τ ∈ [0, 3]`` (one unit each) as a :class:`pinarms.robots.delta.path_motion.PlatformPath`,
with a proven bound of ``|dp/dτ|``: for a Hermite piece the sum of its derivative's polynomial
coefficients (:func:`~pinarms.robots.delta.path_motion.tangent_bound`), for the tracking piece
``T (|v| + 1.875 lift / descend)`` (``T`` the tracking time, ``v`` the belt's velocity, 1.875 the
largest slope of the quintic ``10 r³ − 15 r⁴ + 6 r⁵``). The tool axis is held (its turn moves no body:
the tool lies on its axis). :meth:`pinarms.robots.cell.Cell.check_motion` of that motion is the
pick's fixture verdict (:func:`~.delta_maps.build_delta_map` with a cell).

:func:`delta_pick_plan` is the same pick on the clock (approach and leave along their time-optimal
profiles, :func:`~.delta_tracking.platform_move_profile`, the tracking segment in its own time, the
release held at the box), what the neighbour guard places beside another arm's pick: its platform's
speed bound is the path's largest ``|dp/ds|`` (exact, :func:`tangent_bound`) times the profile's
largest path speed (``ṡ`` is linear in time between the profile's grid points, so its largest value
is at one of them).
"""

from __future__ import annotations

import numpy as np

from dataclasses import dataclass

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.delta_tracking import platform_move_profile
from pinarms.optim.line.station import Station
from pinarms.optim.line.tracking import TrackingSpec
from pinarms.robots.delta.path_motion import PlatformPath, tangent_bound

__all__ = ["delta_pick_path", "delta_pick_plan", "DeltaPickPlan", "QUINTIC_SLOPE"]

#: Largest slope of the quintic ``10 r³ − 15 r⁴ + 6 r⁵`` on [0, 1] (at r = 1/2).
QUINTIC_SLOPE = 1.875


def _hermite(p0, p1, m0, m1):
    """``(points(t) -> (p, dp/dt), bound of |dp/dt|)`` of the cubic Hermite on t ∈ [0, 1]."""
    p0, p1, m0, m1 = (np.asarray(v, float) for v in (p0, p1, m0, m1))

    def points(t):
        t = np.asarray(t, float)[:, None]
        p = (2 * t ** 3 - 3 * t ** 2 + 1) * p0 + (t ** 3 - 2 * t ** 2 + t) * m0 + (-2 * t ** 3 + 3 * t ** 2) * p1 \
            + (t ** 3 - t ** 2) * m1
        d = (6 * t ** 2 - 6 * t) * p0 + (3 * t ** 2 - 4 * t + 1) * m0 + (-6 * t ** 2 + 6 * t) * p1 + (3 * t ** 2 - 2 * t) * m1
        return p, d

    return points, tangent_bound([m0, -6 * p0 - 4 * m0 + 6 * p1 - 2 * m1, 6 * p0 + 3 * m0 - 6 * p1 + 3 * m1])


def _pick_points(station: Station, belt: Belt, spec: TrackingSpec, u: float, w: float,
                 item_height: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The pick's platform points in the delta's base frame [m]: above the item at (``u``, ``w``), at the box,
    at the end of the tracking segment, and the belt's direction there."""
    R = station.base_to_world[:3, :3]
    pre = station.world_to_base(belt.to_world(u, w, item_height + spec.lift)) - station.robot.tcp_offset
    box = station.world_to_base(station.place.position) - station.robot.tcp_offset
    d = R.T @ belt.direction
    return pre, box, pre + belt.speed * d * spec.track_time, d


def delta_pick_path(station: Station, belt: Belt, spec: TrackingSpec, u: float, w: float, *,
                    item_height: float) -> PlatformPath:
    """The platform path of the pick at belt coordinates (``u``, ``w``) (module doc), in the delta's base frame."""
    arm = station.robot
    pre, box, end, d = _pick_points(station, belt, spec, u, w, item_height)
    velocity = belt.speed * d
    approach, g_a = _hermite(box, pre, pre - box, float(np.linalg.norm(pre - box)) * d)
    leave, g_c = _hermite(end, box, float(np.linalg.norm(box - end)) * d, box - end)
    T, z = spec.track_time, np.array([0.0, 0.0, 1.0])

    def depth(x, slope=False):
        down, up = np.clip(x / spec.descend, 0.0, 1.0), np.clip((x - spec.descend - spec.grasp) / spec.descend, 0.0, 1.0)
        if slope:
            ds = lambda r: 30 * r ** 2 - 60 * r ** 3 + 30 * r ** 4  # noqa: E731
            inside = lambda r: (r > 0.0) & (r < 1.0)  # noqa: E731
            return spec.lift / spec.descend * (ds(down) * inside(down) - ds(up) * inside(up))
        quintic = lambda r: 10 * r ** 3 - 15 * r ** 4 + 6 * r ** 5  # noqa: E731
        return spec.lift * (quintic(down) - quintic(up))

    def points(tau):
        tau = np.atleast_1d(np.asarray(tau, float))
        piece = np.clip(np.floor(tau), 0, 2).astype(int)
        local = tau - piece
        p, dp = np.empty((tau.size, 3)), np.empty((tau.size, 3))
        for k, fn in ((0, approach), (2, leave)):
            sel = piece == k
            if sel.any():
                p[sel], dp[sel] = fn(local[sel])
        sel = piece == 1
        if sel.any():
            x = local[sel] * T
            p[sel] = pre + x[:, None] * velocity - depth(x)[:, None] * z
            dp[sel] = T * (velocity - depth(x, slope=True)[:, None] * z)
        return p, dp

    g_t = T * (belt.speed + QUINTIC_SLOPE * spec.lift / spec.descend)
    return PlatformPath(arm.delta, points, 3.0, max(g_a, g_t, g_c))


def _profile(timing, points, length):
    """``(p(t), dp/dt)`` along a time-optimal profile (constant ``s̈`` between grid points) of ``points(s)``."""
    s, sd, sdd = (np.asarray(v, float) for v in (timing.s, timing.sd, timing.sdd))
    dt = 2.0 * np.diff(s) / np.maximum(sd[:-1] + sd[1:], 1e-300)
    t_grid = np.concatenate([[0.0], np.cumsum(dt)])

    def at(t):
        t = np.clip(np.asarray(t, float), 0.0, t_grid[-1])
        k = np.clip(np.searchsorted(t_grid, t, side="right") - 1, 0, dt.size - 1)
        tau = t - t_grid[k]
        sk = np.minimum(s[k] + sd[k] * tau + 0.5 * sdd[k] * tau ** 2, length)
        p, dp, _ = points(sk)
        return p, dp * (sd[k] + sdd[k] * tau)[:, None]

    return at, float(t_grid[-1]), float(sd.max())


@dataclass(frozen=True)
class DeltaPickPlan:
    """A delta's pick on its own clock: ``times`` (approach, tracking, leave, release) [s] and ``trajectory``
    (a :class:`~pinarms.robots.delta.path_motion.PlatformPath` over the whole pick, time in s)."""

    station: str
    times: tuple[float, float, float, float]
    trajectory: PlatformPath

    @property
    def duration(self) -> float:
        return float(sum(self.times))


def delta_pick_plan(station: Station, belt: Belt, spec: TrackingSpec, u: float, w: float, *, mass: float,
                    item_height: float, n: int = 24) -> DeltaPickPlan:
    """The pick at belt coordinates (``u``, ``w``) on the clock (module doc): the same moves as
    :func:`~.delta_tracking.delta_pick_times` (the tool axis held)."""
    arm = station.robot
    pre, box, end, d = _pick_points(station, belt, spec, u, w, item_height)
    velocity = belt.speed * d
    approach, t_a, v_a = _profile(*platform_move_profile(arm, box, pre, d, belt.speed, True, 0.0, n),
                                  float(np.linalg.norm(pre - box)))
    leave, t_c, v_c = _profile(*platform_move_profile(arm, end, box, d, belt.speed, False, mass, n),
                               float(np.linalg.norm(box - end)))
    g_a = v_a * _hermite(box, pre, pre - box, float(np.linalg.norm(pre - box)) * d)[1] / float(np.linalg.norm(pre - box))
    g_c = v_c * _hermite(end, box, float(np.linalg.norm(box - end)) * d, box - end)[1] / float(np.linalg.norm(box - end))
    T = spec.track_time
    track = _tracking(spec, pre, velocity)
    edges = np.cumsum([0.0, t_a, T, t_c, spec.release])

    def points(t):
        t = np.atleast_1d(np.asarray(t, float))
        p, dp = np.tile(box, (t.size, 1)), np.zeros((t.size, 3))
        for k, fn in ((0, approach), (1, track), (2, leave)):
            sel = (t >= edges[k]) & (t < edges[k + 1]) if k < 2 else (t >= edges[k]) & (t <= edges[k + 1])
            if sel.any():
                p[sel], dp[sel] = fn(t[sel] - edges[k])
        return p, dp

    g_t = belt.speed + QUINTIC_SLOPE * spec.lift / spec.descend
    return DeltaPickPlan(station.name, (t_a, T, t_c, spec.release),
                         PlatformPath(arm.delta, points, float(edges[-1]), max(g_a, g_t, g_c)))


def _tracking(spec: TrackingSpec, pre: np.ndarray, velocity: np.ndarray):
    """``x -> (p, dp/dx)`` of the tracking segment (the item's path and the vertical quintic), ``x`` in s."""
    z = np.array([0.0, 0.0, 1.0])

    def at(x):
        x = np.asarray(x, float)
        down, up = np.clip(x / spec.descend, 0.0, 1.0), np.clip((x - spec.descend - spec.grasp) / spec.descend, 0.0, 1.0)
        quintic = lambda r: 10 * r ** 3 - 15 * r ** 4 + 6 * r ** 5  # noqa: E731
        slope = lambda r: (30 * r ** 2 - 60 * r ** 3 + 30 * r ** 4) * ((r > 0.0) & (r < 1.0))  # noqa: E731
        depth = spec.lift * (quintic(down) - quintic(up))
        rate = spec.lift / spec.descend * (slope(down) - slope(up))
        return pre + x[:, None] * velocity - depth[:, None] * z, velocity - rate[:, None] * z

    return at
