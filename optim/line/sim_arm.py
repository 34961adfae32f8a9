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
from typing import Any

import numpy as np

from pinarms.optim.line.items import Items
from pinarms.optim.line.task_maps import TaskMap
from pinarms.errors import InvalidInput

__all__ = ["SimArm", "ArmState"]


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


class ArmState:
    """Per arm during a run: the grid of pre-grasp points (absolute u) and every item's times on it.

    Raises:
        InvalidInput: the arm's maps do not share one ``du`` grid, or hold no feasible pick.
    """

    def __init__(self, arm: SimArm, items: Items, speed: float) -> None:
        m0 = arm.maps[0]
        for m in arm.maps:
            if m.du.shape != m0.du.shape or np.any(m.du != m0.du):
                raise InvalidInput(f"arm {arm.name!r}: the maps of all item types must share one du grid")
        grid = m0.sim_grid(*arm.maps[1:])  # a node twice where the IK branch changes (no interpolation across)
        self.u = arm.u_base + grid[0]
        n = len(items)
        self.tA = np.empty((n, self.u.size))
        self.tC = np.empty((n, self.u.size))
        self.extra = np.empty(n)
        for k, m in enumerate(arm.maps):
            sel = items.kind == k
            self.tA[sel], self.tC[sel] = m.rows(items.w[sel], grid)
            self.extra[sel] = m.track + m.release
        ok = np.isfinite(self.tA) & np.isfinite(self.tC)
        self.tA[~ok] = np.nan
        cols = np.flatnonzero(ok.any(axis=0))
        if cols.size == 0:
            raise InvalidInput(f"arm {arm.name!r}: its maps hold no feasible pick")
        self.u_min, self.u_max = float(self.u[cols[0]]), float(self.u[cols[-1]])
        self.max_tA = float(np.nanmax(self.tA)) if np.isfinite(self.tA).any() else 0.0
        self.speed = speed
        self.rest = np.array(arm.rest)

    def intercept(self, t: float, idx: np.ndarray, t0: np.ndarray) -> tuple[np.ndarray, ...]:
        """(ok, start, meet, finish, u) of items ``idx`` for the arm ready at ``t``."""
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
        return ok, start, meet, finish, u
