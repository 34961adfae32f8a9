"""Quintic B-spline through via points (seed 002), with scipy's B-spline machinery.

A degree-5 B-spline interpolating ``m+1`` via points at the given times has its interior
knots at the via times (simple knots), so it is C⁴ there: velocity, acceleration, jerk
and snap are continuous, which is why seed 002 takes k = 5 (k >= 4 is needed for a
continuous jerk). The four extra conditions of an odd-degree interpolating spline are the
end velocities and accelerations (zero unless given).

The spline is built with :func:`scipy.interpolate.make_interp_spline` (``k=5``,
``bc_type`` with first and second derivatives at both ends; all joints in one call) and
converted to the common piecewise representation of :class:`planning.Trajectory` from its
derivatives 0..5 at the left end of every piece.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.interpolate import make_interp_spline

from planning import _inputs
from planning.errors import TrajectoryError
from planning.trajectory import Trajectory

__all__ = ["quintic_bspline"]

_INV_FACTORIAL = np.array([1.0 / math.factorial(k) for k in range(6)])


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
    n = q.shape[1]
    ends = {
        "start_velocity": start_velocity,
        "end_velocity": end_velocity,
        "start_acceleration": start_acceleration,
        "end_acceleration": end_acceleration,
    }
    vals = {k: _inputs.per_joint(v, n, k) for k, v in ends.items()}
    bc = (
        [(1, vals["start_velocity"]), (2, vals["start_acceleration"])],
        [(1, vals["end_velocity"]), (2, vals["end_acceleration"])],
    )
    try:
        spline = make_interp_spline(t, q, k=5, bc_type=bc, axis=0)
    except (ValueError, np.linalg.LinAlgError) as exc:  # pragma: no cover - knot_times already checked
        raise TrajectoryError(f"quintic B-spline through times {t.tolist()} failed: {exc}") from exc
    left = t[:-1]
    derivs = np.stack([spline(left, nu) for nu in range(6)], axis=1)  # (m, 6, n)
    coefs = derivs * _INV_FACTORIAL[None, :, None]
    definition = {"kind": "quintic_bspline", "times": t.tolist(), "positions": q.tolist()}
    definition.update({k: v.tolist() for k, v in vals.items()})
    return Trajectory(t, coefs, definition)
