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
4-3-4 also has 14. Quintic pieces with ``continuity=4`` and given end velocities and
accelerations are the interpolating quintic B-spline (:mod:`pinarms.planning.bspline` uses this
system).

Populations: :func:`piecewise_polynomial_batch` solves the system for P timings of the same
via points at once (one scatter assembles the P matrices from a cached template, one
``np.linalg.solve`` on (P, N, N)); :func:`piecewise_polynomial` is the same code with P = 1.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning import _inputs
from pinarms.planning.errors import ConditionCountError, TrajectoryError
from pinarms.planning.polynomial import derivative_row
from pinarms.planning.trajectory import Trajectory

__all__ = ["piecewise_polynomial", "piecewise_polynomial_batch", "solve_coefficients", "PRESETS"]

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
    try:
        out = tuple(degrees)
    except TypeError:
        raise TrajectoryError(
            f"degrees must be a sequence of positive integers (one per segment) or a preset "
            f"{sorted(PRESETS)}, got {degrees!r}"
        ) from None
    if not out or any(isinstance(d, bool) or not isinstance(d, (int, np.integer)) or d < 1 for d in out):
        raise TrajectoryError(f"degrees must be positive integers, one per segment, got {degrees!r}")
    return tuple(int(d) for d in out)


@dataclass(frozen=True)
class _System:
    """Where the entries of the linear system go, for one degree pattern (cached).

    Row ``rows[e]``, column ``cols[e]`` of the matrix holds ``values[e] * (g[knots[e]] /
    h[segs[e]]) ** powers[e]``: a derivative condition of order r at knot k is scaled by
    ``g_k**r`` with ``g_k`` a duration of the pieces that meet there (see
    :func:`_row_scales`), so that its entries are O(1) whatever the other durations;
    ``unknown[i, k]`` is the index of the coefficient of ``s**k`` on segment i (``-1`` above
    the segment's degree).
    """

    size: int
    rows: np.ndarray
    cols: np.ndarray
    values: np.ndarray
    segs: np.ndarray
    powers: np.ndarray
    knots: np.ndarray
    start_rows: np.ndarray  # (end_order,) row of derivative r = 1.. at the start
    end_rows: np.ndarray  # (end_order,) row of derivative r = 1.. at the end
    unknown: np.ndarray  # (m, K+1)


@functools.lru_cache(maxsize=32)
def _system(degs: tuple[int, ...], continuity: int, end_order: int) -> _System:
    m = len(degs)
    offsets = np.concatenate([[0], np.cumsum([d + 1 for d in degs])])
    entries: list[tuple[int, int, float, int, int, int]] = []
    row = 0

    def put(r: int, seg: int, order: int, s: float, sign: float, knot: int) -> None:
        vals = derivative_row(degs[seg], order, s) * sign
        for k in np.flatnonzero(vals):
            entries.append((r, int(offsets[seg] + k), float(vals[k]), seg, order, knot))

    for i in range(m):
        put(row, i, 0, 0.0, 1.0, i)
        put(row + 1, i, 0, 1.0, 1.0, i + 1)
        row += 2
    start_rows, end_rows = [], []
    for r in range(1, end_order + 1):
        put(row, 0, r, 0.0, 1.0, 0)
        put(row + 1, m - 1, r, 1.0, 1.0, m)
        start_rows.append(row)
        end_rows.append(row + 1)
        row += 2
    for i in range(1, m):
        for r in range(1, continuity + 1):
            put(row, i - 1, r, 1.0, 1.0, i)
            put(row, i, r, 0.0, -1.0, i)
            row += 1
    K = max(degs)
    unknown = np.full((m, K + 1), -1)
    for i, d in enumerate(degs):
        unknown[i, : d + 1] = offsets[i] + np.arange(d + 1)
    rows, cols, values, segs, powers, knots = (np.array(col) for col in zip(*entries))
    out = _System(int(offsets[-1]), rows, cols, values.astype(float), segs, powers, knots,
                  np.array(start_rows, dtype=int), np.array(end_rows, dtype=int), unknown)
    for arr in (out.rows, out.cols, out.values, out.segs, out.powers, out.knots, out.unknown):
        arr.flags.writeable = False
    return out


def _row_scales(h: np.ndarray) -> np.ndarray:
    """Duration g_k (s) scaling the derivative conditions at knot k: (P, m) -> (P, m+1).

    The ends take their piece's duration; an interior knot the shorter of its two pieces,
    so that the larger of the two entries ``(g / h)**r`` of a continuity row is 1 and no
    ratio of durations is raised to the r-th power against the position rows.
    """
    g = np.empty((h.shape[0], h.shape[1] + 1))
    g[:, 0] = h[:, 0]
    g[:, -1] = h[:, -1]
    g[:, 1:-1] = np.minimum(h[:, :-1], h[:, 1:])
    return g


def _check_options(degrees: str | Sequence[int], n_knots: int, continuity: int, end_order: int) -> tuple[int, ...]:
    degs = _degrees(degrees)
    m = n_knots - 1
    if len(degs) != m:
        raise TrajectoryError(
            f"{len(degs)} segment degrees {degs} need {len(degs) + 1} knot times, got {n_knots}"
        )
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
    return degs


def solve_coefficients(
    t: np.ndarray,
    q: np.ndarray,
    degs: tuple[int, ...],
    continuity: int,
    end_order: int,
    start_derivatives: np.ndarray | None = None,
    end_derivatives: np.ndarray | None = None,
) -> np.ndarray:
    """Coefficients (P, m, K+1, n) in ascending powers of tau (s), one batched linear solve.

    Arguments are already checked: knot times ``t`` (P, m+1), positions ``q`` (m+1, n),
    degrees, and optionally the derivatives 1..end_order at the start and at the end
    (end_order, n) (default zero: at rest). Row p of the answer solves the system of
    individual p (module docstring); the matrices of all individuals are assembled with
    one scatter and solved by one ``np.linalg.solve`` on (P, N, N).
    """
    sysm = _system(degs, int(continuity), int(end_order))
    P, n, N = t.shape[0], q.shape[1], sysm.size
    m = len(degs)
    h = np.diff(t, axis=1)  # (P, m)
    g = _row_scales(h)  # (P, m+1)
    A = np.zeros((P, N, N))
    A[:, sysm.rows, sysm.cols] = sysm.values * (g[:, sysm.knots] / h[:, sysm.segs]) ** sysm.powers
    b = np.zeros((P, N, n))
    b[:, 0 : 2 * m : 2] = q[:-1]
    b[:, 1 : 2 * m : 2] = q[1:]
    orders = np.arange(1, end_order + 1, dtype=float)
    if start_derivatives is not None:  # d^r q/dt^r * g^r
        b[:, sysm.start_rows] = start_derivatives[None] * (g[:, :1, None] ** orders[None, :, None])
    if end_derivatives is not None:
        b[:, sysm.end_rows] = end_derivatives[None] * (g[:, -1:, None] ** orders[None, :, None])
    try:
        a = np.linalg.solve(A, b)
        if not np.all(np.isfinite(a)):
            raise np.linalg.LinAlgError
    except np.linalg.LinAlgError:
        raise TrajectoryError(
            f"the conditions for degrees {degs} are not independent (singular system"
            f"{' for one of the ' + str(P) + ' timings' if P > 1 else ''}); "
            "raise the degrees of the segments or lower continuity/end_order"
        ) from None
    k = np.arange(sysm.unknown.shape[1])
    valid = sysm.unknown >= 0
    coefs = np.where(valid[None, :, :, None], a[:, np.maximum(sysm.unknown, 0)], 0.0)  # (P, m, K+1, n)
    return coefs / (h[:, :, None] ** k)[..., None]


def piecewise_polynomial_batch(
    times: ArrayLike,
    positions: ArrayLike,
    degrees: str | Sequence[int] = (3, 5, 3),
    *,
    continuity: int = 2,
    end_order: int = 2,
) -> np.ndarray:
    """Coefficients of :func:`piecewise_polynomial` for P timings of the same via points at once.

    Args:
        times: (P, m+1) knot times (s), every row strictly increasing.
        positions: (m+1,) or (m+1, n_joints) via points shared by all rows (rad or m).
        degrees, continuity, end_order: as :func:`piecewise_polynomial`.

    Returns:
        (P, m, K+1, n_joints) coefficients in ascending powers of the time since each
        piece's start (row p is ``piecewise_polynomial(times[p], ...).coefficients``, from
        the same code); peak them with :func:`pinarms.planning.peaks_batch`.
    """
    t = _inputs.knot_times_batch(times)
    degs = _check_options(degrees, t.shape[1], continuity, end_order)
    q = _inputs.via_positions(positions, t.shape[1])
    if t.shape[0] == 0:
        return np.zeros((0, len(degs), max(degs) + 1, q.shape[1]))
    return solve_coefficients(t, q, degs, continuity, end_order)


def piecewise_polynomial(
    times: ArrayLike,
    positions: ArrayLike,
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
    t = _inputs.knot_times(times)
    degs = _check_options(degrees, t.size, continuity, end_order)
    q = _inputs.via_positions(positions, t.size)
    coefs = solve_coefficients(t[None], q, degs, continuity, end_order)[0]
    definition = {
        "kind": "piecewise_polynomial",
        "times": t.tolist(),
        "positions": q.tolist(),
        "degrees": list(degs),
        "continuity": int(continuity),
        "end_order": int(end_order),
    }
    return Trajectory(t, coefs, definition)
