"""Building a :class:`~.task_maps.TaskMap`: exact picks planned on a grid, refined where the times bend.

:func:`build_task_map` plans a pick (:func:`~.tracking.plan_pick`) at every node of a grid of
pre-grasp points (``du`` along the belt from the arm's base, ``w`` across) on each IK branch,
and keeps its approach and leave times. The item's yaw (:mod:`~.task_maps`): with ``yaw="auto"``
(default) the times are also planned at ``yaw_nodes`` tool yaws over [-period/2, period/2] on a
few probe columns of ``du``; where the task time changes by more than
:data:`~.task_maps.YAW_TOLERANCE` of itself, every column is planned at every yaw node and the
map gets a yaw coordinate (refined where the time bends along yaw), otherwise it has none and
stores the spread it measured. An arm that cannot turn its tool (:func:`~.tracking.can_yaw`)
has a spread of 0 without planning.

Built on the execution layer (:func:`pinarms.execution.map_chunks`: serial by default, or a
Dask cluster), one task per ``du`` column and yaw node, same result either way.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from pinarms.optim.errors import InfeasibleProblem, OptimError
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.station import Station
from pinarms.optim.line.task_maps import YAW_TOLERANCE, TaskMap
from pinarms.optim.line.tracking import TrackingSpec, can_yaw, ik_branch_labels, plan_pick, rest_configuration
from pinarms.optim.line.windows import belt_span, check_reach
from pinarms.errors import InvalidInput, UnreachableTarget

if TYPE_CHECKING:
    from pinarms.optim.line.fixtures import FixtureCheck

__all__ = ["build_task_map", "measure_yaw", "YAW_MODES", "PROBE_COLUMNS", "PROBE_YAWS", "task_fixture_check"]

#: ``"auto"``: a yaw coordinate where the task time depends on yaw (measured); ``"axis"``: always
#: (arms that can turn their tool); ``"none"``: never, the spread not measured (the maps before).
YAW_MODES = ("auto", "axis", "none")
#: Interior ``du`` columns on which ``yaw="auto"`` measures the yaw dependence (evenly spread).
PROBE_COLUMNS = 3
#: Where on the yaw grid (fractions of it, 0: -period/2, 1: +period/2) ``yaw="auto"`` probes.
PROBE_YAWS = (0.0, 0.25, 0.75)


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
    """Grid ``x`` with ``new`` points, and each table with its ``added`` slices along ``axis``, sorted."""
    order = np.argsort(np.concatenate([x, new]), kind="stable")
    return (np.concatenate([x, new])[order],
            *(np.take(np.concatenate([t, a], axis=axis), order, axis=axis) for t, a in zip(tables, added)))


def task_fixture_check(task: dict) -> FixtureCheck | None:
    """The fixture check of a map column's ``task`` (its ``cell``, ``station`` and ``clearance``; None: no cell given):
    a :class:`~.fixtures.FixtureCheck`."""
    if task.get("cell") is None:
        return None
    from pinarms.optim.line.fixtures import fixture_check

    return fixture_check(task["cell"], task["station"].name, task["clearance"])


def _plan_yaw(yaw: float, period: float) -> float:
    """The item yaw [rad] planned for tool-yaw node ``yaw``: the node itself, the last node
    (+period/2, the same grasp as -period/2 reached from the other side) just below it."""
    return min(float(yaw), period / 2.0 * (1.0 - 1e-9))


def _column(task: dict) -> tuple[np.ndarray, np.ndarray, int]:
    """Exact times of one ``du`` column at one tool yaw (a task of the execution layer), and how
    many of its planned picks came closer than the clearance to the cell's fixtures (their times NaN)."""
    st, belt, spec = task["station"], task["belt"], task["spec"]
    u_base = float(belt.to_belt(st.base_to_world[:3, 3])[0])
    q_rest = rest_configuration(st)
    labels = task.get("branches", (-1,))
    yaw = _plan_yaw(task.get("yaw", 0.0), spec.yaw_period)
    fixtures = task_fixture_check(task)
    blocked = 0
    tA = np.full((len(labels), len(task["w"])), np.nan)
    tC = np.full_like(tA, np.nan)
    for b, label in enumerate(labels):
        for j, w in enumerate(task["w"]):
            try:
                plan = plan_pick(st, belt, spec, u_base + task["du"], w, item_height=task["height"], mass=task["mass"],
                                 q_rest=q_rest, branch=None if label < 0 else label, yaw=yaw)
            except (UnreachableTarget, InfeasibleProblem, OptimError):
                continue
            verdict = "clear" if fixtures is None else fixtures.verdict(plan.trajectory)
            if verdict != "clear":
                blocked += verdict == "fixtures"
                continue
            tA[b, j], tC[b, j] = plan.times[0], plan.times[2]
    return tA, tC, blocked


class _Planner:
    """Plans blocks of the 4-D tables (yaw, branch, du, w) through the execution layer, counting
    blocked nodes and reporting progress as one count over every block (``progress(done, total)``)."""

    def __init__(self, task: dict, scheduler: Any, progress: Callable | None) -> None:
        self.task, self.scheduler, self.progress = task, scheduler, progress
        self.blocked, self.done, self.total = 0, 0, 0

    def __call__(self, du: np.ndarray, w: np.ndarray, yaw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tables (len(yaw), nb, len(du), len(w)) of approach and leave times."""
        from pinarms.execution import map_chunks

        tasks = [{**self.task, "du": float(d), "w": w.tolist(), "yaw": float(y)} for y in yaw for d in du]
        base, self.total = self.done, self.total + len(tasks)

        def report(done: int, total: int | None = None) -> None:
            self.done = base + done
            if self.progress is not None:
                self.progress(self.done, self.total)

        cols = map_chunks(_column, tasks, scheduler=self.scheduler, progress=report if self.progress else None)
        self.done = base + len(tasks)
        self.blocked += sum(c[2] for c in cols)
        nb = len(self.task["branches"])
        shape = (len(yaw), len(du), nb, len(w))
        A = np.stack([c[0] for c in cols]).reshape(shape).transpose(0, 2, 1, 3)
        C = np.stack([c[1] for c in cols]).reshape(shape).transpose(0, 2, 1, 3)
        return A, C


def _spread(A: np.ndarray, C: np.ndarray, zero: int, extra: float) -> float:
    """Largest relative change of the task time over the yaw layers of (ny, nb, nu, nw) tables against
    the layer ``zero``, on each IK branch where it is feasible at both yaws (0 where none is): what
    interpolating a map without yaw on its branch errs by. A branch that is feasible at one yaw
    and not at another (a joint limit reached as the hand turns) is not counted here."""
    tot = A + C + extra
    with np.errstate(invalid="ignore"):
        rel = np.abs(tot - tot[zero]) / tot[zero]
    rel = rel[np.isfinite(rel)]
    return float(rel.max()) if rel.size else 0.0


def _yaw_axis(plan: _Planner, du: np.ndarray, w: np.ndarray, mode: str, nodes: int, period: float, extra: float,
              ) -> tuple[np.ndarray | None, np.ndarray, np.ndarray, float]:
    """The yaw grid (None: no yaw coordinate), the (ny, nb, nu, nw) tables and the measured spread.
    ``"auto"`` probes :data:`PROBE_YAWS` of the grid on :data:`PROBE_COLUMNS` interior columns first."""
    y0 = np.zeros(1)
    if mode == "none" or not can_yaw(plan.task["station"].robot):
        A, C = plan(du, w, y0)
        return None, A, C, (float("nan") if mode == "none" else 0.0)
    grid = np.linspace(-period / 2.0, period / 2.0, nodes)
    mid = nodes // 2
    grid[mid] = 0.0
    A = np.full((nodes, len(plan.task["branches"]), du.size, w.size), np.nan)
    C = np.full_like(A, np.nan)
    A[mid:mid + 1], C[mid:mid + 1] = plan(du, w, y0)
    cols, todo = np.arange(du.size), np.delete(np.arange(nodes), mid)
    if mode == "auto":
        probe = np.unique(np.round(np.linspace(0, du.size - 1, PROBE_COLUMNS + 2)).astype(int)[1:-1])
        ys = np.unique(np.round(np.asarray(PROBE_YAWS) * (nodes - 1)).astype(int))
        A[np.ix_(ys, range(A.shape[1]), probe)], C[np.ix_(ys, range(A.shape[1]), probe)] = plan(du[probe], w, grid[ys])
        spread = _spread(A[np.r_[mid, ys]][:, :, probe], C[np.r_[mid, ys]][:, :, probe], 0, extra)
        if spread <= YAW_TOLERANCE:
            return None, A[mid:mid + 1], C[mid:mid + 1], spread
        rest = [(y, np.arange(du.size) if y not in ys else np.setdiff1d(cols, probe)) for y in todo]
    else:
        rest = [(y, cols) for y in todo]
    for group in (probe_rows for probe_rows in _same_columns(rest)):
        ys_, cs = group
        if cs.size:
            A[np.ix_(ys_, range(A.shape[1]), cs)], C[np.ix_(ys_, range(A.shape[1]), cs)] = plan(du[cs], w, grid[ys_])
    return grid, A, C, _spread(A, C, mid, extra)


def _same_columns(rows: list) -> list:
    """``[(yaw index, columns)]`` grouped as ``[(yaw indices, columns)]`` for rows with the same columns."""
    groups: dict = {}
    for y, cs in rows:
        groups.setdefault(tuple(cs.tolist()), []).append(y)
    return [(np.array(ys), np.array(cs, dtype=int)) for cs, ys in groups.items()]


def _refine(plan: _Planner, du: np.ndarray, w: np.ndarray, yaw: np.ndarray | None, A: np.ndarray, C: np.ndarray,
            extra: float, tolerance: float, passes: int, yaw_passes: int) -> tuple:
    """Refinement passes (module doc of :func:`build_task_map`): du, then w, then yaw (4-D tables)."""
    ys = np.zeros(1) if yaw is None else yaw
    for k in range(max(passes, yaw_passes if yaw is not None else 0)):
        flat = (A.reshape(-1, *A.shape[2:]), C.reshape(-1, *C.shape[2:]))  # yaw layers as more branches
        new_u = _refine_at(du, *flat, extra, tolerance, 1) if k < passes else np.zeros(0)
        if new_u.size:
            du, A, C = _merge(du, new_u, (A, C), plan(new_u, w, ys), 2)
            flat = (A.reshape(-1, *A.shape[2:]), C.reshape(-1, *C.shape[2:]))
        new_w = _refine_at(w, *flat, extra, tolerance, 2) if k < passes else np.zeros(0)
        if new_w.size:
            w, A, C = _merge(w, new_w, (A, C), plan(du, new_w, ys), 3)
        new_y = np.zeros(0)
        if yaw is not None and k < yaw_passes:
            by_yaw = tuple(np.moveaxis(T, 0, 1).reshape(T.shape[1], T.shape[0], -1) for T in (A, C))
            new_y = _refine_at(ys, *by_yaw, extra, tolerance, 1)
            if new_y.size:
                ys, A, C = _merge(ys, new_y, (A, C), plan(du, w, new_y), 0)
        if new_u.size == 0 and new_w.size == 0 and new_y.size == 0:
            break
    return du, w, (None if yaw is None else ys), A, C


def build_task_map(station: Station, belt: Belt, spec: TrackingSpec = TrackingSpec(), *, mass: float = 0.1,
                   item_height: float = 0.04, margin: float = 0.025, nu: int = 24, nw: int = 7,
                   du_range: tuple[float, float] | None = None, scheduler: Any = None,
                   progress: Any = None, refine: int = 0, tolerance: float = 0.005, cell: Any = None,
                   clearance: float = 0.01, yaw: str = "auto", yaw_nodes: int = 9, yaw_refine: int = 2) -> TaskMap:
    """Plan picks exactly on a ``nu`` × ``nw`` grid and keep their times (module doc).

    ``du`` spans the sampled workspace over the belt (:func:`~.windows.belt_span`, or ``du_range`` [m]);
    ``w`` the belt's width less ``margin`` [m] at each edge (half an item's width).
    ``refine``: passes that add a ``du`` column, then a ``w`` row, at the middle of each interval
    where a branch's approach or leave time bends more than linear interpolation can follow
    (:func:`_refine_at`: a second difference above ``4 × tolerance`` of the task time; a kink
    between nodes, e.g. where the limiting joint changes, shows there); the grid is then uneven.
    Maps of several item types of one arm must share their ``du`` grid: refine only single-type maps.
    ``yaw`` (:data:`YAW_MODES`), ``yaw_nodes`` (odd, >= 3: the first yaw grid, 0 its middle node) and
    ``yaw_refine`` (passes that add yaw nodes where the time bends along yaw): the item's yaw
    (module doc). ``progress(done, total)``: picks columns planned so far (the total grows as the
    yaw measure and the refinement add columns).
    ``cell``: a :class:`pinarms.robots.cell.Cell` with the station as one of its arms (same name and base):
    a node whose planned pick (the whole trajectory) comes closer than ``clearance`` [m] to the
    cell's fixtures is infeasible (:mod:`~.fixtures`; counted in ``TaskMap.fixture_infeasible``).

    Raises:
        BeltOutOfReach: the arm reaches no point of the belt (names the nearest belt point).
        UnreachableTarget: the arm cannot reach its box.
        InvalidInput: a grid size, range, margin or yaw option out of its domain.
    """
    if not (isinstance(nu, int) and isinstance(nw, int) and nu >= 2 and nw >= 2):
        raise InvalidInput(f"nu and nw must be integers >= 2, got {nu!r}, {nw!r}")
    if yaw not in YAW_MODES:
        raise InvalidInput(f"yaw must be one of {YAW_MODES}, got {yaw!r}")
    if not (isinstance(yaw_nodes, int) and yaw_nodes >= 3 and yaw_nodes % 2 == 1):
        raise InvalidInput(f"yaw_nodes must be an odd integer >= 3 (0 is the middle node), got {yaw_nodes!r}")
    if not (isinstance(yaw_refine, int) and yaw_refine >= 0):
        raise InvalidInput(f"yaw_refine must be an integer >= 0, got {yaw_refine!r}")
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
    task = {"station": station, "belt": belt, "spec": spec, "mass": mass, "height": item_height,
            "seed": 0, "branches": labels, "cell": cell, "clearance": clearance}
    plan = _Planner(task, scheduler, progress)
    extra = spec.track_time + spec.release
    ygrid, A, C, spread = _yaw_axis(plan, du, w, yaw, yaw_nodes, spec.yaw_period, extra)
    du, w, ygrid, A, C = _refine(plan, du, w, ygrid, A, C, extra, tolerance, refine, yaw_refine)
    zero = 0 if ygrid is None else int(np.flatnonzero(ygrid == 0.0)[0])
    A0, C0 = A[zero], C[zero]
    tot = A0 + C0
    best = np.argmin(np.where(np.isfinite(tot), tot, np.inf), axis=0)[None]
    tA = np.take_along_axis(A0, best, 0)[0]
    tC = np.take_along_axis(C0, best, 0)[0]
    if ygrid is not None:
        spread = _spread(A, C, zero, extra)
    yaw_fields = {} if ygrid is None else {"yaw": ygrid, "yaw_approach": A, "yaw_leave": C}
    return TaskMap(station.name, du, w, tA, tC, spec.track_time, spec.release, belt.speed, float(mass),
                   time.perf_counter() - start, labels, A0, C0, int(plan.blocked), yaw_period=spec.yaw_period,
                   yaw_spread=spread, **yaw_fields)


def measure_yaw(task_map: TaskMap, station: Station, belt: Belt, spec: TrackingSpec = TrackingSpec(), *,
                item_height: float = 0.04, yaw_nodes: int = 9, scheduler: Any = None, progress: Any = None) -> TaskMap:
    """``task_map`` (without a yaw coordinate, e.g. read from a file written before maps measured yaw)
    with its yaw spread measured as :func:`build_task_map` measures it (probe columns and yaws of a
    ``yaw_nodes`` grid, against the map's own times at yaw 0); its times unchanged. The map's
    :meth:`~.task_maps.TaskMap.warnings` then say whether it may ignore yaw.

    Raises:
        InvalidInput: the map already has a yaw coordinate, or ``yaw_nodes`` is not odd and >= 3.
    """
    from dataclasses import replace

    if task_map.yaw is not None:
        raise InvalidInput(f"task map {task_map.station!r} has a yaw coordinate already: nothing to measure")
    if not (isinstance(yaw_nodes, int) and yaw_nodes >= 3 and yaw_nodes % 2 == 1):
        raise InvalidInput(f"yaw_nodes must be an odd integer >= 3 (0 is the middle node), got {yaw_nodes!r}")
    if not can_yaw(station.robot):
        return replace(task_map, yaw_spread=0.0, yaw_period=spec.yaw_period)
    task = {"station": station, "belt": belt, "spec": spec, "mass": task_map.mass, "height": item_height,
            "seed": 0, "branches": task_map.branches, "cell": None, "clearance": 0.01}
    plan = _Planner(task, scheduler, progress)
    du = task_map.du
    grid = np.linspace(-spec.yaw_period / 2.0, spec.yaw_period / 2.0, yaw_nodes)
    probe = np.unique(np.round(np.linspace(0, du.size - 1, PROBE_COLUMNS + 2)).astype(int)[1:-1])
    ys = np.unique(np.round(np.asarray(PROBE_YAWS) * (yaw_nodes - 1)).astype(int))
    A, C = plan(du[probe], task_map.w, grid[ys])
    A0 = (task_map.approach[None] if task_map.branch_approach is None else task_map.branch_approach)[None][:, :, probe]
    C0 = (task_map.leave[None] if task_map.branch_leave is None else task_map.branch_leave)[None][:, :, probe]
    spread = _spread(np.concatenate([A0, A]), np.concatenate([C0, C]), 0, task_map.track + task_map.release)
    return replace(task_map, yaw_spread=spread, yaw_period=spec.yaw_period)
