"""A task map read at many items at once: :meth:`TaskMap.rows` by its cells across the belt.

:meth:`TaskMap.rows` gives, for items at ``w`` across, the approach and leave times at the
simulator's pre-grasp nodes: within one cell ``[w_j, w_j+1]`` of the map's grid, on the IK branch
that cell uses, ``T_j · (1 − f) + T_j+1 · f`` (``f`` the item's place in the cell; NaN where the
cell has no feasible branch or ``w`` is off the grid). :class:`CellRows` reads the two ends
``T_j``, ``T_j+1`` of every cell once, from the map itself (``TaskMap.rows`` of the map cut to that
one cell, at ``f = 0`` and ``f = 1``, where the sum is exact), and then evaluates every item with
the same products and sum: the same bits, many times faster on a long stream (compiled, item by
item: two rows of cell ends per item instead of a branch lookup per item and node).

Before it is used, its rows (numpy and compiled) are compared with :meth:`TaskMap.rows` at a spread
of the items and at the grid's nodes;
a map it cannot cut (another kind of map), a map with a yaw coordinate (its times depend on each
item's yaw, which the cells do not hold) or any difference sends every item through
:meth:`TaskMap.rows` instead.
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
    ``ends`` (4, nw − 1, K): approach at ``w_j``, at ``w_j+1``, leave at ``w_j``, at ``w_j+1``."""

    def __init__(self, task_map: TaskMap, grid: tuple) -> None:
        w = task_map.w
        K = grid[0].size
        self.w = w
        self.ends = np.empty((4, w.size - 1, K))
        for j in range(w.size - 1):
            cut = {"w": w[j:j + 2], "approach": task_map.approach[:, j:j + 2], "leave": task_map.leave[:, j:j + 2]}
            if task_map.branch_approach is not None:
                cut.update(branch_approach=task_map.branch_approach[:, :, j:j + 2],
                           branch_leave=task_map.branch_leave[:, :, j:j + 2])
            a, c = replace(task_map, **cut).rows(w[j:j + 2], grid)
            self.ends[:, j] = a[0], a[1], c[0], c[1]

    def rows(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(t_A, t_C)`` (len(w), K) as :meth:`TaskMap.rows` gives them (numpy; :meth:`fill` compiled)."""
        g = self.w
        j = np.clip(np.searchsorted(g, w, side="right") - 1, 0, g.size - 2)
        f = (w - g[j]) / (g[j + 1] - g[j])
        f = np.where((w < g[0]) | (w > g[-1]), np.nan, f)[:, None]
        e = self.ends
        return e[0, j] * (1 - f) + e[1, j] * f, e[2, j] * (1 - f) + e[3, j] * f

    def fill(self, w: np.ndarray, sel: np.ndarray, tA: np.ndarray, tC: np.ndarray) -> None:
        """Rows ``sel`` of ``tA``, ``tC`` for the items at ``w[sel]``: :meth:`rows` item by item, compiled
        (:func:`~._sim_kernel.cell_rows`: the same products and sum, no temporary arrays)."""
        from pinarms.optim.line._sim_kernel import cell_rows

        cell_rows(np.ascontiguousarray(w, dtype=float), np.ascontiguousarray(sel, dtype=np.int64),
                  np.ascontiguousarray(self.w, dtype=float), self.ends, tA, tC)


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
    if getattr(task_map, "yaw", None) is not None:  # times per item's yaw: the map itself, chunk by chunk
        for a in range(0, sel.size, ROWS_CHUNK):
            part = sel[a:a + ROWS_CHUNK]
            tA[part], tC[part] = task_map.rows(w[part], grid, None if yaw is None else yaw[part])
        return
    cells = _cells(task_map, grid)
    if cells is not None and sel.size:
        spread = sel[np.linspace(0, sel.size - 1, min(sel.size, CHECKED_ITEMS)).astype(int)]
        probe = np.unique(np.concatenate([w[spread], task_map.w]))
        ref = task_map.rows(probe, grid)
        compiled = [np.empty((probe.size, grid[0].size)) for _ in range(2)]
        cells.fill(probe, np.arange(probe.size), *compiled)
        if _same(cells.rows(probe), ref) and _same(compiled, ref):
            cells.fill(w, sel, tA, tC)
            return
    for a in range(0, sel.size, ROWS_CHUNK):
        part = sel[a:a + ROWS_CHUNK]
        tA[part], tC[part] = task_map.rows(w[part], grid)


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
