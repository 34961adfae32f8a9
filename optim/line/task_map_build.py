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
from functools import partial
from typing import Any, Callable

import numpy as np

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.map_request import MapRequest, MapResult, MapStatus
from pinarms.optim.line.map_nodes import map_key, node_fixtures, plan_node, plan_yaw, task_station
from pinarms.optim.line.map_refine import add_yaw_nodes, bent_lines, bent_nodes, merge_nodes
from pinarms.optim.line.station import Station
from pinarms.optim.line.task_maps import YAW_TOLERANCE, TaskMap
from pinarms.optim.line.tracking import TrackingSpec, can_yaw, ik_branch_labels, plan_pick, rest_configuration
from pinarms.optim.line.windows import belt_span, check_reach
from pinarms.errors import InvalidInput
from pinarms.execution import Scheduler, scheduler_session

__all__ = ["build_task_map", "measure_yaw", "PROBE_COLUMNS", "PROBE_YAWS"]

#: Interior ``du`` columns on which ``yaw="auto"`` measures the yaw dependence (evenly spread).
PROBE_COLUMNS = 3
#: Where on the yaw grid (fractions of it, 0: -period/2, 1: +period/2) ``yaw="auto"`` probes.
PROBE_YAWS = (0.0, 0.25, 0.75)


def _column(task: dict) -> tuple[np.ndarray, np.ndarray, int, float]:
    """Exact times of one ``du`` column at one tool yaw (a task of the execution layer), how
    many of its planned picks came closer than the clearance to the cell's fixtures (their times NaN),
    and the CPU time [s] it took."""
    cpu = time.process_time()
    st, belt, spec = task_station(task), task["belt"], task["spec"]
    u_base = float(belt.to_belt(st.base_to_world[:3, 3])[0])
    q_rest = task["q_rest"]
    labels = task.get("branches", (-1,))
    yaw = plan_yaw(task.get("yaw", 0.0), spec.yaw_period)
    fixtures = node_fixtures(task)
    blocked = 0
    tA = np.full((len(labels), len(task["w"])), np.nan)
    tC = np.full_like(tA, np.nan)
    for b, label in enumerate(labels):
        for j, w in enumerate(task["w"]):
            plan, bad = plan_node(partial(plan_pick, st, belt, spec, u_base + task["du"], w, item_height=task["height"],
                                          mass=task["mass"], q_rest=q_rest, branch=None if label < 0 else label,
                                          yaw=yaw), fixtures)
            blocked += bad
            if plan is not None:
                tA[b, j], tC[b, j] = plan.times[0], plan.times[2]
    return tA, tC, blocked, time.process_time() - cpu


class _Planner:
    """Plans blocks of the 4-D tables (yaw, branch, du, w) through the execution layer, counting
    plans and blocked nodes and reporting progress as one count over every block
    (``progress(done, total)``: columns planned)."""

    def __init__(self, task: dict, scheduler: Any, progress: Callable | None) -> None:
        self.task, self.scheduler, self.progress = task, scheduler, progress
        self.blocked, self.done, self.total, self.plans, self.cpu = 0, 0, 0, 0, 0.0

    def __call__(self, du: np.ndarray, w: np.ndarray, yaw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tables (len(yaw), nb, len(du), len(w)) of approach and leave times at every node."""
        return self.nodes(du, w, yaw, np.ones((len(yaw), len(du), len(w)), bool))

    def nodes(self, du: np.ndarray, w: np.ndarray, yaw: np.ndarray, need: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tables (len(yaw), nb, len(du), len(w)) planned where ``need`` (len(yaw), len(du), len(w)), NaN
        elsewhere: one task per yaw and column that needs a node."""
        from pinarms.execution import map_chunks

        where = [(k, i) for k in range(len(yaw)) for i in range(len(du)) if need[k, i].any()]
        tasks = [{**self.task, "du": float(du[i]), "w": np.asarray(w)[need[k, i]].tolist(), "yaw": float(yaw[k])}
                 for k, i in where]
        base, self.total = self.done, self.total + len(tasks)

        def report(done: int, total: int | None = None) -> None:
            self.done = base + done
            if self.progress is not None:
                self.progress(self.done, self.total)

        cols = map_chunks(_column, tasks, scheduler=self.scheduler, progress=report if self.progress else None)
        self.done = base + len(tasks)
        nb = len(self.task["branches"])
        A = np.full((len(yaw), nb, len(du), len(w)), np.nan)
        C = np.full_like(A, np.nan)
        for (k, i), (a, c, blocked, cpu) in zip(where, cols):
            A[k, :, i, need[k, i]], C[k, :, i, need[k, i]] = a.T, c.T
            self.blocked += blocked
            self.plans += a.size
            self.cpu += cpu
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
    """Refinement passes (:mod:`~.map_refine`): whole du columns, then w rows, where a time bends;
    then yaw nodes at each (du, w) node where its time bends along yaw (the others interpolated)."""
    ys = np.zeros(1) if yaw is None else yaw
    for k in range(max(passes, yaw_passes if yaw is not None else 0)):
        added = 0
        if k < passes:
            new_u = bent_lines(du, A, C, extra, tolerance, 2)
            if new_u.size:
                du, A, C = merge_nodes(du, new_u, (A, C), plan(new_u, w, ys), 2)
            new_w = bent_lines(w, A, C, extra, tolerance, 3)
            if new_w.size:
                w, A, C = merge_nodes(w, new_w, (A, C), plan(du, new_w, ys), 3)
            added = new_u.size + new_w.size
        if yaw is not None and k < yaw_passes:
            ys, A, C, more = add_yaw_nodes(ys, A, C, extra, tolerance, partial(plan.nodes, du, w))
            added += more
        if not added:
            break
    return du, w, (None if yaw is None else ys), A, C


def build_task_map(request: MapRequest, *, scheduler: Scheduler = None,
                   progress: Callable[[int, int], None] | None = None) -> MapResult:
    """Plan picks exactly on the request's ``nu`` × ``nw`` grid and keep their times (module doc).

    ``du`` spans the sampled workspace over the belt (:func:`~.windows.belt_span`, or ``du_range`` [m]);
    ``w`` the belt's width less ``margin`` [m] at each edge (half an item's width).
    ``refine``: passes that add a ``du`` column, then a ``w`` row, at the middle of each interval
    where a branch's approach or leave time bends more than linear interpolation can follow
    (:func:`~.map_refine.bent_lines`: a second difference above ``4 × tolerance`` of the task time; a kink
    between nodes, e.g. where the limiting joint changes, shows there); the grid is then uneven.
    Maps of several item types of one arm must share their ``du`` grid: refine only single-type maps.
    ``yaw``, ``yaw_nodes`` and ``yaw_refine`` (passes that add a yaw node where the time bends along
    yaw, planned only at the (du, w) nodes that bend: :func:`~.map_refine.bent_nodes`): the item's
    yaw (module doc). ``cell``: nodes whose planned pick (the whole trajectory) comes closer than
    ``clearance`` [m] to the cell's fixtures are infeasible (:mod:`~.fixtures`; counted in
    ``TaskMap.fixture_infeasible`` and ``MapResult.blocked``).
    ``scheduler``: where the plans run (:mod:`pinarms.execution`; ``"processes:N"`` starts its
    workers once for the whole build); ``progress(done, total)``: columns planned so far (the total
    grows as the yaw measure and the refinement add columns).

    Returns:
        :class:`~.map_request.MapResult`: the ``TaskMap``; status ``built``, ``refine left`` (a time
        still bends more than the tolerance after the last refinement pass asked for) or ``no
        feasible node``.

    Raises:
        BeltOutOfReach: the arm reaches no point of the belt (names the nearest belt point).
        UnreachableTarget: the arm cannot reach its box.
        InvalidInput: not a :class:`~.map_request.MapRequest`.
    """
    if not isinstance(request, MapRequest):
        raise InvalidInput(f"build_task_map takes a MapRequest (optim.line.MapRequest), got {type(request).__name__}")
    rq, station, belt, spec = request, request.station, request.belt, request.spec
    check_reach(station, belt, rq.item_height)
    q_rest = rest_configuration(station)
    start = time.perf_counter()
    lo, hi = belt_span(station, belt) if rq.du_range is None else (float(rq.du_range[0]), float(rq.du_range[1]))
    du = np.linspace(lo, hi, rq.nu)
    half = belt.width / 2.0 - rq.margin
    w = np.linspace(-half, half, rq.nw)
    u_base = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    uu, ww = np.meshgrid(u_base + du, w, indexing="ij")
    labels = ik_branch_labels(station, belt.to_world(uu.ravel(), ww.ravel(), rq.item_height + spec.lift))
    task = {"station": station, "belt": belt, "spec": spec, "mass": rq.mass, "height": rq.item_height, "seed": 0,
            "branches": labels, "cell": rq.cell, "clearance": rq.clearance, "q_rest": q_rest, "key": map_key()}
    extra = spec.track_time + spec.release
    with scheduler_session(scheduler) as held:
        plan = _Planner(task, held, progress)
        ygrid, A, C, spread = _yaw_axis(plan, du, w, rq.yaw, rq.yaw_nodes, spec.yaw_period, extra)
        du, w, ygrid, A, C = _refine(plan, du, w, ygrid, A, C, extra, rq.tolerance, rq.refine, rq.yaw_refine)
    zero = 0 if ygrid is None else int(np.flatnonzero(ygrid == 0.0)[0])
    A0, C0 = A[zero], C[zero]
    tot = A0 + C0
    best = np.argmin(np.where(np.isfinite(tot), tot, np.inf), axis=0)[None]
    tA = np.take_along_axis(A0, best, 0)[0]
    tC = np.take_along_axis(C0, best, 0)[0]
    if ygrid is not None:
        spread = _spread(A, C, zero, extra)
    yaw_fields = {} if ygrid is None else {"yaw": ygrid, "yaw_approach": A, "yaw_leave": C}
    seconds = time.perf_counter() - start
    m = TaskMap(station.name, du, w, tA, tC, spec.track_time, spec.release, belt.speed, float(rq.mass), seconds,
                labels, A0, C0, int(plan.blocked), yaw_period=spec.yaw_period, yaw_spread=spread, **yaw_fields)
    status, reason = _status(rq, du, w, ygrid, A, C, extra)
    return MapResult(status, reason, m, plan.plans, int(plan.blocked), seconds, plan.cpu)


def _status(rq: MapRequest, du: np.ndarray, w: np.ndarray, yaw: np.ndarray | None, A: np.ndarray, C: np.ndarray,
            extra: float) -> tuple[MapStatus, str]:
    """The build's status and reason (:mod:`~.map_request`): no feasible node; bends left after the
    refinement passes asked for (du/w with ``refine`` > 0, yaw with ``yaw_refine`` > 0); built."""
    if not np.isfinite(A + C).any():
        return MapStatus.NO_FEASIBLE, "no node of the grid is feasible: move the arm or its box, or widen du_range"
    left = []
    if rq.refine > 0:
        lines = bent_lines(du, A, C, extra, rq.tolerance, 2).size + bent_lines(w, A, C, extra, rq.tolerance, 3).size
        if lines:
            left.append(f"{lines} du/w intervals (raise refine, now {rq.refine})")
    if yaw is not None and rq.yaw_refine > 0:
        nodes = int(bent_nodes(yaw, A, C, extra, rq.tolerance).sum())
        if nodes:
            left.append(f"{nodes} yaw intervals at (du, w) nodes (raise yaw_refine, now {rq.yaw_refine})")
    if left:
        return MapStatus.REFINE_LEFT, f"times still bend beyond tolerance {rq.tolerance:g} in " + " and ".join(left)
    return MapStatus.BUILT, ""


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
    task = {"station": station, "belt": belt, "spec": spec, "mass": task_map.mass, "height": item_height, "seed": 0,
            "branches": task_map.branches, "cell": None, "clearance": 0.01, "q_rest": rest_configuration(station),
            "key": map_key()}
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
