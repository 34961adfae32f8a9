"""What the torque and limit constraints read of a timed joint curve: :class:`TimedCurve`.

A :class:`pinarms.planning.Trajectory` is one; so is the stand-in the time-optimal timing builds while it
refines (:mod:`pinarms.optim.topp`). The constraints of :mod:`pinarms.planning.path_constraints` and
:mod:`pinarms.planning.torque` take either, typed by this protocol, so neither module needs the
trajectory's module (which imports them back lazily) and this one imports neither: no import circle, even for type-only imports.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["TimedCurve", "CurvePeaks"]


class CurvePeaks(Protocol):
    """Per-joint peaks of a timed curve (:class:`pinarms.planning.trajectory.Peaks` is one)."""

    velocity: np.ndarray
    acceleration: np.ndarray


class TimedCurve(Protocol):
    """A piecewise-polynomial joint curve in time (the members the constraints read)."""

    @property
    def n_joints(self) -> int:
        """How many joints (columns) it moves."""

    @property
    def knot_times(self) -> np.ndarray:
        """(m+1,) piece boundaries [s]."""

    @property
    def coefficients(self) -> np.ndarray:
        """(m, K+1, n_joints) ascending powers of the time since each piece's start."""

    def peaks(self) -> CurvePeaks:
        """Exact per-joint velocity, acceleration and jerk peaks."""

    def sample(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity, acceleration, jerk at instants ``t`` [s]."""
