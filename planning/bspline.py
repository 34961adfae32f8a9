"""Quintic B-spline through via points (seed 002), for one timing or a whole population.

A degree-5 B-spline interpolating ``m+1`` via points at the given times has its interior
knots at the via times (simple knots), so it is C⁴ there: velocity, acceleration, jerk
and snap are continuous, which is why seed 002 takes k = 5 (k >= 4 is needed for a
continuous jerk). The four extra conditions of an odd-degree interpolating spline are the
end velocities and accelerations (zero unless given).

The spline is computed in its piecewise-polynomial form: m quintic pieces (6m unknowns)
fixed by the positions at both ends of every piece (2m), continuity of derivatives 1..4 at
the m-1 interior knots (4(m-1)) and the end velocities and accelerations (4). This is the
system of :mod:`planning.piecewise` with degrees 5-5-...-5, ``continuity=4`` and
``end_order=2``, solved by the same code (batched over timings); a C⁴ quintic spline
through the points with these end conditions is unique, so it *is* the B-spline of
:func:`scipy.interpolate.make_interp_spline` (``k=5``, first and second derivatives given
at both ends), which the tests check to 1e-9.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from planning import _inputs
from planning.piecewise import solve_coefficients
from planning.trajectory import Trajectory

__all__ = ["quintic_bspline", "quintic_bspline_batch"]

_ENDS = ("start_velocity", "end_velocity", "start_acceleration", "end_acceleration")


def _end_values(n: int, values: dict[str, Any]) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
    """Checked end derivatives per joint, and the (2, n) start and end rows (velocity, acceleration)."""
    vals = {k: _inputs.per_joint(values[k], n, k) for k in _ENDS}
    start = np.stack([vals["start_velocity"], vals["start_acceleration"]])
    end = np.stack([vals["end_velocity"], vals["end_acceleration"]])
    return vals, start, end


def quintic_bspline_batch(
    times: Any,
    positions: Any,
    *,
    start_velocity: Any = 0.0,
    end_velocity: Any = 0.0,
    start_acceleration: Any = 0.0,
    end_acceleration: Any = 0.0,
) -> np.ndarray:
    """Coefficients of :func:`quintic_bspline` for P timings of the same via points at once.

    Args:
        times: (P, m+1) knot times (s), every row strictly increasing.
        positions: (m+1,) or (m+1, n_joints) via points shared by all rows (rad or m).
        start_velocity, end_velocity, start_acceleration, end_acceleration: as
            :func:`quintic_bspline` (shared by all rows).

    Returns:
        (P, m, 6, n_joints) coefficients in ascending powers of the time since each piece's
        start; row p is ``quintic_bspline(times[p], ...).coefficients`` (same code).
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
    times: Any,
    positions: Any,
    *,
    start_velocity: Any = 0.0,
    end_velocity: Any = 0.0,
    start_acceleration: Any = 0.0,
    end_acceleration: Any = 0.0,
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
    coefs = solve_coefficients(t[None], q, (5,) * (t.size - 1), 4, 2, start, end)[0]
    definition = {"kind": "quintic_bspline", "times": t.tolist(), "positions": q.tolist()}
    definition.update({k: v.tolist() for k, v in vals.items()})
    return Trajectory(t, coefs, definition)
