"""Planned trajectories to a robot controller: ROS 2 ``JointTrajectory`` YAML and CSV at a rate.

:func:`controller_trajectory` samples a planned motion at a user-chosen rate (125 Hz,
500 Hz, ...): instants ``k / rate`` from the start, plus the end instant (so the last point
is the motion's end, to the nanosecond below; it follows the one before by less than one period). Instants are
whole nanoseconds (``time_from_start`` is ``{sec, nanosec}``), and every point is the
trajectory evaluated at exactly its written instant: positions, velocities and
accelerations reproduce it to float precision, far below 1e-9. Every position is checked
against the joint limits and every velocity against the URDF's velocity limits (a
violation is an error, never clamped); accelerations beyond the arms' acceleration limits are
flagged (:mod:`.acceleration_check`: a warning and ``over_acceleration``).

Sources: a :class:`pinarms.planning.Trajectory` with its robot, a planned cycle
(:class:`pinarms.optim.CycleResult`, with its robot or cell arm), a planned move
(:class:`pinarms.optim.motion.MotionPlan`: the planned arms' joints, prefixed as in the
cell) and one arm of a line schedule (:class:`pinarms.optim.LineSchedule` with the
cycles: that arm's periodic motion over one period, its time offset included, holding
between cycles).

Files: :func:`write_trajectory_yaml` writes a ``trajectory_msgs/JointTrajectory`` document
(``header``, ``joint_names``, ``points`` with ``positions``, ``velocities``,
``accelerations``, ``effort`` (empty) and ``time_from_start``), which ``ros2 topic pub`` /
``ros2 action send_goal`` and a ``JointTrajectoryController`` accept;
:func:`write_trajectory_csv` one row per instant: ``time_s``, then ``pos:<joint>``,
``vel:<joint>``, ``acc:<joint>`` (SI units). Both are written atomically and read back by
:func:`~.trajectory_read.read_trajectory_yaml` / :func:`~.trajectory_read.read_trajectory_csv`.
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence, TYPE_CHECKING

import numpy as np

from pinarms.errors import InvalidInput, LimitViolation
from pinarms.files import atomic_write

from pinarms.export.acceleration_check import acceleration_limits_of, flag_accelerations
from pinarms.export.errors import InvalidJointName, InvalidRate, JointMismatch

if TYPE_CHECKING:
    from pinarms.optim.cycle.spec import CycleResult
    from pinarms.optim.line.schedule import LineSchedule
    from pinarms.optim.motion.result import MotionPlan
    from pinarms.planning.trajectory import Trajectory
    from pinarms.robots.robot import Robot

__all__ = ["ControllerTrajectory", "controller_trajectory", "write_trajectory_yaml", "write_trajectory_csv",
           "line_arm_sampler", "check_joint_names", "check_rate", "ROS_NAME"]

#: Most points one file may hold.
MAX_POINTS = 2_000_000


@dataclass(frozen=True, eq=False)
class ControllerTrajectory:
    """A trajectory sampled for a controller.

    Attributes:
        joint_names: the controller's joint names.
        time_ns: ``(N,)`` instants from the start [ns] (integers).
        positions, velocities, accelerations: ``(N, n)`` [rad or m, /s, /s²].
        over_acceleration: joints whose accelerations exceed their arm's acceleration limit
            (flagged with a warning, :mod:`.acceleration_check`); empty when read from a file.
    """

    joint_names: tuple[str, ...]
    time_ns: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray
    over_acceleration: tuple[str, ...] = ()

    @property
    def times(self) -> np.ndarray:
        """Instants from the start [s]."""
        return self.time_ns.astype(float) * 1e-9


def check_rate(rate: float) -> float:
    """``rate`` [Hz] as a float, checked before anything is planned or sampled.

    Raises:
        InvalidRate: not a finite number > 0 (a bool counts as no number).
    """
    if isinstance(rate, bool) or not isinstance(rate, (int, float, np.integer, np.floating)):
        raise InvalidRate(f"rate must be a number of samples per second (Hz), got {rate!r}")
    value = float(rate)
    if not math.isfinite(value) or value <= 0.0:
        raise InvalidRate(f"rate must be a finite number > 0 Hz (e.g. 125 or 500), got {rate!r}")
    return value


def line_arm_sampler(schedule: LineSchedule, cycles: Mapping[str, CycleResult], arm: str) -> tuple[float, float, Callable]:
    """``(start, end, sample)`` of arm ``arm`` over one period of a line schedule (offset included)."""
    from pinarms.robots.cell import ArmMotion

    if arm not in schedule.offsets or arm not in cycles:
        raise JointMismatch(f"arm {arm!r} is not scheduled; arms: {', '.join(schedule.arms)}")
    traj = cycles[arm].trajectory
    motion = ArmMotion(arm, traj, schedule.offsets[arm], schedule.period)

    def sample(t: np.ndarray):
        local = motion.local_time(t)
        q, qd, qdd, _ = traj.sample(local)
        held = np.mod(t - motion.offset, motion.period) >= traj.duration  # waiting for the next cycle
        qd, qdd = np.where(held[:, None], 0.0, qd), np.where(held[:, None], 0.0, qdd)
        return q, qd, qdd

    return 0.0, float(schedule.period), sample


def _source(source: Any, robot: Any, arm: str | None, cycles: Mapping[str, Any] | None):
    """``(joint names, (lower, upper, velocity limit), start, end, sample)`` of what is to be written."""
    from pinarms.optim import CycleResult, LineSchedule
    from pinarms.optim.motion import MotionPlan
    from pinarms.planning import Trajectory

    if isinstance(source, MotionPlan):
        cell = source.cell
        names, lo, hi, vmax = [], [], [], []
        for name in source.arms:
            a = cell.arm(name)
            names += [a.prefix + j for j in a.robot.joint_names]
            lo.append(a.robot.position_limits[0])  # continuous joints: none
            hi.append(a.robot.position_limits[1])
            vmax.append(a.robot.velocity_limit)
        traj = source.trajectory
        limits = (np.concatenate(lo), np.concatenate(hi), np.concatenate(vmax))
        return tuple(names), limits, traj.start_time, traj.end_time, lambda t: traj.sample(t)[:3]
    if isinstance(source, LineSchedule):
        if cycles is None or arm is None:
            raise InvalidInput("a line schedule is written one arm at a time: give arm= and the cycles= it scheduled")
        cell_arm = robot.arm(arm) if hasattr(robot, "arm") else None
        if cell_arm is None:
            raise InvalidInput("a line schedule needs its cell as robot=")
        _check_width(cycles[arm].trajectory.n_joints if arm in cycles else -1, cell_arm.robot, f"arm {arm!r}")
        start, end, sample = line_arm_sampler(source, cycles, arm)
        return tuple(cell_arm.prefix + j for j in cell_arm.robot.joint_names), _limits(cell_arm.robot), start, end, sample
    prefix = ""
    if robot is not None and hasattr(robot, "arm"):  # a cell: the arm's prefixed names
        if arm is None:
            raise InvalidInput("with a cell as robot=, name the arm (arm=)")
        cell_arm = robot.arm(arm)
        robot, prefix = cell_arm.robot, cell_arm.prefix
    if robot is None:
        raise InvalidInput("give the robot (or cell and arm) the trajectory is for: robot=")
    if isinstance(source, CycleResult):
        if source.trajectory.n_joints != robot.nq or tuple(source.q_via.shape[1:]) != (robot.nq,):
            raise JointMismatch(f"the cycle was planned for {source.robot!r} ({source.trajectory.n_joints} joints), "
                                f"not for {robot.name!r} ({robot.nq} joints: {', '.join(robot.joint_names)})")
        traj = source.trajectory
    elif isinstance(source, Trajectory):
        traj = source
    else:
        raise InvalidInput(f"cannot write {type(source).__name__} for a controller: give a Trajectory, a CycleResult, "
                           "a MotionPlan or a LineSchedule")
    _check_width(traj.n_joints, robot, "the trajectory")
    return tuple(prefix + j for j in robot.joint_names), _limits(robot), traj.start_time, traj.end_time, \
        lambda t: traj.sample(t)[:3]


def _limits(robot: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (*robot.position_limits, np.asarray(robot.velocity_limit, dtype=float))  # continuous joints: no position limit


def _check_width(n: int, robot: Any, what: str) -> None:
    if n != robot.nq:
        raise JointMismatch(f"{what} has {n} joints; robot {robot.name!r} has {robot.nq} "
                            f"({', '.join(robot.joint_names)}): write it for the robot it was planned for")


def controller_trajectory(source: Trajectory | CycleResult | MotionPlan | LineSchedule, rate: float, *, robot: Robot | None = None, arm: str | None = None,
                          cycles: Mapping[str, CycleResult] | None = None) -> ControllerTrajectory:
    """Sample ``source`` at ``rate`` [Hz] for a controller (module doc).

    Args:
        source: a :class:`pinarms.planning.Trajectory`, :class:`pinarms.optim.CycleResult`,
            :class:`pinarms.optim.motion.MotionPlan` or :class:`pinarms.optim.LineSchedule`.
        rate: samples per second (> 0).
        robot: the :class:`pinarms.robots.Robot` it is for, or the cell (then ``arm`` names the arm;
            joint names carry the arm's prefix). Not needed for a MotionPlan.
        cycles: with a LineSchedule, the ``{arm: CycleResult}`` it scheduled.

    Raises:
        InvalidRate: rate ≤ 0, NaN or infinite. JointMismatch: a trajectory for other joints.
        LimitViolation: a sample outside the joint limits. InvalidInput: anything else missing.
    """
    hz = check_rate(rate)
    names, (lower, upper, vmax), start, end, sample = _source(source, robot, arm, cycles)
    duration_ns = int(math.floor((end - start) * 1e9))  # the last instant never after the end
    step_ns = 1e9 / hz
    count = int(math.floor(duration_ns / step_ns * (1.0 + 1e-12))) + 1
    if count > MAX_POINTS:
        raise InvalidRate(f"rate {hz:g} Hz over {end - start:g} s gives {count} points, more than {MAX_POINTS}")
    ticks = np.round(np.arange(count) * step_ns).astype(np.int64)
    ticks = ticks[ticks < duration_ns]
    ticks = np.append(ticks, np.int64(duration_ns))
    t = np.minimum(start + ticks.astype(float) * 1e-9, end)
    q, qd, qdd = (np.atleast_2d(np.asarray(a, dtype=float)) for a in sample(t))
    bad = (q < np.asarray(lower) - 1e-12) | (q > np.asarray(upper) + 1e-12)
    if bad.any():
        i, j = (int(v[0]) for v in np.nonzero(bad))
        raise LimitViolation(f"joint {names[j]} = {float(q[i, j])!r} at t = {t[i] - start:.9f} s is outside its limits "
                             f"[{float(lower[j])!r}, {float(upper[j])!r}]: the trajectory cannot be sent as it is")
    limit = np.where(vmax > 0, vmax, np.inf)  # a URDF velocity of 0 means "not given"
    fast = np.abs(qd) > limit * (1.0 + 1e-9) + 1e-12
    if fast.any():
        i, j = (int(v[0]) for v in np.nonzero(fast))
        raise LimitViolation(f"joint {names[j]} moves at {float(qd[i, j])!r} at t = {t[i] - start:.9f} s, beyond its "
                             f"velocity limit {float(limit[j])!r}: re-time the trajectory under the robot's limits")
    over = flag_accelerations(names, qdd, acceleration_limits_of(source, robot, arm))
    return ControllerTrajectory(names, ticks, q, qd, qdd, over)


#: The ROS graph resource name rule (wiki.ros.org/Names, "Valid Names": a letter, ``~`` or ``/``
#: first, then letters, digits, ``_`` and ``/``), without the private ``~``; at most 255 characters.
ROS_NAME = re.compile(r"[A-Za-z/][A-Za-z0-9_/]{0,254}")


def check_joint_names(names: Sequence[str]) -> tuple[str, ...]:
    """``names`` as a tuple, each a ROS name (:data:`ROS_NAME`); else :class:`InvalidJointName` naming it."""
    out = tuple(names)
    for name in out:
        if not isinstance(name, str) or ROS_NAME.fullmatch(name) is None:
            raise InvalidJointName(f"joint name {name!r} is not a ROS name (a letter or '/' first, then letters, "
                                   "digits, '_' and '/', at most 255 characters): rename the joint in the URDF "
                                   "(a controller matches these names to its own)")
    return out


def _yaml_float(value: float) -> str:
    text = repr(float(value))  # finite (checked): a YAML float as PyYAML's emitter writes it
    mantissa, e, exponent = text.partition("e")
    if e and "." not in mantissa:  # YAML 1.1 readers need a dot in 1.0e-05
        text = f"{mantissa}.0e{exponent}"
    return text


def _yaml_list(values: np.ndarray) -> str:
    return "[" + ", ".join(_yaml_float(v) for v in values) + "]"


def write_trajectory_yaml(path: str | os.PathLike, trajectory: ControllerTrajectory, *, frame_id: str = "") -> os.PathLike:
    """Write ``trajectory`` as a ROS 2 ``trajectory_msgs/JointTrajectory`` YAML document, atomically.

    Joint names must follow the ROS name rule (:data:`ROS_NAME`); the names and ``frame_id`` are
    written by PyYAML's safe emitter, so they read back as written. Every value must be finite.

    Raises:
        InvalidJointName: a joint name outside the rule. InvalidInput: a value that is NaN or infinite.
    """
    import yaml

    names = check_joint_names(trajectory.joint_names)
    for key in ("positions", "velocities", "accelerations"):
        if not np.all(np.isfinite(getattr(trajectory, key))):
            raise InvalidInput(f"the trajectory's {key} hold NaN or infinite values: sample a finite trajectory")
    head = {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": str(frame_id)}, "joint_names": list(names)}
    out = io.StringIO()
    out.write("# trajectory_msgs/JointTrajectory written by pinarms (SI units: rad, m, s)\n")
    out.write(yaml.safe_dump(head, sort_keys=False, default_flow_style=None, allow_unicode=True, width=1 << 30))
    out.write("points:\n")
    for k, ns in enumerate(trajectory.time_ns):
        sec, nanosec = divmod(int(ns), 1_000_000_000)
        out.write(f"- positions: {_yaml_list(trajectory.positions[k])}\n"
                  f"  velocities: {_yaml_list(trajectory.velocities[k])}\n"
                  f"  accelerations: {_yaml_list(trajectory.accelerations[k])}\n"
                  f"  effort: []\n"
                  f"  time_from_start: {{sec: {sec}, nanosec: {nanosec}}}\n")
    data = out.getvalue().encode("utf-8")
    return atomic_write(path, lambda f: f.write(data))


def write_trajectory_csv(path: str | os.PathLike, trajectory: ControllerTrajectory) -> os.PathLike:
    """Write ``trajectory`` as CSV (``time_s``, ``pos:<joint>``…, ``vel:<joint>``…, ``acc:<joint>``…), atomically."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    names = trajectory.joint_names
    writer.writerow(["time_s"] + [f"pos:{n}" for n in names] + [f"vel:{n}" for n in names] + [f"acc:{n}" for n in names])
    for k, t in enumerate(trajectory.times):
        writer.writerow([repr(float(t))] + [repr(float(v)) for v in trajectory.positions[k]]
                        + [repr(float(v)) for v in trajectory.velocities[k]]
                        + [repr(float(v)) for v in trajectory.accelerations[k]])
    data = out.getvalue().encode("utf-8")
    return atomic_write(path, lambda f: f.write(data))
