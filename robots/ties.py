"""Tie rules: choices that must not depend on the last bit of a float.

Which joint limits a move, which IK solution is nearest, in which order equal-cost
candidates are listed: when two values are equal up to rounding, ``np.argmax`` /
``np.argsort`` pick whichever is larger *in the last bit*, and that differs between
processors and BLAS builds. These helpers treat values within a tolerance as equal and
break the tie by the **lowest index** (the joint order, the solver's branch order).
"""

from __future__ import annotations

import numpy as np

__all__ = ["TIE_RTOL", "TIE_ATOL", "near_max", "argmin_tied", "argsort_tied"]

#: Values within ``TIE_ATOL + TIE_RTOL * |reference|`` of each other count as equal.
TIE_RTOL = 1e-9
TIE_ATOL = 1e-12


def _tol(ref: float, rtol: float, atol: float) -> float:
    return atol + rtol * abs(ref)


def near_max(values, rtol: float = TIE_RTOL, atol: float = TIE_ATOL) -> np.ndarray:
    """Indices (ascending) of every entry within tolerance of the largest finite value.

    ``near_max([1.0, 0.92, 1.0 - 1e-14])`` is ``[0, 2]``: both joints are at their limit.
    An array without a finite value gives an empty result.
    """
    v = np.asarray(values, dtype=float).reshape(-1)
    finite = np.isfinite(v)
    if not finite.any():
        return np.arange(0)
    top = float(v[finite].max())
    return np.flatnonzero(finite & (v >= top - _tol(top, rtol, atol)))


def argmin_tied(values, rtol: float = TIE_RTOL, atol: float = TIE_ATOL) -> int:
    """Index of the smallest value; among values within tolerance of it, the lowest index."""
    v = np.asarray(values, dtype=float).reshape(-1)
    if v.size == 0:
        raise ValueError("argmin_tied of an empty sequence")
    finite = np.isfinite(v)
    if not finite.any():
        return 0
    low = float(v[finite].min())
    return int(np.flatnonzero(finite & (v <= low + _tol(low, rtol, atol)))[0])


def argsort_tied(values, rtol: float = TIE_RTOL, atol: float = TIE_ATOL) -> np.ndarray:
    """Ascending order; runs of values each within tolerance of the run's first are kept in index order.

    Non-finite values go last, in index order.
    """
    v = np.asarray(values, dtype=float).reshape(-1)
    order = np.argsort(v, kind="stable")
    out: list[int] = []
    i = 0
    n = v.size
    while i < n:
        start = v[order[i]]
        if not np.isfinite(start):
            out.extend(sorted(int(k) for k in order[i:]))
            break
        j = i + 1
        limit = start + _tol(float(start), rtol, atol)
        while j < n and np.isfinite(v[order[j]]) and v[order[j]] <= limit:
            j += 1
        out.extend(sorted(int(k) for k in order[i:j]))
        i = j
    return np.asarray(out, dtype=np.intp)
