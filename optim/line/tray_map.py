"""The pick-to-tray task map: times of picks placed in trays on a second moving belt, interpolated.

A :class:`TrayMap` stores, on a grid of pre-grasp points relative to the arm (``du`` along the
item belt, ``w`` across it) and of pre-place points along the tray belt (``dv``, from the arm's
base projected on the tray belt), the exact times of :func:`~.trays.plan_pick_to_tray`: the
approach ``t_A(du, w)`` (the same as a box pick's), the transfer ``t_X(du, w, dv)`` (from the end
of the pick's tracking segment to the pre-place point, moving with the tray) and the return
``t_R(du, w, dv)`` (from the end of the place tracking to rest at home); NaN where infeasible.
The place coordinate ``dv`` is where the tray's place point is at the place rendezvous: with the
tray's phase it fixes which tray and when (:mod:`~.tray_sim`). Between nodes the times are
interpolated (bilinear for ``t_A``, trilinear for ``t_X``, ``t_R``); a point is feasible when all
the nodes of its cell are. One IK branch: the one :func:`~.trays.plan_pick_to_tray` takes
(the rest configuration's where it reaches) for the pick; the place tracking segment on each
IK branch (``branches``: the SCARA's elbows), kept apart like the box maps': at a point the map
takes the fastest branch whose eight cell nodes are feasible (:meth:`TrayMap.branch_at`), never a
mixture (the place's elbow change costs ~0.7 s on seed 000's SCARA beside its base). The pick's
elbow (``pick_branch``, per node) may change where the rest configuration's stops reaching: a cell
whose four pick nodes are not on one elbow is infeasible (the arm does not pick there).
The approach ``t_A`` is a box pick's approach (the item not yet held): with ``approach_map`` (the
same station's box :class:`~.task_maps.TaskMap`, refined where t_A bends) it is read there on the
pick's elbow, and the simulator's pick part (:attr:`TrayMap.pick_map`) lies on that finer grid.
Built by :func:`~.tray_maps.build_tray_map`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pinarms.optim.line.task_maps import YAW_TOLERANCE, TaskMap
from pinarms.errors import InvalidInput

__all__ = ["TrayMap"]


def _weights(grid: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    i = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, grid.size - 2)
    f = (x - grid[i]) / (grid[i + 1] - grid[i])
    return i, np.where((x < grid[0]) | (x > grid[-1]), np.nan, f)


@dataclass(frozen=True, eq=False)
class TrayMap:
    """Tray task times (module doc): ``du`` (nu,), ``w`` (nw,), ``dv`` (nv,) [m]; ``approach``
    (nu, nw), ``transfer`` and ``back`` (nb, nu, nw, nv) [s] on each place branch ``branches`` (nb,); ``track`` the pick's tracking and
    ``place`` the place's tracking (descend, release, lift) [s]; ``speed``, ``tray_speed`` [m/s]
    and ``mass`` [kg] it was built for."""

    station: str
    du: np.ndarray
    w: np.ndarray
    dv: np.ndarray
    approach: np.ndarray
    transfer: np.ndarray
    back: np.ndarray
    track: float
    place: float
    speed: float
    tray_speed: float
    mass: float
    build_seconds: float = 0.0
    branches: tuple[int, ...] = (-1,)
    pick_branch: np.ndarray | None = None  #: (nu, nw) the pick's IK branch label at each node (None: one)
    approach_map: Any = None  #: a finer source of t_A: the same station's box :class:`TaskMap` (module doc)
    fixture_infeasible: int = 0  #: nodes planned but closer than the clearance to the cell's fixtures
    yaw_spread: float = float("nan")  #: measured largest relative change of the time over the item's yaw (NaN: not)
    yaw_period: float = float(np.pi)  #: the gripper's symmetry about the vertical [rad]

    def __post_init__(self) -> None:
        shape = (len(self.branches), self.du.size, self.w.size, self.dv.size)
        if self.approach.shape != shape[1:3] or self.transfer.shape != shape or self.back.shape != shape:
            raise InvalidInput(f"tray map {self.station!r}: tables of shapes {self.approach.shape}, "
                               f"{self.transfer.shape}, {self.back.shape} for a {shape} grid")
        P = np.zeros(shape[1:3], int) if self.pick_branch is None else np.asarray(self.pick_branch, int)
        one = (P[:-1, :-1] == P[1:, :-1]) & (P[:-1, :-1] == P[:-1, 1:]) & (P[:-1, :-1] == P[1:, 1:])
        object.__setattr__(self, "_one_pick_branch", one)  # cells whose four pick nodes share an elbow

    def warnings(self, tolerance: float = YAW_TOLERANCE) -> tuple[str, ...]:
        """Why the map's times may be off, in words: its dependence on the item's yaw never measured,
        or above ``tolerance`` (a tray map holds its times at yaw 0: it has no yaw coordinate)."""
        if np.isnan(self.yaw_spread):
            return (f"tray map {self.station!r}: its dependence on the item's yaw was never measured: rebuild it "
                    "(build_tray_map, yaw='auto')",)
        if self.yaw_spread > tolerance:
            return (f"tray map {self.station!r}: the pick-to-tray time changes by {100 * self.yaw_spread:.1f} % over "
                    "the item's yaw; a tray map holds its times at yaw 0 (no yaw coordinate): items at other yaws "
                    "take that much longer or shorter",)
        return ()

    def times(self, du: Any, w: Any, dv: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Interpolated ``(t_A, t_X, t_R)`` [s] at ``du``, ``w``, ``dv`` (broadcast) on the branch
        :meth:`branch_at` names; NaN where infeasible."""
        tA, X, R = self._interp(du, w, dv)
        b = self._best(tA, X, R)
        bb = np.maximum(b, 0)[None]
        x, r = np.take_along_axis(X, bb, 0)[0], np.take_along_axis(R, bb, 0)[0]
        return tuple(np.where(b >= 0, v, np.nan) for v in (tA, x, r))

    def branch_at(self, du: float, w: float, dv: float) -> int | None:
        """The place's IK branch label the map uses at a point (None: one branch, or infeasible)."""
        b = int(self._best(*self._interp(du, w, dv)))
        return None if b < 0 or self.branches[b] < 0 else int(self.branches[b])

    @staticmethod
    def _best(tA: np.ndarray, X: np.ndarray, R: np.ndarray) -> np.ndarray:
        tot = tA[None] + X + R
        ok = np.isfinite(tot)
        return np.where(ok.any(axis=0), np.argmin(np.where(ok, tot, np.inf), axis=0), -1)

    def _interp(self, du: Any, w: Any, dv: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        du, w, dv = np.broadcast_arrays(*(np.asarray(x, float) for x in (du, w, dv)))
        (i, fu), (j, fw), (k, fv) = _weights(self.du, du), _weights(self.w, w), _weights(self.dv, dv)
        a = self.approach
        fu = np.where(self._one_pick_branch[i, j], fu, np.nan)  # never across the pick's elbow change
        tA = (a[i, j] * (1 - fu) + a[i + 1, j] * fu) * (1 - fw) + (a[i, j + 1] * (1 - fu) + a[i + 1, j + 1] * fu) * fw
        tA = self._fine_approach(tA, self._pick_label()[i, j], du, w)
        out = [tA]
        for T in (self.transfer, self.back):
            v = 0.0
            for di, wi in ((0, 1 - fu), (1, fu)):
                for dj, wj in ((0, 1 - fw), (1, fw)):
                    v = v + wi * wj * (T[:, i + di, j + dj, k] * (1 - fv) + T[:, i + di, j + dj, k + 1] * fv)
            out.append(v)
        return out[0], out[1], out[2]

    def _pick_label(self) -> np.ndarray:
        """(nu, nw) the pick's elbow label at each node (-1: one branch or none)."""
        return np.full(self.approach.shape, -1) if self.pick_branch is None else np.asarray(self.pick_branch, int)

    def _fine_approach(self, tA: np.ndarray, label: np.ndarray, du: np.ndarray, w: np.ndarray) -> np.ndarray:
        """``tA`` (this grid's) replaced by ``approach_map``'s on the same elbow where both are feasible."""
        if self.approach_map is None:
            return tA
        fine = self.approach_map.approach_on(label, du, w)
        return np.where(np.isfinite(tA) & np.isfinite(fine), fine, tA)

    def place_cells(self, du: float, w: float) -> tuple[np.ndarray, ...]:
        """The place times along ``dv`` for a pick at (``du``, ``w``), cell by cell on each place
        branch: ``(X0, X1, R0, R1)`` (nb, nv − 1), transfer and return at the start and the end of
        each ``dv`` cell, NaN where the cell is infeasible on that branch (one of its eight nodes,
        or the pick's cell). Within a cell and branch the times are linear in ``dv`` (what
        :meth:`times` gives there), so the simulator finds its crossings exactly, never across two
        cells (the branch, or the time, may change at a node)."""
        (i, fu), (j, fw) = _weights(self.du, np.asarray(du, float)), _weights(self.w, np.asarray(w, float))
        nc = self.dv.size - 1
        if not (np.isfinite(fu) and np.isfinite(fw) and self._one_pick_branch[i, j]):
            nan = np.full((len(self.branches), nc), np.nan)
            return nan, nan, nan, nan
        out = []
        for T in (self.transfer, self.back):
            v = ((T[:, i, j] * (1 - fu) + T[:, i + 1, j] * fu) * (1 - fw)
                 + (T[:, i, j + 1] * (1 - fu) + T[:, i + 1, j + 1] * fu) * fw)  # (nb, nv); NaN: a node infeasible
            bad = ~(np.isfinite(v[:, :-1]) & np.isfinite(v[:, 1:]))
            out += [np.where(bad, np.nan, v[:, :-1]), np.where(bad, np.nan, v[:, 1:])]
        return out[0], out[1], out[2], out[3]

    @property
    def pick_map(self) -> TaskMap:
        """The pick part as a :class:`TaskMap` (approach; leave 0 where some place is feasible, the
        place's times come from this map): what the simulator's item intercept uses. Its branches
        are the pick's elbows (``pick_branch``), so a cell whose four pick nodes are not on one
        elbow is infeasible there too, as in this map: the intercept never proposes a pick this map
        cannot place. With ``approach_map`` it lies on that map's (finer) grid: its nodes inside
        this map's feasible cells, each on the cell's elbow, with the finer approach times."""
        if self.approach_map is not None:
            return self._fine_pick_map()
        ok = np.isfinite(self.approach) & np.isfinite(self.transfer + self.back).any(axis=(0, 3))
        P = self._pick_label()
        labels = tuple(int(x) for x in np.unique(P[ok])) or (-1,)
        A = np.stack([np.where(ok & (P == b), self.approach, np.nan) for b in labels])
        return self._as_task_map(self.du, self.w, labels, A)

    def _fine_pick_map(self) -> TaskMap:
        """A node of the finer grid holds, on each elbow, the finer t_A when a feasible pick cell
        of this map on that elbow touches it (a node on a cell border touches both cells)."""
        fm = self.approach_map
        du, w = fm.du[(fm.du >= self.du[0]) & (fm.du <= self.du[-1])], fm.w[(fm.w >= self.w[0]) & (fm.w <= self.w[-1])]
        U, Wm = np.meshgrid(du, w, indexing="ij")
        X = self.transfer + self.back
        cube = np.isfinite(X[:, :-1, :-1] + X[:, 1:, :-1] + X[:, :-1, 1:] + X[:, 1:, 1:])  # (nb, nu-1, nw-1, nv)
        ok = self._one_pick_branch & (cube[..., :-1] & cube[..., 1:]).any(axis=(0, 3))  # pick cells that place
        label = np.where(ok, self._pick_label()[:-1, :-1], -2)
        touching = []  # the labels of the feasible cells touching each node
        for side_u in ("right", "left"):
            i = np.clip(np.searchsorted(self.du, U, side=side_u) - 1, 0, self.du.size - 2)
            for side_w in ("right", "left"):
                j = np.clip(np.searchsorted(self.w, Wm, side=side_w) - 1, 0, self.w.size - 2)
                touching.append(label[i, j])
        labels = tuple(int(x) for x in np.unique(label[label > -2])) or (-1,)
        A = np.stack([np.where(np.any([t == b for t in touching], axis=0), fm.approach_on(b, U, Wm), np.nan)
                      for b in labels])
        return self._as_task_map(du, w, labels, A)

    def _as_task_map(self, du: np.ndarray, w: np.ndarray, labels: tuple, A: np.ndarray) -> TaskMap:
        C = np.where(np.isfinite(A), 0.0, np.nan)
        best = np.min(np.where(np.isfinite(A), A, np.inf), axis=0)
        a = np.where(np.isfinite(best), best, np.nan)
        return TaskMap(self.station, du, w, a, np.where(np.isfinite(a), 0.0, np.nan), self.track, 0.0, self.speed,
                       self.mass, branches=labels, branch_approach=A, branch_leave=C, yaw_period=self.yaw_period,
                       yaw_spread=self.yaw_spread)


