"""Exceptions of the trajectory layer.

Everything here derives from :class:`robots.errors.PinarmsError`, so a caller can catch
the whole pinarms family with one ``except``; :class:`TrajectoryError` is also a
``ValueError`` because it is raised for bad arguments (times, positions, degrees).
"""

from __future__ import annotations

from pinarms.robots.errors import PinarmsError

__all__ = ["TrajectoryError", "ConditionCountError", "OutOfTimeRange"]


class TrajectoryError(PinarmsError, ValueError):
    """A trajectory cannot be built or used with the given input (times, positions, ...)."""


class ConditionCountError(TrajectoryError):
    """The boundary/continuity conditions do not match the number of polynomial coefficients."""


class OutOfTimeRange(TrajectoryError):
    """A trajectory was sampled outside ``[0, duration]``."""
