"""Straight vertical approach and retreat for a pick-and-place cycle (``CycleApproach("straight")``).

Each move of the cycle becomes *line, transfer, line*::

    pick ─straight line─▶ above pick ─transfer (joint space, via points)─▶ above place ─straight line─▶ place

The lines are Cartesian (:func:`pinarms.planning.cartesian_path`, tcp within ``tolerance`` of the
vertical segment, on the branch of the cycle's joint via points) and time-optimal
(:func:`pinarms.optim.time_optimal` under the joint velocity and acceleration limits, a tool-speed
limit if given, joint torques with the payload on the move to place and without it on
the way back when torque limits are asked for, the jerk limit as a smoothed result).
The transfer is the joint-space
family of the cycle (``kind``) timed by :func:`pinarms.optim.minimize_time`, from rest above the
pick to rest above the place. The arm stops at the lift points: a line's tangent and the
transfer's meet at an angle there. The joint-space cycle of the same spec is timed too
(:attr:`pinarms.optim.CycleResult.straight_cost`: against today's cycle, whose moves are smooth
polynomials through the lift points), and each line is also timed as a *joint-space*
line between the same configurations under the same limits and time scaling
(:attr:`pinarms.optim.CycleResult.line_cost`: what the straightness itself costs).

Units: m, rad, s.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.optim.cycle.joint import joint_cycle
from pinarms.optim.cycle.request import CycleRequest
from pinarms.optim.cycle.spec import LINE_SAMPLES, CycleResult
from pinarms.optim.cycle.vertical import at_rest, segment_distance, vertical_segments
from pinarms.optim.errors import InvalidLimits
from pinarms.optim.topp.path_timing import PathTiming, time_optimal
from pinarms.optim.timing.segments import TimingRequest, TimingResult, minimize_time
from pinarms.optim.torque import torque_constraint
from pinarms.planning import (JointAccelerationConstraint, JointTorqueConstraint, JointVelocityConstraint,
                              ToolSpeedConstraint, Trajectory, cartesian_path, joint_spline, torque_peaks)
from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.planning.trajectory import Trajectory
    from pinarms.robots.robot import Robot
    from pinarms.robots.payload import Payload

__all__ = ["StraightMove", "straight_cycle", "approach_cycle"]


@dataclass(frozen=True, eq=False)
class StraightMove:
    """One move with straight approach and retreat: a line, the transfer, a line (at rest between).

    Attributes:
        lines: the two timed lines (:class:`pinarms.optim.PathTiming`): the lift, then the lowering.
        transfer: the joint-space transfer (:class:`pinarms.optim.TimingResult`).
        trajectory: the three concatenated.
        joint_lines: (2,) [s] the same two moves as straight lines in *joint* space between the
            same configurations, timed the same way (the reference for :attr:`line_cost`).
        torque_ratios: refined torque peak / limit per joint (nq,) over the move, or None
            without torque limits.
    """

    lines: tuple[PathTiming, PathTiming] = field(repr=False)
    transfer: TimingResult = field(repr=False)
    trajectory: Trajectory = field(repr=False)
    joint_lines: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(2))
    torque_ratios: np.ndarray | None = field(repr=False, default=None)

    @property
    def line_cost(self) -> float:
        """Time [s] the Cartesian lines take beyond joint-space lines between the same configurations."""
        return float(self.lines[0].duration + self.lines[1].duration - self.joint_lines.sum())

    @property
    def durations(self) -> np.ndarray:
        """(3,) [s]: lift line, transfer, lowering line."""
        return np.array([self.lines[0].duration, self.transfer.total, self.lines[1].duration])

    @property
    def total(self) -> float:
        """Duration of the move [s]."""
        return float(self.durations.sum())


def straight_cycle(robot: Robot, joint: CycleResult, *, kind: str, method: str = "exact", seed: int = 0,
                   tool_speed: float | None = None, tolerance: float = 1e-4, payload: Payload | None = None,
                   torque_limits: ArrayLike = False) -> CycleResult:
    """The cycle of ``joint`` (a joint-space :class:`CycleResult`) with straight lines at pick and place.

    Args:
        robot: the robot of ``joint``.
        joint: the joint-space cycle of the same spec (its via points fix the IK branch).
        kind, method, seed: the transfer's trajectory family and optimiser (as :func:`pinarms.optim.plan_cycle`).
        tool_speed: tcp speed limit on the lines [m/s] (e.g. 0.5 carrying food), or None.
        tolerance: largest tcp deviation from the vertical lines [m].
        payload, torque_limits: as :func:`pinarms.optim.plan_cycle`: the move to place (lines and
            transfer) is timed carrying the payload, the move back empty, both under the torque
            limits (:class:`pinarms.planning.JointTorqueConstraint` on the lines).

    Raises:
        InvalidLimits: no acceleration limit (a time-optimal line needs one).
        InvalidInput: ``kind="3-5-3"`` without exactly two transfer via points.
        planning.errors.PathError: a line cannot be followed (singularity, limit, reach), with where.
    """
    if joint.amax is None:
        raise InvalidLimits("approach='straight' times the vertical lines time-optimally along the path: give amax "
                            "(rad/s² or m/s² per joint)")
    spec = joint.spec
    k = len(spec.names)
    if kind == "3-5-3" and k != 6:
        raise InvalidInput(f"kind='3-5-3' times 4 transfer waypoints; with approach='straight' the transfer has {k - 2} "
                           "(above pick, the vias, above place): use 'multi-quintic' or 'quintic-bspline'")
    legs = _Legs(robot, joint, kind, method, seed, tool_speed, tolerance, payload, torque_limits)
    poses, q = joint.waypoints[:k], joint.q_via[:k]
    up_pick = legs.line(poses[0], poses[1], q[0], 0)
    q_above_pick = _end(up_pick)
    there = legs.transfer(np.vstack([q_above_pick, q[2 : k - 1]]), 0)
    down_place = legs.line(poses[k - 2], poses[k - 1], q[k - 2], 0)
    up_place = legs.line(poses[k - 1], poses[k - 2], _end(down_place), 1)
    back = legs.transfer(np.vstack([_end(up_place), q[k - 3 : 1 : -1], q_above_pick]), 1)
    down_pick = legs.line(poses[1], poses[0], q_above_pick, 1)
    moves = [legs.move(leg, *parts) for leg, parts in enumerate(((up_pick, there, down_place),
                                                                 (up_place, back, down_pick)))]
    parts = [moves[0].trajectory, moves[1].trajectory]
    if spec.dwell > 0.0:
        parts = [at_rest(q[0], spec.dwell), parts[0], at_rest(_end(down_place), spec.dwell), parts[1]]
    trajectory = parts[0]
    for part in parts[1:]:
        trajectory = trajectory.concatenated(part)
    deviation = _line_deviations(robot, (up_pick, down_place, up_place, down_pick), vertical_segments(poses))
    v, a, j = joint.vmax, joint.amax, joint.jmax
    return CycleResult(
        robot=joint.robot, spec=spec, names=joint.names, waypoints=joint.waypoints, q_via=joint.q_via,
        moves=tuple(moves), trajectory=trajectory, peaks=trajectory.peaks(), vmax=v, amax=a, jmax=j,
        line_deviation=deviation, branches=joint.branches, payload=joint.payload, torque_limit=joint.torque_limit,
        approach="straight", joint_cycle_time=joint.cycle_time)


def _end(timing: PathTiming) -> np.ndarray:
    """The configuration a timed line ends at."""
    return timing.path.q_knots[-1]


class _Legs:
    """The two legs of a straight cycle: the move to place (carrying the payload) and the move back (empty).

    Each leg has its path constraints for the lines (joint velocity and acceleration, the tool
    speed, the torques with or without the payload) and the keywords of its transfer's timing.
    """

    def __init__(self, robot: Any, joint: CycleResult, kind: str, method: str, seed: int, tool_speed: float | None,
                 tolerance: float, payload: Any, torque_limits: Any) -> None:
        self.robot, self.kind, self.method, self.seed, self.tolerance = robot, kind, method, seed, tolerance
        self.v, self.a, self.j = joint.vmax, joint.amax, joint.jmax
        cons = [JointVelocityConstraint(self.v), JointAccelerationConstraint(self.a)]
        if tool_speed is not None:
            cons.append(ToolSpeedConstraint(tool_speed))
        self.loaded = torque_constraint(robot, torque_limits, payload)
        # (constraints of the lines, robot and limits of the transfer) carrying the payload, then empty
        if self.loaded is None:
            self.legs = [(cons, {}), (cons, {})]
        else:
            empty = torque_constraint(robot, self.loaded.limit)
            self.legs = [(cons + [JointTorqueConstraint(t.robot, t.limit)],
                          {"robot": t.robot, "torque_limits": t.limit}) for t in (self.loaded, empty)]
        self.options = {"velocities": "heuristic"} if kind == "multi-quintic" else None

    def line(self, frm: np.ndarray, to: np.ndarray, q_from: np.ndarray, leg: int) -> PathTiming:
        """The straight Cartesian line ``frm`` → ``to`` from ``q_from``, time-optimal under the leg's constraints."""
        path = cartesian_path(self.robot, np.stack([frm, to]), q_start=q_from, tolerance=self.tolerance)
        return time_optimal(path, self.legs[leg][0], jerk=self.j)

    def transfer(self, q_via: np.ndarray, leg: int) -> TimingResult:
        """The joint-space transfer through ``q_via``, timed by :func:`pinarms.optim.minimize_time`."""
        return minimize_time(TimingRequest(q_via, self.kind, self.v, self.a, self.j, method=self.method, seed=self.seed,
                             trajectory_options=self.options, **self.legs[leg][1]))

    def joint_line(self, timing: PathTiming, leg: int) -> float:
        """Duration [s] of the same line's ends joined in joint space, timed the same way."""
        path = joint_spline(timing.path.q_knots[[0, -1]], robot=self.robot)
        return time_optimal(path, self.legs[leg][0], jerk=self.j).duration

    def move(self, leg: int, first: PathTiming, middle: TimingResult, last: PathTiming) -> StraightMove:
        """Line, transfer, line of one leg as a :class:`StraightMove` (its torque ratios with torque limits)."""
        traj = first.trajectory.concatenated(middle.trajectory).concatenated(last.trajectory)
        ratios = None
        if self.loaded is not None:
            arm, limit = self.legs[leg][1]["robot"], self.legs[leg][1]["torque_limits"]
            ratios = torque_peaks(traj, arm).ratios(limit)
        return StraightMove((first, last), middle, traj,
                            np.array([self.joint_line(first, leg), self.joint_line(last, leg)]), ratios)


def _line_deviations(robot: Any, lines: tuple[PathTiming, ...], ends: np.ndarray) -> np.ndarray:
    """(4,) largest tcp distance [m] of each timed line from its vertical segment, in :data:`LINE_NAMES` order."""
    deviation = np.empty(4)
    for i, timing in enumerate(lines):
        t = np.linspace(0.0, timing.duration, LINE_SAMPLES)
        p = np.asarray(robot.fk(timing.trajectory(t)))[:, :3, 3]
        deviation[i] = segment_distance(p, ends[i, 0], ends[i, 1]).max()
    return deviation

def approach_cycle(request: CycleRequest) -> CycleResult:
    """The cycle of ``request`` ignoring its cell, with the approach it asks for.

    ``"joint"``: the joint-space cycle (:func:`pinarms.optim.cycle.joint.joint_cycle`); ``"straight"``:
    that cycle with straight lines at pick and place (:func:`straight_cycle`, on its branch).
    """
    joint = joint_cycle(request)
    if request.approach.approach == "joint":
        return joint
    t, load = request.timing, request.load
    return straight_cycle(request.robot, joint, kind=t.kind, method=t.method, seed=t.seed,
                          tool_speed=request.approach.tool_speed, payload=load.payload,
                          torque_limits=load.torque_limits)
