"""Where a task map needs more nodes: the times' bend tested against linear interpolation, per node or per grid line.

A map interpolates linearly between its nodes (bilinear in ``du``, ``w``; linear between yaw
layers). At an interior node ``k`` of a grid ``x`` the interpolation across it would err by
``dev = |T_k − (h₊ T_k−1 + h₋ T_k+1) / (h₋ + h₊)|`` (``h₋``, ``h₊`` the spacings on either side;
half the second difference on an even grid); at a node where ``dev`` exceeds ``2 × tolerance`` of
the task time there (``t_A + t_C + extra``), the time bends more than linear interpolation
follows: interpolation errs by about a quarter of the second difference at a kink, an eighth on a
smooth bend, so the two intervals beside it get a node in their middle.

- :func:`bent_lines` marks whole grid lines (a ``du`` column or a ``w`` row: every node along it
  is planned), from any branch, yaw layer and node across.
- :func:`bent_nodes` marks each (``du``, ``w``) node on its own (the yaw axis): a new yaw layer is
  planned only at the nodes whose time bends there; at the others it holds the linear
  interpolation of its two neighbours (what the map gave there before the layer, within the
  tolerance by the test above), so a yaw layer costs only the plans the bend needs.
- :func:`merge_nodes` puts new nodes and their tables into a grid, sorted; :func:`add_yaw_nodes`
  is one yaw pass (the nodes that bend planned, the others interpolated).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

__all__ = ["bent_lines", "bent_nodes", "merge_nodes", "add_yaw_nodes"]


def _deviation(x: np.ndarray, T: np.ndarray) -> np.ndarray:
    """``dev`` (module doc) at the interior nodes of ``x`` along axis 0 of ``T``: (len(x) − 2, ...)."""
    h0 = (x[1:-1] - x[:-2]).reshape(-1, *([1] * (T.ndim - 1)))
    h1 = (x[2:] - x[1:-1]).reshape(h0.shape)
    return np.abs(T[1:-1] - (h1 * T[:-2] + h0 * T[2:]) / (h0 + h1))


def _bent(x: np.ndarray, A: np.ndarray, C: np.ndarray, extra: float, tolerance: float) -> np.ndarray:
    """(len(x) − 2, ...) whether the approach or the leave bends at each interior node along axis 0
    (NaN, an infeasible node on either side: not bent)."""
    tot = (A + C)[1:-1] + extra
    with np.errstate(invalid="ignore"):
        return (_deviation(x, A) > 2.0 * tolerance * tot) | (_deviation(x, C) > 2.0 * tolerance * tot)


def _intervals(bent: np.ndarray) -> np.ndarray:
    """Intervals (len(x) − 1, ...) beside a bent interior node."""
    mark = np.zeros((bent.shape[0] + 1, *bent.shape[1:]), bool)
    mark[:-1] |= bent
    mark[1:] |= bent
    return mark


def bent_lines(x: np.ndarray, A: np.ndarray, C: np.ndarray, extra: float, tolerance: float, axis: int) -> np.ndarray:
    """Midpoints of the intervals of grid ``x`` (along ``axis`` of the tables ``A``, ``C`` of any
    shape) beside a node where some approach or leave time bends (module doc)."""
    if x.size < 3:
        return np.zeros(0)
    bent = _bent(x, np.moveaxis(A, axis, 0), np.moveaxis(C, axis, 0), extra, tolerance)
    mark = _intervals(bent.reshape(bent.shape[0], -1).any(axis=1))
    return 0.5 * (x[:-1] + x[1:])[mark]


def bent_nodes(yaw: np.ndarray, A: np.ndarray, C: np.ndarray, extra: float, tolerance: float) -> np.ndarray:
    """(ny − 1, nu, nw) the yaw intervals, at each (du, w) node, beside a yaw node where the time
    bends on some branch (tables (ny, nb, nu, nw)); module doc."""
    if yaw.size < 3:
        return np.zeros((max(yaw.size - 1, 0), *A.shape[2:]), bool)
    return _intervals(_bent(yaw, A, C, extra, tolerance).any(axis=1))


def merge_nodes(x: np.ndarray, new: np.ndarray, tables: tuple, added: tuple, axis: int) -> tuple:
    """Grid ``x`` with ``new`` points, and each table with its ``added`` slices along ``axis``, sorted."""
    order = np.argsort(np.concatenate([x, new]), kind="stable")
    return (np.concatenate([x, new])[order],
            *(np.take(np.concatenate([t, a], axis=axis), order, axis=axis) for t, a in zip(tables, added)))


def add_yaw_nodes(yaw: np.ndarray, A: np.ndarray, C: np.ndarray, extra: float, tolerance: float,
                  plan: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]) -> tuple:
    """One yaw refinement pass over tables (ny, nb, nu, nw): a yaw node in the middle of every yaw
    interval that bends at some (du, w) node (:func:`bent_nodes`); ``plan(mid, need)`` gives the
    tables (len(mid), nb, nu, nw) planned where ``need`` (len(mid), nu, nw), and every other node of
    the new layer holds the mean of its two neighbours (the linear interpolation it had). Returns
    ``(yaw, A, C, added)``, ``added`` the new yaw nodes (0: nothing bends)."""
    mark = bent_nodes(yaw, A, C, extra, tolerance)  # (ny - 1, nu, nw)
    ks = np.flatnonzero(mark.any(axis=(1, 2)))
    if not ks.size:
        return yaw, A, C, 0
    mid = 0.5 * (yaw[ks] + yaw[ks + 1])
    PA, PC = plan(mid, mark[ks])
    need = mark[ks][:, None]
    FA = np.where(need, PA, 0.5 * (A[ks] + A[ks + 1]))
    FC = np.where(need, PC, 0.5 * (C[ks] + C[ks + 1]))
    yaw, A, C = merge_nodes(yaw, mid, (A, C), (FA, FC), 0)
    return yaw, A, C, int(ks.size)
