"""Per-arm task-time maps: pick times over the belt, built once from exact planning, interpolated.

Planning a pick exactly (:func:`pinarms.optim.line.tracking.plan_pick`: IK of the tracking segment and
two time-optimal moves) takes about 0.2 s; a simulation asks for millions. A :class:`TaskMap`
stores, on a grid of pre-grasp points relative to the arm (``du`` along the belt from the
arm's base, ``w`` across), the approach time ``t_A`` (from rest at the box to the pre-grasp
point, moving with the belt) and the leave time ``t_C`` (from the end of the tracking
segment to rest at the box, carrying the item); NaN where the pick is infeasible. Between
grid points the times are interpolated bilinearly; a point is feasible when its four
surrounding grid points are. :func:`map_error` compares the interpolation with exact
planning at seeded random points.

The item's yaw: the hand turns to it (:func:`~.tracking.tool_yaw`, reduced by the gripper's
symmetry into [-period/2, period/2)). Where the arm's task time depends on it (a 6-axis arm whose
wrist is slow), the map has a third coordinate ``yaw`` (tool-yaw nodes spanning
[-period/2, period/2], one ``(nb, nu, nw)`` layer of times per node, linear between layers);
where it does not (measured when the map is built: ``yaw_spread``, the largest relative change
of the task time over yaw at probed nodes), the map has none and holds at every yaw.

A map holds for one arm model, limits, lateral offset and height of the base, box position
relative to the base, belt speed, tracking spec and item mass: moving the arm (and its box)
along the belt keeps it valid, which is what the sizing search uses.

Built by :func:`~.task_map_build.build_task_map` on the execution layer, checked against exact
planning by :func:`~.task_map_error.map_error`. Saved as ``.npz`` (no pickle; :mod:`~.task_map_file`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from pinarms.files import atomic_write
from pinarms.optim.line.errors import TaskMapError
from pinarms.optim.line.task_map_checks import (MAX_MAP_VALUES, MAX_TASK_TIME, check_grid, check_scalar, check_sizes,
                                                check_times, check_yaw)
from pinarms.optim.line.task_map_file import map_members, read_map_file

__all__ = ["TaskMap", "MAX_MAP_VALUES", "YAW_TOLERANCE"]

#: Largest relative change of the task time over the item's yaw a map without a yaw coordinate may
#: ignore (:attr:`TaskMap.yaw_spread`): above it the map says so (:meth:`TaskMap.warnings`).
YAW_TOLERANCE = 0.005


@dataclass(frozen=True, eq=False, repr=False)
class TaskMap:
    """Task times over the belt (module doc). ``du`` (nu,), ``w`` (nw,) [m]; ``approach``,
    ``leave`` (nu, nw) [s] (NaN: infeasible; the fastest branch at each node); ``track``,
    ``release`` [s]; ``speed`` [m/s] and ``mass`` [kg] it was built for; ``build_seconds``;
    ``branches`` (nb,) IK branch labels and ``branch_approach``, ``branch_leave`` (nb, nu, nw)
    the times on each branch (None: one branch, ``approach`` and ``leave``); ``fixture_infeasible``:
    grid nodes (over branches) planned but closer than the clearance to the cell's fixtures.

    Yaw (module doc): ``yaw`` (ny,) tool-yaw nodes [rad] from -``yaw_period``/2 to +``yaw_period``/2
    through 0, with ``yaw_approach``, ``yaw_leave`` (ny, nb, nu, nw) [s] (the tables above are the
    layer at yaw 0); None: no yaw coordinate. ``yaw_spread``: the measured largest relative change
    of the task time over yaw (NaN: not measured, a file written before pinarms measured it)."""

    station: str
    du: np.ndarray
    w: np.ndarray
    approach: np.ndarray
    leave: np.ndarray
    track: float
    release: float
    speed: float
    mass: float
    build_seconds: float = 0.0
    branches: tuple[int, ...] = (-1,)
    branch_approach: np.ndarray | None = field(default=None, repr=False)
    branch_leave: np.ndarray | None = field(default=None, repr=False)
    fixture_infeasible: int = 0
    yaw: np.ndarray | None = None
    yaw_approach: np.ndarray | None = field(default=None, repr=False)
    yaw_leave: np.ndarray | None = field(default=None, repr=False)
    yaw_period: float = float(np.pi)
    yaw_spread: float = float("nan")

    def __post_init__(self) -> None:
        """Every field checked (:mod:`~.task_map_checks`; TaskMapError naming the field and the node)."""
        name = self.station
        if not isinstance(name, str) or len(name) > 256:
            raise TaskMapError(f"a task map's station must be a name of at most 256 characters, got {name!r:.80}")
        du, w = check_grid(self.du, "du", name), check_grid(self.w, "w", name)
        try:
            branches = tuple(int(b) for b in self.branches)
        except (TypeError, ValueError):
            raise TaskMapError(f"task map {name!r}: branches must be integer labels, got {self.branches!r:.80}") from None
        if len(set(branches)) != len(branches):
            raise TaskMapError(f"task map {name!r}: branch labels {branches} repeat one")
        period = check_scalar(self.yaw_period, "yaw_period [rad]", name, high=2.0 * np.pi + 1e-12, open_low=True)
        yaw = None if self.yaw is None else check_yaw(self.yaw, period, name)
        ny = 1 if yaw is None else yaw.size
        check_sizes(len(branches), du.size, w.size, name, ny)  # from the grids, before any table is looked at
        grid = (du.size, w.size)
        spread = self.yaw_spread
        fields = {"du": du, "w": w, "branches": branches, "yaw": yaw, "yaw_period": period,
                  "yaw_spread": float("nan") if isinstance(spread, float) and np.isnan(spread) else
                  check_scalar(spread, "yaw_spread", name, high=MAX_TASK_TIME),
                  "approach": check_times(self.approach, "approach", name, grid),
                  "leave": check_times(self.leave, "leave", name, grid),
                  "track": check_scalar(self.track, "track time [s]", name, high=MAX_TASK_TIME),
                  "release": check_scalar(self.release, "release time [s]", name, high=MAX_TASK_TIME),
                  "speed": check_scalar(self.speed, "belt speed [m/s]", name, open_low=True),
                  "mass": check_scalar(self.mass, "item mass [kg]", name),
                  "build_seconds": check_scalar(self.build_seconds, "build_seconds [s]", name),
                  "fixture_infeasible": int(check_scalar(self.fixture_infeasible, "fixture_infeasible", name))}
        shape = (len(branches), *grid)
        for key in ("branch_approach", "branch_leave"):
            table = getattr(self, key)
            fields[key] = None if table is None else check_times(table, key, name, shape)
        for key in ("yaw_approach", "yaw_leave"):
            table = getattr(self, key)
            if (table is None) != (yaw is None):
                raise TaskMapError(f"task map {name!r}: {key} must be given exactly when the map has a yaw grid")
            fields[key] = None if table is None else check_times(table, key, name, (ny, *shape))
        for key, value in fields.items():
            object.__setattr__(self, key, value)
        A = self.approach[None] if self.branch_approach is None else self.branch_approach
        C = self.leave[None] if self.branch_leave is None else self.branch_leave
        if A.shape != shape or C.shape != shape:
            raise TaskMapError(f"task map {name!r}: branch tables of shape {A.shape}, {C.shape} for "
                               f"{len(branches)} branches on a {du.size} x {w.size} grid")
        if yaw is not None:
            zero = int(np.flatnonzero(yaw == 0.0)[0])
            if not (np.array_equal(self.yaw_approach[zero], A, equal_nan=True)
                    and np.array_equal(self.yaw_leave[zero], C, equal_nan=True)):
                raise TaskMapError(f"task map {name!r}: the yaw layer at yaw 0 differs from the branch tables "
                                   "(they are that layer): rebuild the map")
        LA = A[None] if yaw is None else self.yaw_approach
        LC = C[None] if yaw is None else self.yaw_leave
        object.__setattr__(self, "_A", A)
        object.__setattr__(self, "_C", C)
        object.__setattr__(self, "_cell", _cell_branches(A, C))
        object.__setattr__(self, "_LA", LA)  # (ny, nb, nu, nw): one layer per yaw node
        object.__setattr__(self, "_LC", LC)
        object.__setattr__(self, "_Lcell", np.stack([_cell_branches(a, c) for a, c in zip(LA, LC)]))
        object.__setattr__(self, "_zero", 0 if yaw is None else int(np.flatnonzero(yaw == 0.0)[0]))

    def __repr__(self) -> str:
        """One line: the grid, its ranges, the times' ranges and what the map was built for."""
        tot = self._LA + self._LC
        bad = int(np.sum(~np.isfinite(tot).any(axis=1)))
        yaw = "" if self.yaw is None else f" x {self.yaw.size} yaw"
        spread = "not measured" if np.isnan(self.yaw_spread) else f"{100 * self.yaw_spread:.2f} %"
        return (f"TaskMap({self.station!r}, {self.du.size} x {self.w.size}{yaw} nodes, du {_span(self.du)} m, "
                f"w {_span(self.w)} m, approach {_span(self.approach)} s, leave {_span(self.leave)} s, "
                f"{len(self.branches)} branch{'es' if len(self.branches) != 1 else ''}, {bad} infeasible, "
                f"yaw spread {spread}, speed {self.speed:.3g} m/s, mass {self.mass:.3g} kg)")

    def warnings(self, tolerance: float = YAW_TOLERANCE) -> tuple[str, ...]:
        """What makes the map's times doubtful, in words (empty: nothing): a yaw dependence never
        measured, or ignored although the task time changes by more than ``tolerance`` over yaw."""
        if self.yaw is not None:
            return ()
        if np.isnan(self.yaw_spread):
            return (f"task map {self.station!r}: its dependence on the item's yaw was never measured (a map file "
                    "written before pinarms measured it): measure it (measure_yaw) or rebuild the map (build_task_map)",)
        if self.yaw_spread > tolerance:
            return (f"task map {self.station!r}: the task time changes by {100 * self.yaw_spread:.1f} % over the item's "
                    "yaw but the map has no yaw coordinate: rebuild it with yaw='auto'",)
        return ()

    def _weights(self, grid: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        i = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, grid.size - 2)
        f = (x - grid[i]) / (grid[i + 1] - grid[i])
        f = np.where((x < grid[0]) | (x > grid[-1]), np.nan, f)
        return i, f

    def yaw_weights(self, yaw: Any, shape: tuple) -> tuple[np.ndarray, np.ndarray]:
        """Layer index k and weight f in [0, 1) of layer k + 1 at item yaws ``yaw`` [rad] (broadcast
        to ``shape``): the yaw reduced by the gripper's symmetry (:func:`~.tracking.tool_yaw`); the
        layer at yaw 0 for a map without yaw or ``yaw`` None."""
        if self.yaw is None or yaw is None:
            return np.full(shape, self._zero), np.zeros(shape)
        p = self.yaw_period
        t = np.broadcast_to((np.asarray(yaw, float) + p / 2.0) % p - p / 2.0, shape)
        k = np.clip(np.searchsorted(self.yaw, t, side="right") - 1, 0, self.yaw.size - 2)
        return k, (t - self.yaw[k]) / (self.yaw[k + 1] - self.yaw[k])

    def _on_layers(self, k: np.ndarray, fy: np.ndarray, one: Any) -> Any:
        """``one(layer index)`` blended linearly between layers k and k + 1 by ``fy`` (each value a
        tuple of arrays; NaN where the other layer is needed and infeasible)."""
        lo = one(k)
        if self.yaw is None or not np.any(fy > 0.0):
            return lo
        hi = one(np.minimum(k + 1, self.yaw.size - 1))
        return tuple(np.where(fy > 0.0, (1.0 - fy) * a + fy * b, a) for a, b in zip(lo, hi))

    def _cell_branch(self, i: np.ndarray, j: np.ndarray, f: np.ndarray, k: Any = None) -> np.ndarray:
        """Table index of the branch of grid cells (i, j) on yaw layer k (None: yaw 0) (-1: no branch
        feasible at its four nodes or ``f`` NaN)."""
        cell = self._cell[i, j] if k is None else self._Lcell[k, i, j]
        return np.where(np.isnan(f), -1, cell)

    def times(self, du: Any, w: Any, yaw: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """Interpolated ``(t_A, t_C)`` [s] at points ``du``, ``w`` [m] and item yaw ``yaw`` [rad]
        (broadcast; None: yaw 0); NaN where infeasible.

        Bilinear within one IK branch: each grid cell uses the fastest branch feasible at its
        four nodes (:meth:`branch_at`), never a mixture of branches; linear between yaw layers."""
        du, w = np.broadcast_arrays(np.asarray(du, float), np.asarray(w, float))
        if yaw is not None:
            du, w, _ = np.broadcast_arrays(du, w, np.asarray(yaw, float))
        i, fu = self._weights(self.du, du)
        j, fw = self._weights(self.w, w)
        k, fy = self.yaw_weights(yaw, du.shape)

        def one(kk: np.ndarray) -> tuple:
            b = self._cell_branch(i, j, fu + fw, kk)
            bb = np.maximum(b, 0)
            out = []
            for table in (self._LA, self._LC):
                a, c = table[kk, bb, i, j], table[kk, bb, i + 1, j]
                d, e = table[kk, bb, i, j + 1], table[kk, bb, i + 1, j + 1]
                v = (a * (1 - fu) + c * fu) * (1 - fw) + (d * (1 - fu) + e * fu) * fw
                out.append(np.where(b >= 0, v, np.nan))
            return tuple(out)

        tA, tC = self._on_layers(k, fy, one)
        return tA, tC

    def approach_on(self, label: Any, du: Any, w: Any) -> np.ndarray:
        """The approach time t_A [s] at ``du``, ``w`` on IK branch ``label`` (broadcast; -1: the
        map's one branch), bilinear on that branch's table at yaw 0; NaN where a node of the cell is
        infeasible on it or the label is not one of the map's."""
        label, du, w = np.broadcast_arrays(np.asarray(label, int), np.asarray(du, float), np.asarray(w, float))
        i, fu = self._weights(self.du, du)
        j, fw = self._weights(self.w, w)
        out = np.full(du.shape, np.nan)
        for b, name in enumerate(self.branches):
            sel = label == name
            if not sel.any():
                continue
            T, ii, jj, a, c = self._A[b], i[sel], j[sel], fu[sel], fw[sel]
            out[sel] = (T[ii, jj] * (1 - a) + T[ii + 1, jj] * a) * (1 - c) + (T[ii, jj + 1] * (1 - a)
                                                                            + T[ii + 1, jj + 1] * a) * c
        return out

    def branch_at(self, du: float, w: float, yaw: float | None = None) -> int | None:
        """The IK branch label the map uses at (``du``, ``w``) [m] and item yaw ``yaw`` [rad] (the
        nearer yaw layer; None: yaw 0) (None: the arm has one branch or the point is infeasible);
        :func:`~.tracking.plan_pick` ``branch=`` plans it exactly."""
        i, fu = self._weights(self.du, np.asarray(du, float))
        j, fw = self._weights(self.w, np.asarray(w, float))
        k, fy = self.yaw_weights(yaw, np.shape(i))
        b = int(self._cell_branch(i, j, fu + fw, np.where(fy > 0.5, k + 1, k)))
        return None if b < 0 or self.branches[b] < 0 else int(self.branches[b])

    def sim_grid(self, *others: "TaskMap") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The simulator's du nodes: ``(du, node, cell)`` (K,): the grid's nodes in order, a node
        listed twice (end of the cell before, start of the cell after) where the cells on its
        two sides use different branches for some w and yaw layer (in this map or ``others``, same
        du grid), so that piecewise-linear interpolation along du stays within one branch (the time
        may jump there)."""
        nodes, cells = [0], [0]
        for n in range(1, self.du.size - 1):
            if any(np.any(m._Lcell[:, n - 1] != m._Lcell[:, n]) for m in (self, *others)):
                nodes.append(n)
                cells.append(n - 1)
            nodes.append(n)
            cells.append(n)
        nodes.append(self.du.size - 1)
        cells.append(self.du.size - 2)
        node, cell = np.array(nodes), np.array(cells)
        return self.du[node], node, cell

    def rows(self, w: Any, grid: tuple | None = None, yaw: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """``(t_A, t_C)`` of shape (len(w), K) at the du nodes of :meth:`sim_grid` (or ``grid``,
        one of its results) for items at ``w`` [m] across and yaw ``yaw`` [rad] (len(w),) (None: 0)."""
        _, node, cell = self.sim_grid() if grid is None else grid
        w = np.asarray(w, float)
        j, fw = self._weights(self.w, w)
        k, fy = self.yaw_weights(None if yaw is None else np.asarray(yaw, float), w.shape)
        k, fy = k[:, None] + np.zeros(cell.size, int), fy[:, None] + np.zeros(cell.size)

        def one(kk: np.ndarray) -> tuple:
            b = self._cell_branch(cell[None, :], j[:, None], fw[:, None] + np.zeros(cell.size), kk)
            bb = np.maximum(b, 0)
            out = []
            for table in (self._LA, self._LC):
                n_, j_, f_ = node[None, :], j[:, None], fw[:, None]
                v = table[kk, bb, n_, j_] * (1 - f_) + table[kk, bb, n_, j_ + 1] * f_
                out.append(np.where(b >= 0, v, np.nan))
            return tuple(out)

        tA, tC = self._on_layers(k, fy, one)
        return tA, tC

    @property
    def checksum(self) -> str:
        """SHA-256 of every value of the map (:func:`~.task_map_file.map_checksum`), stored in its file."""
        return str(map_members(self)["checksum"])

    def save(self, path: str | Path) -> Path:
        """Write the map as ``.npz`` with its checksum, atomically (:func:`pinarms.files.atomic_write`)."""
        members = map_members(self)
        return atomic_write(path, lambda fh: np.savez(fh, **members))

    @classmethod
    def load(cls, path: str | Path) -> "TaskMap":
        """Read a map written by :meth:`save` (no pickle; sizes bounded before inflating, every value
        checked, the checksum compared: :mod:`~.task_map_file`).

        Raises:
            TaskMapError: not a regular file, too large, not a task map file, a value out of range,
                a checksum that does not match (the file was changed or damaged). A file written
                before maps had a yaw coordinate is read as a map without one whose yaw dependence
                was never measured (:meth:`warnings` says so).
        """
        z = read_map_file(path)
        s = z["scalars"]
        if s.shape != (5,):
            raise TaskMapError(f"{str(path)!r} is not a task map file: scalars of shape {s.shape}, not (5,)")
        extra: dict[str, Any] = {}
        if "branches" in z:
            extra = {"branches": tuple(int(b) for b in z["branches"].ravel()),
                     "branch_approach": z.get("branch_approach"), "branch_leave": z.get("branch_leave")}
        if "fixture_infeasible" in z:
            extra["fixture_infeasible"] = int(z["fixture_infeasible"].ravel()[0]) if z["fixture_infeasible"].size else -1
        extra.update(_yaw_members(z, path))
        m = cls(str(z["station"]), z["du"], z["w"], z["approach"], z["leave"], *map(float, s), **extra)
        if "checksum" not in z:
            raise TaskMapError(f"task map file {str(path)!r} has no checksum (written before pinarms checked its "
                               "values, or not by TaskMap.save): rebuild it, or load it once with numpy and save it")
        if str(z["checksum"]) != m.checksum:
            raise TaskMapError(f"task map file {str(path)!r}: its values do not match its checksum (the file was "
                               "changed or damaged): rebuild the map")
        return m


def _cell_branches(A: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Per grid cell (nu-1, nw-1): the index of the branch feasible at the cell's four nodes with
    the least total time over them (-1: none)."""
    tot = A + C
    four = tot[:, :-1, :-1] + tot[:, 1:, :-1] + tot[:, :-1, 1:] + tot[:, 1:, 1:]  # NaN where any node is infeasible
    best = np.argmin(np.where(np.isfinite(four), four, np.inf), axis=0)
    return np.where(np.isfinite(four).any(axis=0), best, -1)




def _yaw_members(z: dict, path: Any) -> dict[str, Any]:
    """The yaw fields of a map file's members (none in a file written before maps measured yaw)."""
    if "yaw_scalars" not in z:
        if any(k in z for k in ("yaw", "yaw_approach", "yaw_leave")):
            raise TaskMapError(f"{str(path)!r} is not a task map file: yaw tables without yaw_scalars.npy; "
                               "rebuild the map")
        return {}
    ys = z["yaw_scalars"]
    if ys.shape != (2,):
        raise TaskMapError(f"{str(path)!r} is not a task map file: yaw_scalars of shape {ys.shape}, not (2,)")
    out: dict[str, Any] = {"yaw_period": float(ys[0]), "yaw_spread": float(ys[1])}
    if "yaw" in z:
        out.update(yaw=z["yaw"], yaw_approach=z.get("yaw_approach"), yaw_leave=z.get("yaw_leave"))
    elif "yaw_approach" in z or "yaw_leave" in z:
        raise TaskMapError(f"{str(path)!r} is not a task map file: yaw tables without a yaw grid; rebuild the map")
    return out


def _span(values: np.ndarray) -> str:
    """``lo..hi`` of the finite values at 3 significant digits (``none`` when none is finite)."""
    finite = np.asarray(values)[np.isfinite(values)]
    return f"{finite.min():.3g}..{finite.max():.3g}" if finite.size else "none"
