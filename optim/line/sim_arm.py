"""An arm as the line simulation sees it: its description and its pick times along the belt.

:class:`SimArm` is what :func:`pinarms.optim.line.simulate.simulate` is given for each arm (its base
on the belt, one task map per item type, its rest point, its tray place). :class:`ArmState`
is that arm during a run: its task maps read on one grid of pre-grasp points for every item
of the stream, and :meth:`ArmState.intercept`, the earliest reachable intercept of items by
the arm ready at a time ``t`` (the first grid point where the arm, leaving now, is there no
later than the item, refined linearly between grid points). Belt coordinates in m, times in s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple, Sequence

import numpy as np

from pinarms.optim.line.items import Items
from pinarms.optim.line.map_rows import map_rows
from pinarms.optim.line.task_maps import TaskMap
from pinarms.errors import InvalidInput

__all__ = ["SimArm", "ArmState", "ItemRows", "Intercepts", "item_rows", "arm_states", "sim_grid"]


@dataclass(frozen=True, eq=False)
class SimArm:
    """One arm as the simulator sees it: ``name``, ``u_base`` (its base projected on the belt,
    m), ``maps`` (one :class:`TaskMap` per item type, in the stream's type order) and
    ``rest`` (the tool at rest at its box, belt coordinates u, w [m], for the "nearest" rule)."""

    name: str
    u_base: float
    maps: tuple[TaskMap, ...]
    rest: tuple[float, float] = (0.0, 0.0)
    place: Any = None  #: :class:`~.tray_sim.SimPlace` when the arm places in trays (None: its box)


class ItemRows(NamedTuple):
    """Every item's times at an arm's pre-grasp nodes, shared by the arms with the same maps:
    ``du`` (K,) the nodes from the arm's base [m] (:func:`sim_grid`), ``tA``, ``tC`` (n, K) approach
    and leave [s] (NaN where the pick is infeasible), ``extra`` (n,) track + release [s],
    ``feasible`` (K,) nodes feasible for some item, ``max_tA`` [s]."""

    du: np.ndarray
    tA: np.ndarray
    tC: np.ndarray
    extra: np.ndarray
    feasible: np.ndarray
    max_tA: float


class Intercepts(NamedTuple):
    """The earliest reachable intercepts of some items (arrays of their shape): ``ok`` (one exists),
    ``start`` (the arm leaves its box) [s], ``meet`` (rendezvous) [s], ``finish`` (back at rest) [s],
    ``u`` the pre-grasp point along the belt [m]."""

    ok: np.ndarray
    start: np.ndarray
    meet: np.ndarray
    finish: np.ndarray
    u: np.ndarray


def sim_grid(arm: SimArm) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The arm's pre-grasp nodes (:meth:`TaskMap.sim_grid` over its maps).

    Raises:
        InvalidInput: the arm's maps do not share one ``du`` grid.
    """
    m0 = arm.maps[0]
    for m in arm.maps:
        if m.du.shape != m0.du.shape or np.any(m.du != m0.du):
            raise InvalidInput(f"arm {arm.name!r}: the maps of all item types must share one du grid")
    return m0.sim_grid(*arm.maps[1:])  # a node twice where the IK branch changes (no interpolation across)


def item_rows(arm: SimArm, items: Items) -> ItemRows:
    """Every item's times at the arm's nodes (:class:`ItemRows`).

    Raises:
        InvalidInput: the maps do not share one ``du`` grid, or hold no feasible pick.
    """
    grid = sim_grid(arm)
    n, K = len(items), grid[0].size
    tA, tC, extra = np.empty((n, K)), np.empty((n, K)), np.empty(n)
    for k, m in enumerate(arm.maps):
        sel = np.flatnonzero(items.kind == k)
        map_rows(m, grid, items.w, sel, tA, tC, yaw=items.yaw)  # per item: its yaw
        extra[sel] = m.track + m.release
    ok = np.isfinite(tA) & np.isfinite(tC)
    tA[~ok] = np.nan
    feasible = ok.any(axis=0)
    if not feasible.any():
        raise InvalidInput(f"arm {arm.name!r}: its maps hold no feasible pick")
    max_tA = float(np.nanmax(tA)) if np.isfinite(tA).any() else 0.0
    return ItemRows(grid[0], tA, tC, extra, feasible, max_tA)


class ArmState:
    """Per arm during a run: the grid of pre-grasp points (absolute u) and every item's times on it
    (``rows``: :func:`item_rows`, given when another arm with the same maps has them already).

    Raises:
        InvalidInput: the arm's maps do not share one ``du`` grid, or hold no feasible pick.
    """

    def __init__(self, arm: SimArm, items: Items, speed: float, rows: ItemRows | None = None) -> None:
        rows = item_rows(arm, items) if rows is None else rows
        self.rows = rows
        self.u = arm.u_base + rows.du
        self.tA, self.tC, self.extra = rows.tA, rows.tC, rows.extra
        cols = np.flatnonzero(rows.feasible)
        self.u_min, self.u_max = float(self.u[cols[0]]), float(self.u[cols[-1]])
        self.max_tA = rows.max_tA
        self.speed = speed
        self.rest = np.array(arm.rest)

    def intercept(self, t: float, idx: np.ndarray, t0: np.ndarray) -> Intercepts:
        """The intercepts of items ``idx`` for the arm ready at ``t``."""
        tA, tC = self.tA[idx], self.tC[idx]
        t_item = t0[idx, None] + self.u[None, :] / self.speed
        g = t + tA - t_item
        good = np.isfinite(tA) & (g <= 0.0)
        ok = good.any(axis=1)
        k = np.argmax(good, axis=1)
        rows = np.arange(idx.size)
        km = np.maximum(k - 1, 0)
        prev_ok = (k > 0) & np.isfinite(tA[rows, km]) & (g[rows, km] > 0.0) & (self.u[k] > self.u[km])
        gp, gk = np.where(prev_ok, g[rows, km], 0.0), g[rows, k]
        with np.errstate(invalid="ignore", divide="ignore"):
            f = np.where(prev_ok, gp / (gp - gk), 1.0)
        u = np.where(prev_ok, self.u[km] + f * (self.u[k] - self.u[km]), self.u[k])
        a = np.where(prev_ok, tA[rows, km] + f * (tA[rows, k] - tA[rows, km]), tA[rows, k])
        c = np.where(prev_ok, tC[rows, km] + f * (tC[rows, k] - tC[rows, km]), tC[rows, k])
        meet = t0[idx] + u / self.speed
        start = np.maximum(meet - a, t)
        finish = meet + self.extra[idx] + c
        return Intercepts(ok, start, meet, finish, u)


def arm_states(arms: Sequence[SimArm], items: Items, speed: float) -> list[ArmState]:
    """Each arm's :class:`ArmState`; arms with the same maps (the same objects: stations that differ only
    by their place along the belt) share one :class:`ItemRows`."""
    shared: dict = {}
    out = []
    for arm in arms:
        key = tuple(id(m) for m in arm.maps)
        if key not in shared:
            shared[key] = item_rows(arm, items)
        out.append(ArmState(arm, items, speed, shared[key]))
    return out
