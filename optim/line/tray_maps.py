"""Building a :class:`~.tray_map.TrayMap` from exact plans, and checking it against them.

:func:`build_tray_map` plans, on a ``nu`` × ``nw`` × ``nv`` grid, each pick once per (``du``, ``w``)
node (:func:`~.tracking.plan_pick`), then its place at every ``dv`` node on every place IK branch
(:func:`~.trays.plan_pick_to_tray`), each node by the rule every map shares
(:func:`~.map_nodes.plan_node`); built on the execution layer, one task per ``du`` column.
:func:`tray_map_error` re-plans at seeded random points on the branch the map chose.
"""


from __future__ import annotations

import time
from functools import partial
from typing import Any, Callable

import numpy as np

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.map_request import MapResult, MapStatus, TrayMapRequest
from pinarms.optim.line.map_nodes import map_key, node_fixtures, plan_node, plan_yaw, task_station
from pinarms.optim.line.station import Station
from pinarms.optim.line.task_map_error import MapError
from pinarms.optim.line.tray_map import TrayMap
from pinarms.optim.line.task_map_build import PROBE_COLUMNS, PROBE_YAWS
from pinarms.optim.line.tracking import (TrackingSpec, branch_label, can_yaw, ik_branch_labels, plan_pick,
                                         rest_configuration)
from pinarms.optim.line.trays import TrayBelt, plan_pick_to_tray
from pinarms.optim.line.windows import belt_span, check_reach
from pinarms.errors import InvalidInput, PinarmsError
from pinarms.execution import Scheduler, scheduler_session

__all__ = ["build_tray_map", "tray_map_error"]


def _column(task: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """One ``du`` column: the pick planned once per ``w`` (on the rest configuration's elbow where it
    reaches), then placed at every ``dv`` on every place branch (each node by :func:`~.map_nodes.plan_node`)."""
    st, belt, trays, spec = task_station(task), task["belt"], task["trays"], task["spec"]
    u_base = float(belt.to_belt(st.base_to_world[:3, 3])[0])
    v_base = float(trays.belt.to_belt(st.base_to_world[:3, 3])[0])
    q_rest = task["q_rest"]
    nw, nv, labels = len(task["w"]), len(task["dv"]), task["branches"]
    fixtures = node_fixtures(task)
    blocked = 0
    A, P = np.full(nw, np.nan), np.full(nw, -1)
    X, R = np.full((len(labels), nw, nv), np.nan), np.full((len(labels), nw, nv), np.nan)
    u = u_base + task["du"]
    yaw = plan_yaw(task.get("yaw", 0.0), spec.yaw_period)
    for j, w in enumerate(task["w"]):
        pick, _ = plan_node(partial(plan_pick, st, belt, spec, u, w, item_height=task["height"], mass=task["mass"],
                                    q_rest=q_rest, yaw=yaw), None)
        if pick is None:
            continue  # no pick here: no place either
        for b, label in enumerate(labels):
            for k, dv in enumerate(task["dv"]):
                p, bad = plan_node(partial(plan_pick_to_tray, st, belt, trays, spec, u, w, v_base + dv,
                                           item_height=task["height"], mass=task["mass"], q_rest=q_rest,
                                           place_branch=None if label < 0 else label, pick=pick, yaw=yaw), fixtures)
                blocked += bad
                if p is None:
                    continue
                A[j], X[b, j, k], R[b, j, k] = p.times[0], p.times[2], p.times[4]
                P[j] = branch_label(st.robot, p.pieces[1].sample(np.array([0.0]))[0][0])
    return A, X, R, P, blocked


#: Half-width [m] of the place-grid cells around the place ending at the arm's home (:func:`_with_home_nodes`).
HOME_GAP = 0.03


def _with_home_nodes(dv: np.ndarray, station: Station, trays: TrayBelt, spec: TrackingSpec,
                     v_base: float) -> np.ndarray:
    """The place grid with nodes at and ``HOME_GAP`` either side of the place whose tracking ends
    just above the arm's home (its box point) when the tray belt passes there: the return time is
    V-shaped about it (0.16 s there, rising on both sides: linear interpolation across the V erred
    by up to 1.1 % of the task), and right at it the return (a path of almost no length starting at
    the tray's speed) has no feasible timing: the node there is infeasible and each side of the V is
    interpolated on its own."""
    home = trays.belt.to_belt(station.place.position)
    if abs(home[1] - trays.w) > 0.05 or abs(home[2] - trays.height - spec.lift) > 0.1:
        return dv  # the place does not pass the home point: no V
    kink = float(home[0]) - v_base - trays.belt.speed * (2.0 * spec.descend + spec.release)
    extra = [x for x in (kink - HOME_GAP, kink, kink + HOME_GAP) if dv[0] < x < dv[-1]]
    return np.unique(np.concatenate([dv, extra]))


def _plan_columns(task: dict, du: np.ndarray, yaw: float, scheduler: Scheduler, progress: Any) -> list:
    """:func:`_column` of every ``du`` at item yaw ``yaw`` through the execution layer."""
    from pinarms.execution import map_chunks

    return map_chunks(_column, [{**task, "du": float(d), "yaw": float(yaw)} for d in du], scheduler=scheduler,
                      progress=progress)


def _measure_yaw(task: dict, du: np.ndarray, cols: list, nodes: int, period: float, extra: float,
                 scheduler: Scheduler) -> tuple[float, int]:
    """The yaw spread of a tray map (the largest relative change of the pick-to-tray time against
    yaw 0, as :func:`~.task_map_build.build_task_map` measures a box map's): its probe columns planned
    at the probe yaws of a ``nodes`` grid, on the middle ``w`` row only; with the plans it took."""
    probe = np.unique(np.round(np.linspace(0, du.size - 1, PROBE_COLUMNS + 2)).astype(int)[1:-1])
    grid = np.linspace(-period / 2.0, period / 2.0, nodes)
    mid = len(task["w"]) // 2
    row = {**task, "w": [task["w"][mid]]}
    worst, plans = 0.0, 0
    for k in np.unique(np.round(np.asarray(PROBE_YAWS) * (nodes - 1)).astype(int)):
        for i, c in zip(probe, _plan_columns(row, du[probe], grid[k], scheduler, None)):
            at0 = cols[i][0][mid] + cols[i][1][:, mid] + cols[i][2][:, mid] + extra  # (nb, nv) at yaw 0
            there = c[0][0] + c[1][:, 0] + c[2][:, 0] + extra
            plans += c[1][:, 0].size
            with np.errstate(invalid="ignore"):
                rel = np.abs(there - at0) / at0
            if np.isfinite(rel).any():
                worst = max(worst, float(np.nanmax(rel)))
    return worst, plans


def build_tray_map(request: TrayMapRequest, *, scheduler: Scheduler = None,
                   progress: Callable[[int, int], None] | None = None) -> MapResult:
    """Plan picks placed in trays exactly on the request's ``nu`` × ``nw`` × ``nv`` grid (module doc);
    ``du`` and ``dv`` span the arm's sampled workspace over each belt (or the ranges given [m]).
    ``approach_map``: the same station's box :class:`TaskMap` whose finer grid then gives t_A.
    ``cell``, ``clearance``: the whole pick-to-tray trajectory kept ``clearance`` [m] from the cell's
    fixtures (``TrayMap.fixture_infeasible``, ``MapResult.blocked``). The item's yaw: with ``yaw="auto"``
    and an arm that can turn its tool, the yaw spread is measured (:func:`_measure_yaw`) and stored
    (``TrayMap.yaw_spread``; above :data:`~.task_maps.YAW_TOLERANCE` its :meth:`TrayMap.warnings`
    say so, and ``run_line`` puts that in its result); ``"none"``: not measured.
    ``scheduler``, ``progress(done, total)``: as :func:`~.task_map_build.build_task_map`'s (``du``
    columns planned).

    Returns:
        :class:`~.map_request.MapResult`: the ``TrayMap``; status ``built`` or ``no feasible node``.

    Raises:
        BeltOutOfReach: the arm reaches no point of the item belt or of the tray belt (names the arm).
        InvalidInput: not a :class:`~.map_request.TrayMapRequest`.
    """
    if not isinstance(request, TrayMapRequest):
        raise InvalidInput(f"build_tray_map takes a TrayMapRequest (optim.line.TrayMapRequest), got "
                           f"{type(request).__name__}")
    rq, station, belt, trays, spec = request, request.station, request.belt, request.trays, request.spec
    check_reach(station, belt, rq.item_height)
    check_reach(station, trays.belt, trays.height)
    q_rest = rest_configuration(station)
    start = time.perf_counter()
    lo, hi = belt_span(station, belt) if rq.du_range is None else rq.du_range
    vlo, vhi = belt_span(station, trays.belt) if rq.dv_range is None else rq.dv_range
    half = belt.width / 2.0 - rq.margin
    du, w = np.linspace(lo, hi, rq.nu), np.linspace(-half, half, rq.nw)
    v_base = float(trays.belt.to_belt(station.base_to_world[:3, 3])[0])
    dv = _with_home_nodes(np.linspace(vlo, vhi, rq.nv), station, trays, spec, v_base)
    vv, zz = np.meshgrid(v_base + dv, np.linspace(-trays.belt.width / 2.0, trays.belt.width / 2.0, 3), indexing="ij")
    labels = ik_branch_labels(station, trays.belt.to_world(vv.ravel(), zz.ravel(), trays.height + spec.lift))
    task = {"station": station, "belt": belt, "trays": trays, "spec": spec, "w": w.tolist(), "dv": dv.tolist(),
            "mass": rq.mass, "height": rq.item_height, "seed": 0, "branches": labels, "cell": rq.cell,
            "clearance": rq.clearance, "q_rest": q_rest, "key": map_key()}
    place = spec.descend + spec.release + spec.descend
    with scheduler_session(scheduler) as held:
        cols = _plan_columns(task, du, 0.0, held, progress)
        spread, probes = float("nan"), 0
        if rq.yaw == "auto":
            spread, probes = ((0.0, 0) if not can_yaw(station.robot) else
                              _measure_yaw(task, du, cols, rq.yaw_nodes, spec.yaw_period, spec.track_time + place,
                                           held))
    A, P = np.stack([c[0] for c in cols]), np.stack([c[3] for c in cols])
    X, R = (np.stack([c[n] for c in cols], axis=1) for n in (1, 2))
    blocked = sum(c[4] for c in cols)
    seconds = time.perf_counter() - start
    m = TrayMap(station.name, du, w, dv, A, X, R, spec.track_time, place, belt.speed, trays.belt.speed,
                float(rq.mass), seconds, labels, P, rq.approach_map, blocked, yaw_spread=spread,
                yaw_period=spec.yaw_period)
    plans = int(np.isfinite(A).sum() + X.size) + probes
    if not np.isfinite(A[None, :, :, None] + X + R).any():
        return MapResult(MapStatus.NO_FEASIBLE, "no node of the grid places an item in a tray: move the arm, its "
                         "trays or widen du_range / dv_range", m, plans, blocked, seconds)
    return MapResult(MapStatus.BUILT, "", m, plans, blocked, seconds)


def tray_map_error(tray_map: TrayMap, station: Station, belt: Belt, trays: TrayBelt,
                   spec: TrackingSpec = TrackingSpec(), *, n: int = 30, item_height: float = 0.04,
                   seed: int = 0) -> MapError:
    """Interpolated vs exact task time (pick to tray) at ``n`` seeded random points (du, w, dv)
    where the map says feasible; ``points`` (n, 3)."""
    rng = np.random.default_rng(seed)
    u_base = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    v_base = float(trays.belt.to_belt(station.base_to_world[:3, 3])[0])
    q_rest = rest_configuration(station)
    rel, pts, tries, start = [], [], 0, time.perf_counter()
    m = tray_map
    while len(rel) < n and tries < 50 * n:
        tries += 1
        du, w, dv = (rng.uniform(g[0], g[-1]) for g in (m.du, m.w, m.dv))
        tA, tX, tR = m.times(du, w, dv)
        if not np.isfinite(tA + tX + tR):
            continue
        try:
            p = plan_pick_to_tray(station, belt, trays, spec, u_base + du, w, v_base + dv, item_height=item_height,
                                  mass=m.mass, q_rest=q_rest, place_branch=m.branch_at(du, w, dv))
        except PinarmsError:
            continue
        approx = float(tA + tX + tR) + m.track + m.place
        rel.append(abs(approx - p.duration) / p.duration)
        pts.append((du, w, dv))
    return MapError(np.array(rel), np.array(pts).reshape(-1, 3), time.perf_counter() - start)
