"""Place targets on a second moving belt: trays, and the place as a second rendezvous.

A :class:`TrayBelt` is a second :class:`~.belt.Belt` carrying trays at a regular ``pitch``,
each taking ``capacity`` items at its place point (``w`` across, ``height`` above the belt's
surface). Placing in a tray is a rendezvous like the pick (:mod:`~.tracking`): after the pick's
tracking segment the arm moves to the *pre-place* point (``lift`` above the place point) and
arrives there moving with the tray belt; still moving with it, it descends (``descend`` s),
opens the gripper (``release`` s) and lifts (``descend`` s); then it returns to rest at its home
(the station's box position)::

    approach │ pick tracking │ transfer (time-optimal)      │ place tracking            │ return
    rest ─▶  │ item's belt   │ item's belt ─▶ tray's belt    │ descend · release · lift  │ ─▶ rest

The transfer is a joint-space cubic Hermite path whose end tangents are both tracking segments'
joint velocities, timed by TOPP-RA with the path speed fixed at both ends (the item as payload);
the return like the pick's leave move. The hand keeps the pick's turn (the item's yaw) through
the place. Checked from FK (tests/optim/line/test_trays.py): tool-to-tray distance < 1 mm and
relative speed < 1 % of the tray belt's speed over the whole release dwell.

Task maps of it: :mod:`~.tray_maps`; in the simulation: :mod:`~.tray_sim`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import CubicSpline

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.numbers import finite_number
from pinarms.optim.line.station import Station
from pinarms.optim.line.tracking import (TRACK_SAMPLES, TrackingSpec, check_rate_limits, move_constraints, hand_joints,
                                         check_positions, hermite_path, ik_path, joint_rates, tool_poses, timed_move, plan_pick,
                                         rest_configuration, tool_yaw, tracking_points)
from pinarms.planning import Trajectory
from pinarms.optim.errors import InfeasibleProblem, OptimError
from pinarms.errors import InvalidInput, UnreachableTarget

__all__ = ["TrayBelt", "TrayPickPlan", "plan_pick_to_tray", "trays_beside", "parse_trays"]


@dataclass(frozen=True, eq=False)
class TrayBelt:
    """Trays on a second belt (module doc): ``belt`` (its direction and speed), ``pitch`` [m]
    between tray centres, ``capacity`` items per tray, ``phase`` [m] the u of tray 0's centre at
    t = 0, ``w`` [m] across of the place point, ``height`` [m] of the place point above the surface."""

    belt: Belt
    pitch: float = 0.4
    capacity: int = 1
    phase: float = 0.0
    w: float = 0.0
    height: float = 0.03

    def __post_init__(self) -> None:
        if not isinstance(self.belt, Belt):
            raise InvalidInput(f"belt of the trays must be an optim.line.Belt, got {type(self.belt).__name__}")
        finite_number(self.pitch, "tray pitch [m]", positive=True)
        finite_number(self.height, "place height above the tray belt [m]")
        finite_number(self.phase, "tray phase [m]")
        if abs(finite_number(self.w, "place point across the tray belt [m]")) > self.belt.width / 2.0:
            raise InvalidInput(f"place point w = {self.w} m lies off the tray belt (width {self.belt.width} m)")
        if not (isinstance(self.capacity, int) and not isinstance(self.capacity, bool) and self.capacity >= 1):
            raise InvalidInput(f"tray capacity must be an integer >= 1, got {self.capacity!r}")

    def tray_u(self, k: ArrayLike, t: ArrayLike) -> np.ndarray:
        """u [m] of tray ``k``'s centre on its belt at time ``t`` [s] (broadcast)."""
        return self.phase - np.asarray(k, float) * self.pitch + self.belt.speed * np.asarray(t, float)


def trays_beside(belt: Belt, place_world: ArrayLike, pitch: float, speed: float, capacity: int, *,
                 height: float = 0.03, width: float = 0.2) -> TrayBelt:
    """Trays on a belt parallel to ``belt`` (same direction and length) whose place point passes
    through ``place_world`` (e.g. the stations' box release point) [m]."""
    b = belt.to_belt(np.asarray(place_world, float))
    origin = belt.to_world(0.0, float(b[1]), float(b[2]) - height)
    return TrayBelt(Belt(origin, belt.direction, speed, width, belt.length), pitch=pitch, capacity=capacity,
                    height=height)


def parse_trays(text: str) -> tuple[float, float, int]:
    """``"PITCH,SPEED,SLOTS"`` (m, m/s, items per tray) → numbers; InvalidInput naming the field."""
    parts = str(text).split(",")
    if len(parts) != 3:
        raise InvalidInput(f"trays must be PITCH,SPEED,SLOTS (m, m/s, items per tray), got {text!r}")
    out = []
    for name, part, kind in zip(("pitch [m]", "speed [m/s]", "slots per tray"), parts, (float, float, int)):
        try:
            out.append(kind(part))
        except ValueError:
            raise InvalidInput(f"tray {name} must be {'an integer' if kind is int else 'a number'}, "
                               f"got {part.strip()!r} in {text!r}") from None
    return out[0], out[1], out[2]


@dataclass(eq=False)
class TrayPickPlan:
    """A pick placed in a tray. Times in s from the start of the approach: ``times`` = approach,
    pick tracking, transfer, place tracking, return; ``grasp_window`` and ``release_window``
    (start, end) of the gripper closing and opening; ``u_pre``, ``w`` the pick's pre-grasp point,
    ``u_place`` the pre-place point on the tray belt [m]."""

    station: str
    u_pre: float
    w: float
    u_place: float
    pieces: tuple
    q_rest: np.ndarray
    grasp_window: tuple[float, float]
    release_window: tuple[float, float]
    times: tuple[float, float, float, float, float]

    @functools.cached_property
    def trajectory(self) -> Trajectory:
        out = self.pieces[0]
        for p in self.pieces[1:]:
            out = out.concatenated(p, atol=1e-7)
        return out

    @property
    def duration(self) -> float:
        return float(sum(self.times))


def _timed_transfer(station: Station, q0, qd0, q1, qd1, mass: float, grid: int) -> Any:
    """Time-optimal move q0 → q1 starting with joint velocity qd0 and ending with qd1 (both moving)."""
    from pinarms.optim.topp.path_timing import time_optimal

    chord = q1 - q0
    arm = ~hand_joints(station.robot)
    if not np.any(arm):
        arm = np.ones(chord.size, bool)
    L = max(float(np.linalg.norm(chord[arm])), 1e-9)
    k0 = L / max(float(np.linalg.norm(qd0[arm])), 1e-12)
    k1 = L / max(float(np.linalg.norm(qd1[arm])), 1e-12)
    path = hermite_path(q0, k0 * qd0, q1, k1 * qd1, station.robot)
    return time_optimal(path, move_constraints(station, mass), grid=grid, start_speed=1.0 / k0, end_speed=1.0 / k1)


#: Hand turns whose travel pick → place → home is within this of the shortest [rad] are all planned
#: and the faster kept (:func:`_hand_turns`).
TURN_TIE = 1.0


def _hand_turns(station: Station, q: np.ndarray, q_ref: np.ndarray, q_home: np.ndarray) -> list[np.ndarray]:
    """``q`` (N, nq) with each hand joint's angles continuous along the segment (no 2π step between
    instants) and on the whole turns (multiples of 2π: the same poses) that keep the hand's travel
    ``q_ref`` → segment → ``q_home`` within :data:`TURN_TIE` of the shortest, within the joint's
    limits; shortest first (ties: nearest ``q_ref``).

    The nearest-solution IK alone flips the place's hand angle by 2π where its distance to the
    pick's end crosses π: the return home then turned the hand a whole turn more (1.12 s against
    0.34 s a node away), a jump of the exact time inside a map cell; and a flip within the segment
    made it infeasible. Where two turns travel about as far, which is faster depends on the arm's
    other joints: the caller plans each and keeps the faster, so the time has no jump there."""
    robot = station.robot
    options = [q.copy()]
    for h in np.flatnonzero(hand_joints(robot)):
        path, ranked = np.unwrap(q[:, h]), []
        for turns in range(-3, 4):
            p = path + 2.0 * np.pi * turns
            if p.min() >= robot.lower[h] - 1e-9 and p.max() <= robot.upper[h] + 1e-9:
                ranked.append((abs(p[0] - q_ref[h]) + abs(p[-1] - q_home[h]), abs(p[0] - q_ref[h]), turns, p))
        if not ranked:
            raise UnreachableTarget(f"arm {station.name!r}: its hand (joint {h + 1}) cannot follow the place "
                                    f"within its limits [{robot.lower[h]:.3f}, {robot.upper[h]:.3f}] rad")
        ranked.sort(key=lambda r: r[:3])
        keep = [r[3] for r in ranked if r[0] <= ranked[0][0] + TURN_TIE]
        options = [np.concatenate([o[:, :h], p[:, None], o[:, h + 1:]], axis=1) for o in options for p in keep]
    return options


def _hand_turn(station: Station, q: np.ndarray, q_ref: np.ndarray, q_home: np.ndarray) -> np.ndarray:
    """The first of :func:`_hand_turns`: the hand's shortest travel."""
    return _hand_turns(station, q, q_ref, q_home)[0]


def _segments(station: Station, belt: Belt, spec: TrackingSpec, u: float, w: float, z: float, yaw: float,
              q_ref: np.ndarray, branch: Any, what: str, q_home: np.ndarray) -> list:
    """The tracking segment on ``belt`` on each hand turn of :func:`_hand_turns`: (trajectory, joint
    velocities at its start and end) each; the turns beyond a joint's rates are left out."""
    tau = np.linspace(0.0, spec.track_time, TRACK_SAMPLES)
    q = ik_path(station, tool_poses(station, tracking_points(belt, spec, u, w, z, tau), yaw), q_ref, branch)
    out, error = [], None
    for qq in _hand_turns(station, q, q_ref, np.asarray(q_home, float)):
        qd_in = joint_rates(station, qq[0], belt.velocity)
        qd_out = joint_rates(station, qq[-1], belt.velocity)
        spline = CubicSpline(tau, qq, axis=0, bc_type=((1, qd_in), (1, qd_out)))
        traj = Trajectory(tau, np.ascontiguousarray(spline.c[::-1].transpose(1, 0, 2)))
        try:
            check_rate_limits(station, traj, what, spec, belt.speed)
        except InfeasibleProblem as exc:
            error = exc
            continue
        out.append((traj, qd_in, qd_out))
    if not out:
        raise error
    return out


def plan_pick_to_tray(station: Station, belt: Belt, trays: TrayBelt, spec: TrackingSpec, u_pre: float, w: float,
                      u_place: float, *, item_height: float = 0.04, mass: float = 0.0, q_rest: Any = None,
                      branch: int | None = None, yaw: float = 0.0, place_branch: int | None = None,
                      pick: Any = None) -> TrayPickPlan:
    """Pick at (``u_pre``, ``w``) on ``belt`` and place in the tray whose place point passes
    ``u_place`` [m] (tray belt) at the place's rendezvous (module doc); arguments as
    :func:`~.tracking.plan_pick`; ``place_branch``: the IK branch label of the place tracking
    segment (None: the pick's where it reaches, else the nearest); ``pick``: the
    :func:`~.tracking.plan_pick` of this very pick when already planned (the tray maps plan it
    once for every place point), else planned here.

    Raises:
        UnreachableTarget: a point of either tracking segment out of reach.
        InfeasibleProblem: a belt too fast for the arm there, or a move beyond its limits.
    """
    q_rest = rest_configuration(station) if q_rest is None else np.asarray(q_rest, float)
    if pick is None:
        pick = plan_pick(station, belt, spec, u_pre, w, item_height=item_height, mass=mass, q_rest=q_rest,
                         branch=branch, yaw=yaw)
    q_end = pick.tracking.sample(np.array([pick.tracking.end_time]))[0][0]
    qd_end = pick.tracking.sample(np.array([pick.tracking.end_time]))[1][0]
    place_spec = replace(spec, grasp=spec.release)  # the dwell is the gripper opening
    best, error = None, None
    for place, qd_in, qd_out in _segments(station, trays.belt, place_spec, float(u_place), trays.w, trays.height,
                                          tool_yaw(station, spec, yaw), q_end, place_branch,
                                          "place tracking segment", q_rest):
        try:
            transfer = _timed_transfer(station, q_end, qd_end, place.sample(np.array([0.0]))[0][0], qd_in, mass,
                                       spec.grid)
            q_last = place.sample(np.array([place.end_time]))[0][0]
            ret = timed_move(station, q_last, qd_out, q_rest, np.zeros(station.robot.nq), 0.0, spec.grid)
            for piece, what in ((place, "place tracking segment"), (transfer.trajectory, "transfer to the tray"),
                                (ret.trajectory, "return from the tray")):
                check_positions(station, piece, what)
        except (InfeasibleProblem, OptimError) as exc:
            error = exc
            continue
        if best is None or transfer.duration + ret.duration < best[1].duration + best[2].duration:
            best = (place, transfer, ret)  # the faster hand turn
    if best is None:
        raise error
    place, transfer, ret = best
    tA, tT = pick.times[0], pick.times[1]
    tX, tP, tR = float(transfer.duration), place_spec.track_time, float(ret.duration)
    r0 = tA + tT + tX + spec.descend
    pieces = (pick.approach.trajectory, pick.tracking, transfer.trajectory, place, ret.trajectory)
    return TrayPickPlan(station.name, float(u_pre), float(w), float(u_place), pieces, q_rest, pick.grasp_window,
                        (r0, r0 + spec.release), (tA, tT, tX, tP, tR))
