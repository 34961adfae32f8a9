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

A map holds for one arm model, limits, lateral offset and height of the base, box position
relative to the base, belt speed, tracking spec and item mass: moving the arm (and its box)
along the belt keeps it valid, which is what the sizing search uses.

Built on the execution layer (:func:`pinarms.execution.map_chunks`: serial by default, or a
Dask cluster), one task per ``du`` column, same result either way. Saved as ``.npz`` (no pickle).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from pinarms.files import atomic_write
from pinarms.optim.errors import InfeasibleProblem, OptimError
from pinarms.optim.line.errors import TaskMapError
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.station import Station
from pinarms.optim.line.task_map_checks import MAX_MAP_VALUES, MAX_TASK_TIME, check_grid, check_scalar, check_sizes, check_times
from pinarms.optim.line.task_map_file import map_members, read_map_file
from pinarms.optim.line.tracking import TrackingSpec, ik_branch_labels, plan_pick, rest_configuration
from pinarms.optim.line.windows import belt_span, check_reach
from pinarms.errors import InvalidInput, PinarmsError, UnreachableTarget

__all__ = ["TaskMap", "build_task_map", "map_error", "MapError", "MAX_MAP_VALUES"]


@dataclass(frozen=True, eq=False, repr=False)
class TaskMap:
    """Task times over the belt (module doc). ``du`` (nu,), ``w`` (nw,) [m]; ``approach``,
    ``leave`` (nu, nw) [s] (NaN: infeasible; the fastest branch at each node); ``track``,
    ``release`` [s]; ``speed`` [m/s] and ``mass`` [kg] it was built for; ``build_seconds``;
    ``branches`` (nb,) IK branch labels and ``branch_approach``, ``branch_leave`` (nb, nu, nw)
    the times on each branch (None: one branch, ``approach`` and ``leave``); ``fixture_infeasible``:
    grid nodes (over branches) planned but closer than the clearance to the cell's fixtures."""

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
        check_sizes(len(branches), du.size, w.size, name)  # from the grids, before any table is looked at
        grid = (du.size, w.size)
        fields = {"du": du, "w": w, "branches": branches,
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
        for key, value in fields.items():
            object.__setattr__(self, key, value)
        A = self.approach[None] if self.branch_approach is None else self.branch_approach
        C = self.leave[None] if self.branch_leave is None else self.branch_leave
        if A.shape != shape or C.shape != shape:
            raise TaskMapError(f"task map {name!r}: branch tables of shape {A.shape}, {C.shape} for "
                               f"{len(branches)} branches on a {du.size} x {w.size} grid")
        object.__setattr__(self, "_A", A)
        object.__setattr__(self, "_C", C)
        object.__setattr__(self, "_cell", _cell_branches(A, C))

    def __repr__(self) -> str:
        """One line: the grid, its ranges, the times' ranges and what the map was built for."""
        tot = self._A + self._C
        bad = int(np.sum(~np.isfinite(tot).any(axis=0)))
        return (f"TaskMap({self.station!r}, {self.du.size} x {self.w.size} nodes, du {_span(self.du)} m, "
                f"w {_span(self.w)} m, approach {_span(self.approach)} s, leave {_span(self.leave)} s, "
                f"{len(self.branches)} branch{'es' if len(self.branches) != 1 else ''}, {bad} infeasible, "
                f"speed {self.speed:.3g} m/s, mass {self.mass:.3g} kg)")

    def _weights(self, grid: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        i = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, grid.size - 2)
        f = (x - grid[i]) / (grid[i + 1] - grid[i])
        f = np.where((x < grid[0]) | (x > grid[-1]), np.nan, f)
        return i, f

    def _cell_branch(self, i: np.ndarray, j: np.ndarray, f: np.ndarray) -> np.ndarray:
        """Table index of the branch of grid cells (i, j) (-1: no branch feasible at its four nodes or ``f`` NaN)."""
        return np.where(np.isnan(f), -1, self._cell[i, j])

    def times(self, du: Any, w: Any) -> tuple[np.ndarray, np.ndarray]:
        """Interpolated ``(t_A, t_C)`` [s] at points ``du``, ``w`` (broadcast); NaN where infeasible.

        Bilinear within one IK branch: each grid cell uses the fastest branch feasible at its
        four nodes (:meth:`branch_at`), never a mixture of branches."""
        du, w = np.broadcast_arrays(np.asarray(du, float), np.asarray(w, float))
        i, fu = self._weights(self.du, du)
        j, fw = self._weights(self.w, w)
        b = self._cell_branch(i, j, fu + fw)
        bb = np.maximum(b, 0)
        out = []
        for table in (self._A, self._C):
            a, c = table[bb, i, j], table[bb, i + 1, j]
            d, e = table[bb, i, j + 1], table[bb, i + 1, j + 1]
            v = (a * (1 - fu) + c * fu) * (1 - fw) + (d * (1 - fu) + e * fu) * fw
            out.append(np.where(b >= 0, v, np.nan))
        return out[0], out[1]

    def approach_on(self, label: Any, du: Any, w: Any) -> np.ndarray:
        """The approach time t_A [s] at ``du``, ``w`` on IK branch ``label`` (broadcast; -1: the
        map's one branch), bilinear on that branch's table; NaN where a node of the cell is
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

    def branch_at(self, du: float, w: float) -> int | None:
        """The IK branch label the map uses at (``du``, ``w``) [m] (None: the arm has one branch
        or the point is infeasible); :func:`~.tracking.plan_pick` ``branch=`` plans it exactly."""
        i, fu = self._weights(self.du, np.asarray(du, float))
        j, fw = self._weights(self.w, np.asarray(w, float))
        b = int(self._cell_branch(i, j, fu + fw))
        return None if b < 0 or self.branches[b] < 0 else int(self.branches[b])

    def sim_grid(self, *others: "TaskMap") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The simulator's du nodes: ``(du, node, cell)`` (K,): the grid's nodes in order, a node
        listed twice (end of the cell before, start of the cell after) where the cells on its
        two sides use different branches for some w (in this map or ``others``, same du grid),
        so that piecewise-linear interpolation along du stays within one branch (the time may
        jump there)."""
        nodes, cells = [0], [0]
        for n in range(1, self.du.size - 1):
            if any(np.any(m._cell[n - 1] != m._cell[n]) for m in (self, *others)):
                nodes.append(n)
                cells.append(n - 1)
            nodes.append(n)
            cells.append(n)
        nodes.append(self.du.size - 1)
        cells.append(self.du.size - 2)
        node, cell = np.array(nodes), np.array(cells)
        return self.du[node], node, cell

    def rows(self, w: Any, grid: tuple | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(t_A, t_C)`` of shape (len(w), K) at the du nodes of :meth:`sim_grid` (or ``grid``,
        one of its results) for items at ``w`` [m] across."""
        _, node, cell = self.sim_grid() if grid is None else grid
        j, fw = self._weights(self.w, np.asarray(w, float))
        b = self._cell_branch(cell[None, :], j[:, None], fw[:, None] + np.zeros(cell.size))
        bb = np.maximum(b, 0)
        out = []
        for table in (self._A, self._C):
            n_, j_, f_ = node[None, :], j[:, None], fw[:, None]
            v = table[bb, n_, j_] * (1 - f_) + table[bb, n_, j_ + 1] * f_
            out.append(np.where(b >= 0, v, np.nan))
        return out[0], out[1]

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
                a checksum that does not match (the file was changed or damaged).
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


def _refine_at(x: np.ndarray, A: np.ndarray, C: np.ndarray, extra: float, tolerance: float, axis: int) -> np.ndarray:
    """Midpoints of the intervals of grid ``x`` (along ``axis`` of the (nb, nu, nw) tables: 1 du, 2 w)
    next to a node where some branch's approach or leave time has a second difference above
    ``4 × tolerance`` of the task time there: bilinear interpolation errs by about a quarter of it
    at a kink, an eighth on a smooth bend."""
    mark = np.zeros(x.size - 1, bool)
    n = x.size
    for T in (A, C):
        T, tot = np.moveaxis(T, axis, 1), np.moveaxis(A + C, axis, 1)
        d2 = np.abs(T[:, :-2] - 2.0 * T[:, 1:-1] + T[:, 2:])  # NaN where a node is infeasible
        with np.errstate(invalid="ignore"):
            bent = np.any(d2 > 4.0 * tolerance * (tot[:, 1:-1] + extra), axis=(0, 2))
        mark[: n - 2] |= bent
        mark[1:] |= bent
    return 0.5 * (x[:-1] + x[1:])[mark]


def _merge(x: np.ndarray, new: np.ndarray, tables: tuple, added: tuple, axis: int) -> tuple:
    """Grid ``x`` with ``new`` points, and each (nb, nu, nw) table with its ``added`` slices, sorted."""
    order = np.argsort(np.concatenate([x, new]), kind="stable")
    return (np.concatenate([x, new])[order],
            *(np.take(np.concatenate([t, a], axis=axis), order, axis=axis) for t, a in zip(tables, added)))


def _fixtures(task: dict) -> Any:
    """The column's :class:`~.fixtures.FixtureCheck` (None: no cell given)."""
    if task.get("cell") is None:
        return None
    from pinarms.optim.line.fixtures import fixture_check

    return fixture_check(task["cell"], task["station"].name, task["clearance"])


def _column(task: dict) -> tuple[np.ndarray, np.ndarray, int]:
    """Exact times of one ``du`` column (a task of the execution layer), and how many of its
    planned picks came closer than the clearance to the cell's fixtures (their times NaN)."""
    st, belt, spec = task["station"], task["belt"], task["spec"]
    u_base = float(belt.to_belt(st.base_to_world[:3, 3])[0])
    q_rest = rest_configuration(st)
    labels = task.get("branches", (-1,))
    fixtures = _fixtures(task)
    blocked = 0
    tA = np.full((len(labels), len(task["w"])), np.nan)
    tC = np.full_like(tA, np.nan)
    for b, label in enumerate(labels):
        for j, w in enumerate(task["w"]):
            try:
                plan = plan_pick(st, belt, spec, u_base + task["du"], w, item_height=task["height"], mass=task["mass"],
                                 q_rest=q_rest, branch=None if label < 0 else label)
            except (UnreachableTarget, InfeasibleProblem, OptimError):
                continue
            verdict = "clear" if fixtures is None else fixtures.verdict(plan.trajectory)
            if verdict != "clear":
                blocked += verdict == "fixtures"
                continue
            tA[b, j], tC[b, j] = plan.times[0], plan.times[2]
    return tA, tC, blocked


def build_task_map(station: Station, belt: Belt, spec: TrackingSpec = TrackingSpec(), *, mass: float = 0.1,
                   item_height: float = 0.04, margin: float = 0.025, nu: int = 24, nw: int = 7,
                   du_range: tuple[float, float] | None = None, scheduler: Any = None,
                   progress: Any = None, refine: int = 0, tolerance: float = 0.005, cell: Any = None,
                   clearance: float = 0.01) -> TaskMap:
    """Plan picks exactly on a ``nu`` × ``nw`` grid and keep their times (module doc).

    ``du`` spans the sampled workspace over the belt (:func:`~.windows.belt_span`, or ``du_range`` [m]);
    ``w`` the belt's width less ``margin`` [m] at each edge (half an item's width).
    ``refine``: passes that add a ``du`` column, then a ``w`` row, at the middle of each interval
    where a branch's approach or leave time bends more than linear interpolation can follow
    (:func:`_refine_at`: a second difference above ``4 × tolerance`` of the task time; a kink
    between nodes, e.g. where the limiting joint changes, shows there); the grid is then uneven.
    Maps of several item types of one arm must share their ``du`` grid: refine only single-type maps.
    ``cell``: a :class:`pinarms.robots.cell.Cell` with the station as one of its arms (same name and base):
    a node whose planned pick (the whole trajectory) comes closer than ``clearance`` [m] to the
    cell's fixtures is infeasible (:mod:`~.fixtures`; counted in ``TaskMap.fixture_infeasible``).

    Raises:
        BeltOutOfReach: the arm reaches no point of the belt (names the nearest belt point).
        UnreachableTarget: the arm cannot reach its box.
    """
    from pinarms.execution import map_chunks

    if not (isinstance(nu, int) and isinstance(nw, int) and nu >= 2 and nw >= 2):
        raise InvalidInput(f"nu and nw must be integers >= 2, got {nu!r}, {nw!r}")
    check_reach(station, belt, item_height)
    rest_configuration(station)
    if cell is not None:
        from pinarms.optim.line.fixtures import check_in_cell, fixture_check

        check_in_cell(cell, station)
        fixture_check(cell, station.name, clearance)  # bad clearance: an error before any planning
    start = time.perf_counter()
    lo, hi = belt_span(station, belt) if du_range is None else (float(du_range[0]), float(du_range[1]))
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise InvalidInput(f"du_range must be two finite numbers, low < high [m], got {du_range!r}")
    du = np.linspace(lo, hi, nu)
    half = belt.width / 2.0 - margin
    if half <= 0.0:
        raise InvalidInput(f"margin {margin} m leaves no belt width (width {belt.width} m)")
    w = np.linspace(-half, half, nw)
    u_base = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    uu, ww = np.meshgrid(u_base + du, w, indexing="ij")
    labels = ik_branch_labels(station, belt.to_world(uu.ravel(), ww.ravel(), item_height + spec.lift))
    task = {"station": station, "belt": belt, "spec": spec, "w": w.tolist(), "mass": mass, "height": item_height,
            "seed": 0, "branches": labels, "cell": cell, "clearance": clearance}
    cols = map_chunks(_column, [{**task, "du": float(d)} for d in du], scheduler=scheduler, progress=progress)
    blocked = sum(c[2] for c in cols)
    A = np.stack([c[0] for c in cols], axis=1)  # (nb, nu, nw)
    C = np.stack([c[1] for c in cols], axis=1)
    extra = spec.track_time + spec.release
    for _ in range(refine):  # along the belt (new du columns), then across (new w rows)
        new_u = _refine_at(du, A, C, extra, tolerance, 1)
        if new_u.size:
            cols = map_chunks(_column, [{**task, "du": float(d), "w": w.tolist()} for d in new_u], scheduler=scheduler,
                              progress=progress)
            blocked += sum(c[2] for c in cols)
            du, A, C = _merge(du, new_u, (A, C), tuple(np.stack([c[k] for c in cols], axis=1) for k in (0, 1)), 1)
        new_w = _refine_at(w, A, C, extra, tolerance, 2)
        if new_w.size:
            cols = map_chunks(_column, [{**task, "du": float(d), "w": new_w.tolist()} for d in du], scheduler=scheduler,
                              progress=progress)
            blocked += sum(c[2] for c in cols)
            w, A, C = _merge(w, new_w, (A, C), tuple(np.stack([c[k] for c in cols], axis=1) for k in (0, 1)), 2)
        if new_u.size == 0 and new_w.size == 0:
            break
    tot = A + C
    best = np.argmin(np.where(np.isfinite(tot), tot, np.inf), axis=0)[None]
    tA = np.take_along_axis(A, best, 0)[0]
    tC = np.take_along_axis(C, best, 0)[0]
    return TaskMap(station.name, du, w, tA, tC, spec.track_time, spec.release, belt.speed, float(mass),
                   time.perf_counter() - start, labels, A, C, int(blocked))


@dataclass(frozen=True, repr=False)
class MapError:
    """Interpolated vs exact task time at random feasible points: ``relative`` (n,) errors of
    the task time (approach + tracking + leave + release), ``max``, ``mean``, ``points`` (n, 2)."""

    relative: np.ndarray
    points: np.ndarray
    planning_seconds: float

    @property
    def max(self) -> float:
        return float(np.max(self.relative)) if self.relative.size else float("nan")

    @property
    def mean(self) -> float:
        return float(np.mean(self.relative)) if self.relative.size else float("nan")

    def __repr__(self) -> str:
        """One line: how many points, the max, mean and 95th percentile of the relative error [%]."""
        if not self.relative.size:
            return f"MapError(0 points, {self.planning_seconds:.1f} s of planning)"
        p95 = float(np.percentile(self.relative, 95))
        return (f"MapError({self.relative.size} points, max {100 * self.max:.2f} %, mean {100 * self.mean:.2f} %, "
                f"p95 {100 * p95:.2f} %, {self.planning_seconds:.1f} s of planning)")


def _span(values: np.ndarray) -> str:
    """``lo..hi`` of the finite values at 3 significant digits (``none`` when none is finite)."""
    finite = np.asarray(values)[np.isfinite(values)]
    return f"{finite.min():.3g}..{finite.max():.3g}" if finite.size else "none"


def map_error(task_map: TaskMap, station: Station, belt: Belt, spec: TrackingSpec = TrackingSpec(), *,
              n: int = 30, item_height: float = 0.04, seed: int = 0) -> MapError:
    """Exact re-planning at ``n`` seeded random points where the map says feasible (module doc), each
    item at a random yaw (the map is built at yaw 0: the hand's turn leaves the time unchanged,
    tests/optim/line/test_tracking.py)."""
    rng = np.random.default_rng(seed)
    u_base = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    q_rest = rest_configuration(station)
    rel, pts = [], []
    tries = 0
    start = time.perf_counter()
    while len(rel) < n and tries < 50 * n:
        tries += 1
        du = rng.uniform(task_map.du[0], task_map.du[-1])
        w = rng.uniform(task_map.w[0], task_map.w[-1])
        yaw = rng.uniform(-np.pi, np.pi)  # the map has no yaw coordinate: the exact plan turns the hand to it
        tA, tC = task_map.times(du, w)
        if not (np.isfinite(tA) and np.isfinite(tC)):
            continue
        try:
            plan = plan_pick(station, belt, spec, u_base + du, w, item_height=item_height, mass=task_map.mass,
                             q_rest=q_rest, branch=task_map.branch_at(du, w), yaw=yaw)
        except PinarmsError:
            continue
        approx = float(tA + tC) + task_map.track + task_map.release
        rel.append(abs(approx - plan.duration) / plan.duration)
        pts.append((du, w))
    return MapError(np.array(rel), np.array(pts).reshape(-1, 2), time.perf_counter() - start)
