"""A task map read at many items at once: :meth:`TaskMap.rows` by its cells across the belt.

:meth:`TaskMap.rows` gives, for items at ``w`` across, the approach and leave times at the
simulator's pre-grasp nodes: within one cell ``[w_j, w_j+1]`` of the map's grid, on the IK branch
that cell uses, ``T_j · (1 − f) + T_j+1 · f`` (``f`` the item's place in the cell; NaN where the
cell has no feasible branch or ``w`` is off the grid). :class:`CellRows` reads the two ends
``T_j``, ``T_j+1`` of every cell once, from the map itself (``TaskMap.rows`` of the map cut to that
one cell, at ``f = 0`` and ``f = 1``, where the sum is exact), and then evaluates every item with
the same products and sum: the same bits, many times faster on a long stream (compiled, item by
item: two rows of cell ends per item instead of a branch lookup per item and node).

A map with a yaw coordinate holds one such table per yaw layer (``ends`` (ny, 4, nw − 1, K), each
layer read like a map without yaw: the map cut to that layer); an item between two layers blends
them as :meth:`TaskMap.rows` does (``(1 − f_y) · lower + f_y · upper`` where its yaw is not on a node).

Before it is used, its rows (numpy and compiled) are compared with :meth:`TaskMap.rows` at a spread
of the items (at their yaws) and at the grid's nodes; a map it cannot cut (another kind of map) or
any difference sends every item through :meth:`TaskMap.rows` instead.
"""

from __future__ import annotations

import weakref
from dataclasses import replace
from typing import Any, TYPE_CHECKING

import numpy as np

from pinarms.errors import PinarmsError

if TYPE_CHECKING:
    from pinarms.optim.line.task_maps import TaskMap

__all__ = ["CellRows", "map_rows", "CHECKED_ITEMS", "ROWS_CHUNK"]

#: Items whose rows are compared with :meth:`TaskMap.rows` before the cells are used.
CHECKED_ITEMS = 256
#: Items whose rows one call of :meth:`TaskMap.rows` computes (bounds its temporary arrays).
ROWS_CHUNK = 65536


class CellRows:
    """Per cell across the belt, the times at its two ends on the cell's branch (module doc):
    ``ends`` (ny, 4, nw − 1, K): approach at ``w_j``, at ``w_j+1``, leave at ``w_j``, at ``w_j+1``,
    per yaw layer (ny = 1 without a yaw coordinate)."""

    def __init__(self, task_map: TaskMap, grid: tuple) -> None:
        w = task_map.w
        K = grid[0].size
        self.w = w
        self.task_map = task_map
        layers = [task_map] if task_map.yaw is None else [_layer(task_map, k) for k in range(task_map.yaw.size)]
        self.ends = np.empty((len(layers), 4, w.size - 1, K))
        for y, layer in enumerate(layers):
            for j in range(w.size - 1):
                cut = {"w": w[j:j + 2], "approach": layer.approach[:, j:j + 2], "leave": layer.leave[:, j:j + 2]}
                if layer.branch_approach is not None:
                    cut.update(branch_approach=layer.branch_approach[:, :, j:j + 2],
                               branch_leave=layer.branch_leave[:, :, j:j + 2])
                a, c = replace(layer, **cut).rows(w[j:j + 2], grid)
                self.ends[y, :, j] = a[0], a[1], c[0], c[1]

    def rows(self, w: np.ndarray, yaw: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(t_A, t_C)`` (len(w), K) as :meth:`TaskMap.rows` gives them for items at ``w`` and ``yaw``
        (None: 0) (numpy; :meth:`fill` compiled)."""
        g = self.w
        j = np.clip(np.searchsorted(g, w, side="right") - 1, 0, g.size - 2)
        f = (w - g[j]) / (g[j + 1] - g[j])
        f = np.where((w < g[0]) | (w > g[-1]), np.nan, f)[:, None]
        k, fy = self.task_map.yaw_weights(yaw, np.shape(w))

        def layer(kk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            e = self.ends[kk, :, j]  # (n, 4, K)
            return e[:, 0] * (1 - f) + e[:, 1] * f, e[:, 2] * (1 - f) + e[:, 3] * f

        lo = layer(k)
        if self.ends.shape[0] == 1 or not np.any(fy > 0.0):
            return lo
        hi = layer(np.minimum(k + 1, self.ends.shape[0] - 1))
        fy = fy[:, None] + np.zeros(self.ends.shape[-1])
        return tuple(np.where(fy > 0.0, (1.0 - fy) * a + fy * b, a) for a, b in zip(lo, hi))

    def fill(self, w: np.ndarray, sel: np.ndarray, tA: np.ndarray, tC: np.ndarray, yaw: np.ndarray | None = None
             ) -> None:
        """Rows ``sel`` of ``tA``, ``tC`` for the items at ``w[sel]`` (and ``yaw[sel]``): :meth:`rows` item
        by item, compiled (:func:`~._sim_kernel.cell_rows`: the same products and sum, no temporary arrays)."""
        from pinarms.optim.line._sim_kernel import cell_rows

        k, fy = self.task_map.yaw_weights(None if yaw is None else np.asarray(yaw, float)[sel], sel.shape)
        layer = np.zeros(np.size(w), np.int64)
        weight = np.zeros(np.size(w))
        layer[sel], weight[sel] = k, fy
        cell_rows(np.ascontiguousarray(w, dtype=float), np.ascontiguousarray(sel, dtype=np.int64),
                  np.ascontiguousarray(self.w, dtype=float), self.ends, layer, weight, tA, tC)


def _layer(task_map: TaskMap, k: int) -> TaskMap:
    """Yaw layer ``k`` of ``task_map`` as a map without yaw (its rows are the layer's rows)."""
    A, C = task_map.yaw_approach[k], task_map.yaw_leave[k]
    tot = np.where(np.isfinite(A + C), A + C, np.inf)
    best = np.argmin(tot, axis=0)[None]
    return replace(task_map, approach=np.take_along_axis(A, best, 0)[0], leave=np.take_along_axis(C, best, 0)[0],
                   branch_approach=A, branch_leave=C, yaw=None, yaw_approach=None, yaw_leave=None)


#: {task map: {grid key: CellRows or None (its cells do not reproduce its rows)}}, dropped with the map
_CELLS: "weakref.WeakKeyDictionary[Any, dict]" = weakref.WeakKeyDictionary()


def _same(a: tuple, b: tuple) -> bool:
    return all(np.array_equal(x, y, equal_nan=True) for x, y in zip(a, b))


def map_rows(task_map: TaskMap, grid: tuple, w: np.ndarray, sel: np.ndarray, tA: np.ndarray, tC: np.ndarray,
             yaw: np.ndarray | None = None) -> None:
    """Rows ``sel`` of ``tA``, ``tC`` (n, K): ``task_map.rows(w[sel], grid, yaw[sel])`` (module doc). The
    cells of a map are read once per grid and kept while the map lives; every call compares them, in
    numpy and compiled, with the map at a spread of its items. ``yaw`` (n,) [rad]: each item's yaw,
    read only by a map with a yaw coordinate (None: 0)."""
    yawed = getattr(task_map, "yaw", None) is not None
    yaw = None if not yawed or yaw is None else np.asarray(yaw, float)

    def exact(part: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return task_map.rows(w[part], grid, None if yaw is None else yaw[part]) if yawed else task_map.rows(w[part],
                                                                                                              grid)

    cells = _cells(task_map, grid)
    if cells is not None and sel.size:
        spread = sel[np.linspace(0, sel.size - 1, min(sel.size, CHECKED_ITEMS)).astype(int)]
        if yaw is None:
            probe_w, probe_yaw = np.unique(np.concatenate([w[spread], task_map.w])), None
        else:  # the items at their yaws, and the grid's nodes across at yaw 0
            probe_w = np.concatenate([w[spread], task_map.w])
            probe_yaw = np.concatenate([yaw[spread], np.zeros(task_map.w.size)])
        ref = task_map.rows(probe_w, grid, probe_yaw) if yawed else task_map.rows(probe_w, grid)
        compiled = [np.empty((probe_w.size, grid[0].size)) for _ in range(2)]
        cells.fill(probe_w, np.arange(probe_w.size), *compiled, yaw=probe_yaw)
        if _same(cells.rows(probe_w, probe_yaw), ref) and _same(compiled, ref):
            cells.fill(w, sel, tA, tC, yaw=yaw)
            return
    for a in range(0, sel.size, ROWS_CHUNK):
        part = sel[a:a + ROWS_CHUNK]
        tA[part], tC[part] = exact(part)


def _cells(task_map: Any, grid: tuple) -> CellRows | None:
    """The map's :class:`CellRows` on ``grid`` (None: a map it cannot cut), read once per map and grid."""
    key = tuple(np.asarray(g).tobytes() for g in grid)
    try:
        known = _CELLS.setdefault(task_map, {})
    except TypeError:  # a map that cannot be weakly referenced: read each time
        known = {}
    if key not in known:
        try:
            known[key] = CellRows(task_map, grid)
        except (PinarmsError, TypeError, ValueError):
            known[key] = None
    return known[key]
