"""Exceptions of the trajectory layer.

Everything here derives from :class:`pinarms.errors.PinarmsError`, so a caller can catch
the whole pinarms family with one ``except``; :class:`TrajectoryError` is also a
``ValueError`` because it is raised for bad arguments (times, positions, degrees).

The Cartesian path errors (:class:`PathError` and its subclasses) say *where* along the
path the arm cannot follow it: the arc length ``s`` [m, weighted, see
:mod:`pinarms.planning.tool_path`], the tcp pose there (4, 4) and the reason, as attributes and in
the message.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms.errors import LimitViolation, PinarmsError, UnreachableTarget

__all__ = ["TrajectoryError", "ConditionCountError", "OutOfTimeRange", "BlendTooLarge", "PathError",
           "SingularityOnPath", "JointLimitOnPath", "UnreachableOnPath"]


class TrajectoryError(PinarmsError, ValueError):
    """A trajectory cannot be built or used with the given input (times, positions, ...)."""


class ConditionCountError(TrajectoryError):
    """The boundary/continuity conditions do not match the number of polynomial coefficients."""


class OutOfTimeRange(TrajectoryError):
    """A trajectory was sampled outside ``[0, duration]``."""


class BlendTooLarge(TrajectoryError):
    """A corner blend of a tool path needs more of a line than the line has (the radius that fits is named)."""


class PathError(TrajectoryError):
    """The arm cannot follow a Cartesian path on its IK branch beyond arc length ``s``.

    Attributes:
        s: arc length [m, weighted] along the tool path where it happens.
        pose: tcp pose (4, 4) there (frame → base, m).
        reason: why, in words (also in the message).
        q: the last joint configuration (nq,) on the branch before ``s`` (rad or m).
    """

    def __init__(self, message: str, *, s: float, pose: Any, reason: str, q: Any = None) -> None:
        super().__init__(message)
        self.s = float(s)
        self.pose = np.array(pose, dtype=float)
        self.reason = reason
        self.q = None if q is None else np.array(q, dtype=float)


class SingularityOnPath(PathError):
    """The path runs into a singular configuration of the arm (the Jacobian loses rank)."""


class JointLimitOnPath(PathError, LimitViolation):
    """On its IK branch the arm would take a joint past its limit to follow the path."""


class UnreachableOnPath(PathError, UnreachableTarget):
    """The path leaves the arm's workspace (or asks for an orientation the arm cannot take)."""
