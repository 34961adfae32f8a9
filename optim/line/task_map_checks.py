"""What a task map may hold: the checks :class:`~.task_maps.TaskMap` runs when it is made (and so
when it is read from a file).

Grids ``du`` and ``w`` [m]: one-dimensional, at least 2 finite nodes, strictly increasing (a
one-node, zero-width, unsorted or NaN grid has no cells to interpolate in: a decreasing grid
once made the simulator pick nothing, silently). Times [s]: NaN where a pick is infeasible,
otherwise finite, ≥ 0 and at most :data:`MAX_TASK_TIME`. ``track`` and ``release`` [s] the same
(never NaN); ``speed`` [m/s] finite and > 0; ``mass`` [kg] finite and ≥ 0. Sizes: at most
:data:`MAX_GRID_NODES` nodes along each grid, at most :data:`MAX_MAP_VALUES` values in one
table (yaw nodes × branches × du × w), counted from the grids before any table is looked at.
The yaw grid [rad] (:func:`check_yaw`): a grid as above, at most :data:`MAX_YAW_NODES` nodes,
from exactly -period/2 to +period/2 with a node at 0 (the layer the 2-D tables hold).
Every fault is a :class:`~.errors.TaskMapError` naming the map, the field and the node.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms.optim.line.errors import TaskMapError

__all__ = ["check_grid", "check_times", "check_scalar", "check_sizes", "check_yaw", "MAX_TASK_TIME", "MAX_GRID_NODES",
           "MAX_MAP_VALUES", "MAX_BRANCHES", "MAX_YAW_NODES"]

#: Longest approach, leave, tracking or release time a map may hold [s] (a line's cycle is at most 600 s).
MAX_TASK_TIME = 600.0
#: Most nodes along ``du`` or ``w``.
MAX_GRID_NODES = 100_000
#: Most values in one table (IK branches × du nodes × w nodes): 8 MiB of float64.
MAX_MAP_VALUES = 2**20
#: Most IK branches a map tables.
MAX_BRANCHES = 64
#: Most nodes of a map's yaw grid.
MAX_YAW_NODES = 361


def check_grid(values: Any, name: str, station: str) -> np.ndarray:
    """The grid ``name`` [m] as float64 (else TaskMapError): 1-D, 2 to :data:`MAX_GRID_NODES` finite
    nodes, strictly increasing."""
    where = f"task map {station!r}: grid {name} [m]"
    try:
        g = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise TaskMapError(f"{where} must be numbers, got {type(values).__name__}") from None
    if g.ndim != 1 or g.size < 2:
        raise TaskMapError(f"{where} must have at least 2 nodes in one dimension, got shape {g.shape}")
    if g.size > MAX_GRID_NODES:
        raise TaskMapError(f"{where} has {g.size} nodes; a map has at most {MAX_GRID_NODES}")
    bad = np.flatnonzero(~np.isfinite(g))
    if bad.size:
        raise TaskMapError(f"{where} must be finite: node {int(bad[0])} is {g[bad[0]]}")
    step = np.flatnonzero(np.diff(g) <= 0.0)
    if step.size:
        k = int(step[0])
        raise TaskMapError(f"{where} must be strictly increasing: node {k + 1} ({g[k + 1]!r}) does not follow node "
                           f"{k} ({g[k]!r}); sort the grid and drop repeated nodes")
    return g


def check_yaw(values: Any, period: float, station: str) -> np.ndarray:
    """The yaw grid [rad] as float64 (else TaskMapError): a grid (:func:`check_grid`) of at most
    :data:`MAX_YAW_NODES` nodes from -``period``/2 to +``period``/2 (1e-9 rad) through 0."""
    g = check_grid(values, "yaw [rad]", station)
    if g.size > MAX_YAW_NODES:
        raise TaskMapError(f"task map {station!r}: grid yaw [rad] has {g.size} nodes; a map has at most {MAX_YAW_NODES}")
    if abs(g[0] + period / 2.0) > 1e-9 or abs(g[-1] - period / 2.0) > 1e-9 or not np.any(g == 0.0):
        raise TaskMapError(f"task map {station!r}: grid yaw [rad] must run from -{period / 2.0:.6g} to "
                           f"{period / 2.0:.6g} (half the yaw period) through 0, got {float(g[0])!r} .. {float(g[-1])!r}")
    return g


def check_sizes(n_branches: int, nu: int, nw: int, station: str, ny: int = 1) -> None:
    """TaskMapError when the tables would hold more than :data:`MAX_MAP_VALUES` values (``ny`` yaw
    layers of ``n_branches`` × ``nu`` × ``nw``) or more than :data:`MAX_BRANCHES` branches."""
    if not 1 <= n_branches <= MAX_BRANCHES:
        raise TaskMapError(f"task map {station!r}: {n_branches} IK branches; a map has 1 to {MAX_BRANCHES}")
    total = ny * n_branches * nu * nw
    if total > MAX_MAP_VALUES:
        layers = f"{ny} yaw nodes x " if ny > 1 else ""
        raise TaskMapError(f"task map {station!r}: {layers}{n_branches} branches x {nu} x {nw} nodes = {total} "
                           f"values; a table holds at most {MAX_MAP_VALUES}: a coarser grid")


def check_times(values: Any, name: str, station: str, shape: tuple[int, ...]) -> np.ndarray:
    """The table ``name`` [s] as float64 of ``shape`` (else TaskMapError): NaN (infeasible) or
    finite in [0, :data:`MAX_TASK_TIME`]."""
    try:
        t = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise TaskMapError(f"task map {station!r}: {name} times must be numbers") from None
    if t.shape != shape:
        raise TaskMapError(f"task map {station!r}: {name} times of shape {t.shape}, the grid needs {shape}")
    with np.errstate(invalid="ignore"):
        bad = ~np.isnan(t) & ~((t >= 0.0) & (t <= MAX_TASK_TIME))
    if bad.any():
        node = tuple(int(k) for k in np.argwhere(bad)[0])
        raise TaskMapError(f"task map {station!r}: {name} time at node {node} is {t[node]!r} s; times are NaN "
                           f"(infeasible) or in [0, {MAX_TASK_TIME:g}] s")
    return t


def check_scalar(value: Any, name: str, station: str, *, low: float = 0.0, high: float = np.inf,
                 open_low: bool = False) -> float:
    """``value`` as a float in [``low``, ``high``] (``(low, high]`` with ``open_low``), finite; else TaskMapError."""
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    x = float(value) if ok else float("nan")
    if not (np.isfinite(x) and (x > low if open_low else x >= low) and x <= high):
        span = f"{'(' if open_low else '['}{low:g}, {high:g}]"
        raise TaskMapError(f"task map {station!r}: {name} must be a finite number in {span}, got {value!r}")
    return x
