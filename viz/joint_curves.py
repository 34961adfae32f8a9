"""Sampled joint curves to draw: :class:`JointCurves`, checked when made.

:func:`pinarms.viz.plots.plot_joint_curves` draws one: instants ``t`` [s] and the joint values at them
(position and, when given, velocity, acceleration, jerk), with optional knot instants.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput

from pinarms.viz.figure_files import checked_numbers

__all__ = ["JointCurves", "ORDERS"]

#: The derivative orders a :class:`JointCurves` may hold, by field: q, qd, qdd, qddd.
ORDERS = ("position", "velocity", "acceleration", "jerk")


@dataclass(frozen=True)
class JointCurves:
    """Joint curves sampled at instants ``t``.

    Attributes:
        t: instants (N,) [s], N >= 2, strictly increasing.
        q, qd, qdd, qddd: (N, n) (or (N,)) in rad, rad/s, ... (or m, m/s, ...); those left
            ``None`` are not drawn (at least one given; all with the same n).
        knot_times: knot (via point) instants [s], or ``None``.

    After checking, the fields hold float arrays: ``t`` (N,), each series (N, n), ``knot_times`` (K,).

    Raises:
        InvalidInput: naming the field: not numbers, NaN, wrong shapes, instants not increasing.
    """

    t: ArrayLike
    q: ArrayLike | None
    qd: ArrayLike | None = None
    qdd: ArrayLike | None = None
    qddd: ArrayLike | None = None
    knot_times: ArrayLike | None = None

    def __post_init__(self) -> None:
        tt = checked_numbers(self.t, "t")
        if tt.ndim != 1 or tt.size < 2:
            raise InvalidInput(f"t must be (N,) instants in s with N >= 2, got shape {tt.shape}")
        if np.any(np.diff(tt) <= 0):
            raise InvalidInput("t must be strictly increasing instants in s")
        object.__setattr__(self, "t", tt)
        for field, what in zip(("q", "qd", "qdd", "qddd"), ORDERS):
            values = getattr(self, field)
            if values is None:
                continue
            arr = checked_numbers(values, what)
            arr = arr[:, None] if arr.ndim == 1 else arr
            if arr.ndim != 2 or arr.shape[0] != tt.size:
                raise InvalidInput(f"{what} must have shape ({tt.size}, n_joints), got {np.shape(values)}")
            object.__setattr__(self, field, arr)
        series = self.series
        if not series:
            raise InvalidInput("give at least one of q, qd, qdd, qddd")
        if any(a.shape[1] != series[0][1].shape[1] for _, a in series):
            raise InvalidInput("q, qd, qdd and qddd must have the same number of joints")
        if self.knot_times is not None:
            object.__setattr__(self, "knot_times", checked_numbers(self.knot_times, "knot_times").ravel())

    @property
    def series(self) -> list[tuple[int, np.ndarray]]:
        """``(order, (N, n) values)`` of each series given, in order (0: position ... 3: jerk)."""
        return [(k, a) for k, a in enumerate((self.q, self.qd, self.qdd, self.qddd)) if a is not None]
