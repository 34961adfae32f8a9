"""Piecewise polynomials of mixed degree (3-5-3, 4-3-4, ...) from ONE linear system.

Segment ``i`` (duration ``h_i``) is a polynomial of degree ``d_i`` in its normalised time
``s = (t - t_i) / h_i`` in [0, 1], as in seed 000 (eq. 4). The unknowns of all segments,
``sum(d_i + 1)`` of them, are fixed by

* the positions at both ends of every segment (2m conditions),
* rest at both ends: derivatives 1..``end_order`` zero at the start and the end
  (2·end_order; velocity and acceleration for the default ``end_order=2``),
* continuity of derivatives 1..``continuity`` at every interior knot, in real time
  (``q_i^{(r)}(1) / h_i^r = q_{i+1}^{(r)}(0) / h_{i+1}^r``; (m-1)·continuity conditions).

There must be exactly as many conditions as unknowns, otherwise :class:`ConditionCountError`
names both counts. For 3-5-3: 4+6+4 = 14 unknowns and 6 + 4 + 4 = 14 conditions (seed 000);
4-3-4 also has 14.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from planning import _inputs
from planning.errors import ConditionCountError, TrajectoryError
from planning.polynomial import derivative_row
from planning.trajectory import Trajectory

__all__ = ["piecewise_polynomial", "PRESETS"]

#: Named degree patterns.
PRESETS: dict[str, tuple[int, ...]] = {"3-5-3": (3, 5, 3), "4-3-4": (4, 3, 4)}


def _degrees(degrees: str | Sequence[int]) -> tuple[int, ...]:
    if isinstance(degrees, str):
        if degrees in PRESETS:
            return PRESETS[degrees]
        try:
            return tuple(int(p) for p in degrees.split("-"))
        except ValueError:
            raise TrajectoryError(
                f"degrees {degrees!r} is not a preset ({sorted(PRESETS)}) nor a pattern like '3-5-3'"
            ) from None
    out = tuple(degrees)
    if not out or any(isinstance(d, bool) or not isinstance(d, (int, np.integer)) or d < 1 for d in out):
        raise TrajectoryError(f"degrees must be positive integers, one per segment, got {degrees!r}")
    return tuple(int(d) for d in out)


def piecewise_polynomial(
    times: Any,
    positions: Any,
    degrees: str | Sequence[int] = (3, 5, 3),
    *,
    continuity: int = 2,
    end_order: int = 2,
) -> Trajectory:
    """Piecewise polynomial through via points, one degree per segment, from one linear solve.

    Args:
        times: knot times (s), (m+1,), strictly increasing; m = len(degrees).
        positions: (m+1,) or (m+1, n_joints) (rad or m).
        degrees: per-segment degrees, or a preset ``"3-5-3"`` / ``"4-3-4"``.
        continuity: highest derivative continuous at interior knots (2: velocity and acceleration).
        end_order: highest derivative that is zero at both ends (2: at rest, zero acceleration).

    Raises:
        ConditionCountError: when the conditions do not match the unknowns (counts named).
    """
    degs = _degrees(degrees)
    t = _inputs.knot_times(times)
    m = t.size - 1
    if len(degs) != m:
        raise TrajectoryError(
            f"{len(degs)} segment degrees {degs} need {len(degs) + 1} knot times, got {t.size}"
        )
    q = _inputs.via_positions(positions, t.size)
    for name, value in (("continuity", continuity), ("end_order", end_order)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
            raise TrajectoryError(f"{name} must be a non-negative integer, got {value!r}")
    unknowns = sum(d + 1 for d in degs)
    conditions = 2 * m + 2 * end_order + (m - 1) * continuity
    if unknowns != conditions:
        raise ConditionCountError(
            f"degrees {'-'.join(map(str, degs))} have {unknowns} coefficients but there are {conditions} "
            f"conditions ({2 * m} positions, {2 * end_order} end derivatives, {(m - 1) * continuity} "
            f"continuity); choose degrees whose coefficients add up to {conditions}, or change "
            "continuity/end_order"
        )
    h = np.diff(t)
    h_ref = float(np.mean(h))
    offsets = np.concatenate([[0], np.cumsum([d + 1 for d in degs])])
    A = np.zeros((unknowns, unknowns))
    b = np.zeros((unknowns, q.shape[1]))
    row = 0
    for i, d in enumerate(degs):
        cols = slice(offsets[i], offsets[i + 1])
        A[row, cols] = derivative_row(d, 0, 0.0)
        b[row] = q[i]
        A[row + 1, cols] = derivative_row(d, 0, 1.0)
        b[row + 1] = q[i + 1]
        row += 2
    for r in range(1, end_order + 1):
        A[row, offsets[0] : offsets[1]] = derivative_row(degs[0], r, 0.0)
        A[row + 1, offsets[m - 1] : offsets[m]] = derivative_row(degs[-1], r, 1.0)
        row += 2
    for i in range(1, m):
        for r in range(1, continuity + 1):
            # Rows scaled by h_ref^r so that all entries are O(1).
            A[row, offsets[i - 1] : offsets[i]] = derivative_row(degs[i - 1], r, 1.0) * (h_ref / h[i - 1]) ** r
            A[row, offsets[i] : offsets[i + 1]] = -derivative_row(degs[i], r, 0.0) * (h_ref / h[i]) ** r
            row += 1
    try:
        a = np.linalg.solve(A, b)
        if not np.all(np.isfinite(a)):
            raise np.linalg.LinAlgError
    except np.linalg.LinAlgError:
        raise TrajectoryError(
            f"the conditions for degrees {degs} are not independent (singular system); "
            "raise the degrees of the segments or lower continuity/end_order"
        ) from None
    K = max(degs)
    coefs = np.zeros((m, K + 1, q.shape[1]))
    for i, d in enumerate(degs):
        coefs[i, : d + 1] = a[offsets[i] : offsets[i + 1]] / (h[i] ** np.arange(d + 1))[:, None]
    definition = {
        "kind": "piecewise_polynomial",
        "times": t.tolist(),
        "positions": q.tolist(),
        "degrees": list(degs),
        "continuity": int(continuity),
        "end_order": int(end_order),
    }
    return Trajectory(t, coefs, definition)
