"""Accelerations a controller receives, against the arms' acceleration limits: flagged, never clamped.

A URDF has no acceleration field and a controller may fault (or a drive trip) on a motion it cannot
follow, so every trajectory sampled for a controller (:func:`.trajectory.controller_trajectory`)
has its accelerations compared with the acceleration limits of the arms it is for
(``Robot.acceleration_limit``: ``velocity_limit / 0.25 s`` by default, see
:data:`pinarms.robots.robot.ACCELERATION_RISE_TIME`). A sample beyond them (a motion timed
without acceleration limits, ``MotionLimits(amax=False)``, or under larger ones) is **flagged**: an
:class:`AccelerationWarning` names the joint, the peak, the limit and how to re-time, and
``ControllerTrajectory.over_acceleration`` lists the joints beyond. The file is still written (the
limits are a stated rule, not the drive's): re-time under ``amax`` before sending it.
"""

from __future__ import annotations

import warnings
from typing import Any, TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from pinarms.optim.cycle.spec import CycleResult
    from pinarms.optim.line.schedule import LineSchedule
    from pinarms.optim.motion.result import MotionPlan
    from pinarms.planning.trajectory import Trajectory
    from pinarms.robots.robot import Robot

__all__ = ["AccelerationWarning", "acceleration_limits_of", "flag_accelerations", "ACCELERATION_TOL"]

#: Relative tolerance of the comparison (a time-optimal motion rides its limits exactly).
ACCELERATION_TOL = 1e-6


class AccelerationWarning(UserWarning):
    """A trajectory for a controller accelerates a joint beyond that arm's acceleration limit."""


def acceleration_limits_of(source: Trajectory | CycleResult | MotionPlan | LineSchedule, robot: Robot | None = None, arm: str | None = None) -> np.ndarray:
    """The acceleration limits ``(n,)`` [rad/s² or m/s²] of the joints a controller file of ``source`` holds.

    ``source`` a MotionPlan: its planned arms' limits, in its order; otherwise ``robot`` (a Robot)
    or its ``arm`` (``robot`` a cell), as :func:`.trajectory.controller_trajectory` takes them.
    """
    from pinarms.optim.motion import MotionPlan

    if isinstance(source, MotionPlan):
        return np.concatenate([np.asarray(source.cell.arm(a).robot.acceleration_limit, dtype=float)
                               for a in source.arms])
    if hasattr(robot, "arm"):
        robot = robot.arm(arm).robot
    return np.asarray(robot.acceleration_limit, dtype=float)


def flag_accelerations(names: tuple[str, ...], accelerations: np.ndarray, limits: np.ndarray) -> tuple[str, ...]:
    """Names of the joints whose ``|accelerations|`` ``(N, n)`` exceed ``limits`` ``(n,)`` (a limit of 0: not
    given, never flagged); an :class:`AccelerationWarning` names the worst of them."""
    lim = np.where(limits > 0.0, limits, np.inf)
    peak = np.max(np.abs(accelerations), axis=0) if accelerations.size else np.zeros(len(names))
    over = np.flatnonzero(peak > lim * (1.0 + ACCELERATION_TOL))
    if not over.size:
        return ()
    j = int(over[np.argmax(peak[over] / lim[over])])
    warnings.warn(AccelerationWarning(
        f"joint {names[j]} accelerates at up to {peak[j]:.4g}, {peak[j] / lim[j]:.1f}x its acceleration limit "
        f"{lim[j]:.4g} [rad/s² or m/s²] ({len(over)} joint(s) beyond their limit): the motion was timed without "
        "these limits; re-time it under them (MotionLimits(amax=None), CycleTiming(amax=...)) before sending it"),
        stacklevel=3)
    return tuple(names[int(k)] for k in over)
