"""Quintic B-spline through via points (seed 002), for one timing or a whole population.

A degree-5 B-spline interpolating ``m+1`` via points at the given times has its interior
knots at the via times (simple knots), so it is C⁴ there: velocity, acceleration, jerk
and snap are continuous, which is why seed 002 takes k = 5 (k >= 4 is needed for a
continuous jerk). The four extra conditions of an odd-degree interpolating spline are the
end velocities and accelerations (zero unless given).

:func:`quintic_bspline` builds it with scipy's B-spline machinery
(:func:`scipy.interpolate.make_interp_spline`, ``k=5``, first and second derivatives given
at both ends) and converts it to the common piecewise-polynomial form by evaluating the
derivatives at the start of every piece.

:func:`quintic_bspline_batch` serves the optimiser, which needs the spline for a whole
population of timings at once: a C⁴ quintic spline through the points with these end
conditions is unique, so it solves the equivalent piecewise system (m quintic pieces, 6m
unknowns: positions at both ends of every piece, continuity of derivatives 1..4 at the
m-1 interior knots, the 4 end conditions) with :mod:`pinarms.planning.piecewise`'s batched solver.
The tests check that both give the same coefficients.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import make_interp_spline

from pinarms.planning import _inputs
from pinarms.planning.piecewise import solve_coefficients
from pinarms.planning.trajectory import Trajectory

__all__ = ["quintic_bspline", "quintic_bspline_batch"]

_ENDS = ("start_velocity", "end_velocity", "start_acceleration", "end_acceleration")


def _end_values(n: int, values: dict[str, Any]) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
    """Checked end derivatives per joint, and the (2, n) start and end rows (velocity, acceleration)."""
    vals = {k: _inputs.per_joint(values[k], n, k) for k in _ENDS}
    start = np.stack([vals["start_velocity"], vals["start_acceleration"]])
    end = np.stack([vals["end_velocity"], vals["end_acceleration"]])
    return vals, start, end


def quintic_bspline_batch(
    times: ArrayLike,
    positions: ArrayLike,
    *,
    start_velocity: ArrayLike = 0.0,
    end_velocity: ArrayLike = 0.0,
    start_acceleration: ArrayLike = 0.0,
    end_acceleration: ArrayLike = 0.0,
) -> np.ndarray:
    """Coefficients of :func:`quintic_bspline` for P timings of the same via points at once.

    Args:
        times: (P, m+1) knot times (s), every row strictly increasing.
        positions: (m+1,) or (m+1, n_joints) via points shared by all rows (rad or m).
        start_velocity, end_velocity, start_acceleration, end_acceleration: as
            :func:`quintic_bspline` (shared by all rows).

    Returns:
        (P, m, 6, n_joints) coefficients in ascending powers of the time since each piece's
        start; row p equals ``quintic_bspline(times[p], ...).coefficients`` (the same spline,
        solved as a piecewise system instead of by scipy).
    """
    t = _inputs.knot_times_batch(times)
    q = _inputs.via_positions(positions, t.shape[1])
    m, n = t.shape[1] - 1, q.shape[1]
    _, start, end = _end_values(n, {"start_velocity": start_velocity, "end_velocity": end_velocity,
                                    "start_acceleration": start_acceleration,
                                    "end_acceleration": end_acceleration})
    if t.shape[0] == 0:
        return np.zeros((0, m, 6, n))
    return solve_coefficients(t, q, (5,) * m, 4, 2, start, end)


def quintic_bspline(
    times: ArrayLike,
    positions: ArrayLike,
    *,
    start_velocity: ArrayLike = 0.0,
    end_velocity: ArrayLike = 0.0,
    start_acceleration: ArrayLike = 0.0,
    end_acceleration: ArrayLike = 0.0,
) -> Trajectory:
    """Degree-5 interpolating B-spline through ``positions`` at ``times`` (C⁴ at interior knots).

    Args:
        times: knot times (s), (m+1,), strictly increasing, m >= 1.
        positions: (m+1,) or (m+1, n_joints) (rad or m).
        start_velocity, end_velocity: rad/s, scalar or (n_joints,); default 0.
        start_acceleration, end_acceleration: rad/s², scalar or (n_joints,); default 0.
    """
    t = _inputs.knot_times(times)
    q = _inputs.via_positions(positions, t.size)
    vals, start, end = _end_values(q.shape[1], {"start_velocity": start_velocity,
                                                "end_velocity": end_velocity,
                                                "start_acceleration": start_acceleration,
                                                "end_acceleration": end_acceleration})
    spline = make_interp_spline(
        t, q, k=5, bc_type=([(1, start[0]), (2, start[1])], [(1, end[0]), (2, end[1])])
    )
    coefs = np.stack([spline(t[:-1], nu=k) / math.factorial(k) for k in range(6)], axis=1)
    definition = {"kind": "quintic_bspline", "times": t.tolist(), "positions": q.tolist()}
    definition.update({k: v.tolist() for k, v in vals.items()})
    return Trajectory(t, coefs, definition)
