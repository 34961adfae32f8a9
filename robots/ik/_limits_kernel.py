"""Joint limits in the compiled IK solver (numba): wrapping to the ranges' 2π windows, projection, the exact check.

``L = (lower, upper, full_turn, unbounded, window_low, window_turns)`` as made by
:meth:`.numerical.NumericalIK._compiled` (the same rules as ``NumericalIK._wrap`` / ``_clip``).
Units: rad or m.
"""

from __future__ import annotations

import math

from pinarms.robots.ik._chain import jit

FREE, WINDOW, CLIP = 0, 1, 2  # free descent; free then wrapped to the ranges' windows; projected descent
_TWO_PI = 2.0 * math.pi


@jit
def wrap_unbounded(q, L):
    """Continuous joints of ``q`` (in place) to ``(-π, π]``."""
    unbounded = L[3]
    for j in range(q.shape[0]):
        if unbounded[j]:
            q[j] = math.pi - (math.pi - q[j]) % _TWO_PI


@jit
def wrap(q, L):
    """Revolute angles of ``q`` (in place) to the 2π window centred on their range, continuous ones to ``(-π, π]``."""
    unbounded, wlow, wturns = L[3], L[4], L[5]
    for j in range(q.shape[0]):
        if unbounded[j]:
            q[j] = math.pi - (math.pi - q[j]) % _TWO_PI
        elif wturns[j] > 0.0:
            q[j] -= _TWO_PI * math.floor((q[j] - wlow[j]) * wturns[j])


@jit
def clip(q, L):
    """Project ``q`` into the limits in place (see ``NumericalIK._clip``); True if a joint was clipped."""
    lo, hi, full_turn = L[0], L[1], L[2]
    wrap_unbounded(q, L)
    out = False
    for j in range(q.shape[0]):
        if q[j] < lo[j] or q[j] > hi[j]:
            out = True
    if not out:
        return False
    at = False
    for j in range(q.shape[0]):
        if full_turn[j]:
            if q[j] > hi[j]:
                q[j] -= _TWO_PI
            elif q[j] < lo[j]:
                q[j] += _TWO_PI
        if q[j] <= lo[j]:
            q[j] = lo[j]
            at = True
        elif q[j] >= hi[j]:
            q[j] = hi[j]
            at = True
    return at


@jit
def in_limits(q, L):
    """``lower ≤ q ≤ upper`` exactly (no tolerance)."""
    lo, hi = L[0], L[1]
    for j in range(q.shape[0]):
        if q[j] < lo[j] or q[j] > hi[j]:
            return False
    return True
