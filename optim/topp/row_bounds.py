"""The rows of the TOPP-RA loops as bounds on the state x, pruned and laid out for the loops.

Both passes of :mod:`optim.topp.profile` reduce, at each grid point, rows ``c x <= slope y +
offset`` (y: the neighbouring set's end in step 1, the state itself in step 2) to a min and
a max. :func:`row_bounds` writes the rows as upper and lower bounds on x, :func:`prune`
leaves out those that cannot decide the min or max over the range the state can take, and
:func:`stage_lists` lays the rest out as flat Python lists, the form the loops read fastest.
"""

from __future__ import annotations

import numpy as np

__all__ = ["row_bounds", "prune", "stage_lists"]


def row_bounds(c: np.ndarray, slope: np.ndarray, offset: np.ndarray) -> tuple[np.ndarray, ...]:
    """Rows ``c x <= slope y + offset`` as ``x <= Su y + Ou`` (c > 0) and ``x >= Sl y + Ol`` (c < 0).

    Rows that do not apply get the neutral offset (+inf for upper, -inf for lower bounds), so
    that a step of the loops is a min and a max over whole rows. ``c == 0`` rows are returned
    as ``0 <= slope y + offset`` conditions (``Zs``, ``Zo``; neutral +inf where they do not apply).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.where(c != 0.0, 1.0 / np.where(c != 0.0, c, 1.0), 0.0)
        up = c > 0.0
        dn = c < 0.0
        zero = (c == 0.0) & np.isfinite(offset)
        Su = np.where(up, slope * inv, 0.0)
        Ou = np.where(up, offset * inv, np.inf)
        Sl = np.where(dn, slope * inv, 0.0)
        Ol = np.where(dn, offset * inv, -np.inf)
        Zs = np.where(zero, slope, 0.0)
        Zo = np.where(zero, offset, np.inf)
    Ou[np.isnan(Ou)] = np.inf
    Ol[np.isnan(Ol)] = -np.inf
    return Su, Ou, Sl, Ol, Zs, Zo


def prune(slope: np.ndarray, offset: np.ndarray, x_lo: np.ndarray, x_hi: np.ndarray, upper: bool) -> np.ndarray:
    """``offset`` with the rows that cannot decide the min (``upper``) or max over ``[x_lo, x_hi]`` made neutral.

    Row r of point i gives ``slope x + offset`` for x in ``[x_lo_i, x_hi_i]`` (N,). It is left
    out when, at both ends of the range, it is beyond the row that is best at the left end
    (or the one best at the right end) by more than 1e-9 of the rows' scale: a linear function
    then stays beyond it over the whole range, far more than the rounding of ``slope x +
    offset``, so the minimum (maximum) is the same to the last bit without it.
    """
    sign = 1.0 if upper else -1.0
    neutral = np.inf if upper else -np.inf
    with np.errstate(invalid="ignore", over="ignore"):
        v_lo = sign * (slope * x_lo[:, None] + offset)
        v_hi = sign * (slope * x_hi[:, None] + offset)
        scale = 1e-9 * (np.abs(slope) * np.maximum(np.abs(x_lo), np.abs(x_hi))[:, None] + np.abs(offset))
        ok = np.isfinite(v_lo) & np.isfinite(v_hi) & np.isfinite(scale)
        keep = np.ones(slope.shape, dtype=bool)
        for best in (np.argmin(np.where(ok, v_lo, np.inf), axis=1), np.argmin(np.where(ok, v_hi, np.inf), axis=1)):
            pick = best[:, None]
            gap = np.take_along_axis(scale, pick, axis=1) + scale
            beyond = (v_lo > np.take_along_axis(v_lo, pick, axis=1) + gap) & \
                     (v_hi > np.take_along_axis(v_hi, pick, axis=1) + gap)
            keep &= ~(beyond & ok & np.take_along_axis(ok, pick, axis=1))
    return np.where(keep, offset, neutral)


def stage_lists(*pairs: np.ndarray) -> tuple[tuple[list, list, list], ...]:
    """The rows that bind at each grid point, as flat Python lists: ``(slopes, offsets, starts)`` per pair.

    ``pairs`` are (slope, offset) arrays (N, m) such as :func:`row_bounds` returns. A row whose
    offset is neutral (+inf for upper and zero rows, -inf for lower rows) cannot change a
    minimum or maximum and is left out; grid point i's rows are ``slopes[starts[i]:starts[i + 1]]``
    (written out in the loops: a call or a list per step would cost more than the arithmetic).
    The loops then run on Python floats: on grids of a few thousand points and a few dozen
    rows that is several times faster than one numpy reduction per step, with the same
    arithmetic (a product and a sum per row, exact min and max), so the same bits.
    """
    out = []
    for k in range(0, len(pairs), 2):
        slope, offset = pairs[k], pairs[k + 1]
        live = np.isfinite(offset)
        starts = np.concatenate([[0], np.cumsum(live.sum(axis=1))]).tolist()
        out.append((slope[live].tolist(), offset[live].tolist(), starts))
    return tuple(out)
