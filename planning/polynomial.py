"""A single polynomial in time through all given points, at rest at both ends where the degree allows.

With ``m+1`` points and degree ``K`` there are ``K+1`` coefficients: ``m+1`` go to the
positions, the remaining ``K-m`` (which must be even) make the first ``(K-m)/2``
derivatives zero at both ends (velocity, then acceleration, then jerk, ...). Examples:

* cubic through 2 points: zero velocity at both ends (4 = 2 + 2);
* quintic through 2 points: zero velocity and acceleration (6 = 2 + 4);
* septic through 4 points: zero velocity and acceleration (8 = 4 + 4) — seed 001's
  "7th-order polynomial through P1..P4".

The coefficients come from one Vandermonde-like solve in normalised time
``s = (t - t_0) / (t_m - t_0)`` (well conditioned for the degrees used here), converted to
the common piecewise representation of :class:`pinarms.planning.Trajectory` (one piece).
"""

from __future__ import annotations

import functools


import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning import _inputs
from pinarms.planning.errors import ConditionCountError, TrajectoryError
from pinarms.planning.trajectory import Trajectory

__all__ = ["polynomial", "derivative_row"]


def derivative_row(degree: int, order: int, s: float) -> np.ndarray:
    """Row ``[d^order/ds^order s^k for k = 0..degree]`` evaluated at ``s`` (length degree+1)."""
    k = np.arange(degree + 1)
    falling = np.ones(degree + 1)
    for r in range(order):
        falling *= k - r
    expo = np.clip(k - order, 0, None)
    return np.where(k >= order, falling * float(s) ** expo, 0.0)


def polynomial(times: ArrayLike, positions: ArrayLike, degree: int) -> Trajectory:
    """One polynomial of ``degree`` through ``positions`` at ``times``, at rest at both ends.

    Args:
        times: strictly increasing instants (s), (m+1,), m >= 1.
        positions: (m+1,) for one joint or (m+1, n_joints) (rad or m).
        degree: polynomial degree K >= m; ``K - m`` must be even (end conditions split
            evenly between the two ends).

    Raises:
        ConditionCountError: when the degree cannot match the number of points
            (too few coefficients, or an odd number left for the ends), naming the counts.
    """
    t = _inputs.knot_times(times)
    q = _inputs.via_positions(positions, t.size)
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or degree < 1:
        raise TrajectoryError(f"degree must be a positive integer, got {degree!r}")
    K = int(degree)
    n_points = t.size
    extra = K + 1 - n_points
    if extra < 0:
        raise ConditionCountError(
            f"a degree-{K} polynomial has {K + 1} coefficients but {n_points} points were given; "
            f"use degree >= {n_points - 1} (or fewer points)"
        )
    if extra % 2:
        raise ConditionCountError(
            f"a degree-{K} polynomial through {n_points} points leaves {extra} end condition(s), "
            f"which cannot be split between the two ends; use degree {K - 1} or {K + 1}"
        )
    T = t[-1] - t[0]
    s = (t - t[0]) / T
    A = _conditions(K, tuple(s.tolist()))
    b = np.zeros((K + 1, q.shape[1]))
    b[:n_points] = q
    try:
        a = np.linalg.solve(A, b)
    except np.linalg.LinAlgError as exc:  # pragma: no cover - Vandermonde with distinct s is regular
        raise TrajectoryError(f"the degree-{K} conditions are singular for times {t.tolist()}") from exc
    coefs = a / (T ** np.arange(K + 1))[:, None]
    definition = {"kind": "polynomial", "times": t.tolist(), "positions": q.tolist(), "degree": K}
    return Trajectory(t[[0, -1]], coefs[None], definition)


@functools.lru_cache(maxsize=256)
def _conditions(degree: int, s: tuple[float, ...]) -> np.ndarray:
    """The condition matrix (K+1, K+1) of :func:`polynomial` (cached: a rest-to-rest move always has s = (0, 1)).

    Rows: the positions at the normalised instants ``s``, then derivatives 1, 2, ... equal to
    zero at s = 0 and s = 1, alternately.
    """
    rows = [derivative_row(degree, 0, si) for si in s]
    for r in range(1, (degree + 1 - len(s)) // 2 + 1):
        rows.append(derivative_row(degree, r, 0.0))
        rows.append(derivative_row(degree, r, 1.0))
    A = np.array(rows)
    A.flags.writeable = False
    return A
