"""Task maps of a delta above the belt: the same :class:`~.task_maps.TaskMap` the simulator reads.

:func:`build_delta_map` plans the delta's pick (:func:`~.delta_tracking.delta_pick_times`) at
every node of a ``nu`` × ``nw`` grid of pre-grasp points: ``du`` along the belt over the span the
delta reaches at the pre-grasp height (the closed-form IK within the motors' range, sampled every
5 mm), ``w`` across the belt less ``margin`` at each edge. One IK branch (the primary: every elbow
outward), so the map has no branch tables.

The item's yaw: the fourth axis turns the tool during the approach and back during the leave,
each taking the longer of the platform's and the tool's time (:func:`~.delta_tracking.tool_turn_time`,
exact, not planned). The spread over yaw (:attr:`TaskMap.yaw_spread`: largest relative change of the
task time against yaw 0 over every node and yaw node) is measured on every node; above
:data:`~.task_maps.YAW_TOLERANCE` the map holds ``yaw_nodes`` yaw layers (linear between them; the
tool time bends where it overtakes the platform's, hence many nodes: they cost nothing to compute).
A delta without the fourth axis grasps at its own yaw: spread 0, no yaw coordinate.
"""

from __future__ import annotations

import time
from typing import Any, Callable

import numpy as np

from pinarms.optim.errors import InfeasibleProblem
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.delta_pick_path import delta_pick_path
from pinarms.optim.line.delta_tracking import DeltaArm, delta_pick_times, tool_turn_time
from pinarms.optim.line.errors import BeltOutOfReach
from pinarms.optim.line.map_request import DeltaMapRequest, MapResult, MapStatus
from pinarms.optim.line.station import Station
from pinarms.optim.line.task_map_error import MapError
from pinarms.optim.line.task_maps import YAW_TOLERANCE, TaskMap
from pinarms.optim.line.tracking import TrackingSpec
from pinarms.robots.delta import inverse_position
from pinarms.errors import InvalidInput

__all__ = ["build_delta_map", "delta_span", "yaw_layers", "delta_map_error"]

_SPAN_STEP = 0.005  # [m] sampling of the reach along the belt


def delta_span(station: Station, belt: Belt, height: float, w: np.ndarray) -> tuple[float, float]:
    """(low, high) [m] of ``du`` (from the base along the belt) where the platform reaches a point at
    ``height`` [m] above the belt at every ``w`` (IK within the motors' range).

    Raises:
        BeltOutOfReach: no such point."""
    arm: DeltaArm = station.robot
    u0 = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    du = np.arange(-2.5, 2.5 + 1e-9, _SPAN_STEP)
    ok = np.ones(du.size, bool)
    lim = arm.delta.limits
    for wi in w:
        p = station.world_to_base(belt.to_world(u0 + du, np.full(du.size, wi), height)) - arm.tcp_offset
        q = inverse_position(arm.delta.geometry, p)
        with np.errstate(invalid="ignore"):
            ok &= np.all(np.isfinite(q) & (q >= lim.lower) & (q <= lim.upper), axis=1)
    if not ok.any():
        raise BeltOutOfReach(f"arm {station.name!r} ({arm.name}) reaches no point {height:.3f} m above the belt across "
                             f"w = {float(w[0]):.3f} .. {float(w[-1]):.3f} m: lower its base or bring it over the belt")
    idx = np.flatnonzero(ok)
    return float(du[idx[0]]), float(du[idx[-1]])


def yaw_layers(arm: DeltaArm, approach: np.ndarray, leave: np.ndarray, yaw: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """(ny, nu, nw) approach and leave times at each tool yaw: the longer of the platform's and the
    fourth axis' (module doc)."""
    v, a = float(arm.velocity_limit[3]), float(arm.acceleration_limit[3])
    turn = np.array([tool_turn_time(y, v, a) for y in yaw])[:, None, None]
    return np.maximum(approach[None], turn), np.maximum(leave[None], turn)


def build_delta_map(request: DeltaMapRequest, *, progress: Callable[[int, int], None] | None = None) -> MapResult:
    """The delta's task map (module doc); the request's ``n`` TOPP grid intervals per move;
    ``progress(done, total)`` after each du column.

    Returns:
        :class:`~.map_request.MapResult`: the ``TaskMap``, status ``built`` (its plans: the picks timed).

    The request's ``cell``: a :class:`pinarms.robots.cell.Cell` with the station as one of its deltas (same
    name and base): each feasible node's pick path (:func:`~.delta_pick_path.delta_pick_path`) is checked
    continuously against the cell's fixtures at ``clearance`` [m] (its bodies posed from the closed form,
    :meth:`Cell.check_motion`); a pick not proven clear is infeasible (counted in ``TaskMap.fixture_infeasible``
    and ``MapResult.blocked``).

    Raises:
        InvalidInput: not a :class:`~.map_request.DeltaMapRequest`.
        BeltOutOfReach: the delta reaches no pick on the belt."""
    if not isinstance(request, DeltaMapRequest):
        raise InvalidInput(f"build_delta_map takes a DeltaMapRequest (optim.line.DeltaMapRequest), got "
                           f"{type(request).__name__}")
    rq, station, belt, spec = request, request.station, request.belt, request.spec
    mass, item_height, margin, nu, nw, n, yaw_nodes = (rq.mass, rq.item_height, rq.margin, rq.nu, rq.nw, rq.n,
                                                       rq.yaw_nodes)
    half = belt.width / 2.0 - margin
    start = time.perf_counter()
    w = np.linspace(-half, half, nw)
    lo, hi = delta_span(station, belt, item_height + spec.lift, w)
    du = np.linspace(lo, hi, nu)
    u0 = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    A, C = np.full((nu, nw), np.nan), np.full((nu, nw), np.nan)
    clearance = rq.clearance
    fixtures = _fixture_view(rq.cell, station, clearance)
    blocked = 0
    for i, d in enumerate(du):
        for j, wj in enumerate(w):
            try:
                A[i, j], C[i, j] = delta_pick_times(station, belt, spec, u0 + d, wj, mass=mass,
                                                    item_height=item_height, n=n)
            except InfeasibleProblem:
                continue
            if fixtures is not None:
                path = delta_pick_path(station, belt, spec, u0 + d, wj, item_height=item_height)
                if not fixtures.check_motion({station.name: path}, margin=clearance, clearance=clearance).clear:
                    A[i, j] = C[i, j] = np.nan
                    blocked += 1
        if progress is not None:
            progress(i + 1, nu)
    if not np.isfinite(A).any():
        why = f"; {blocked} meet the cell's fixtures" if blocked else ""
        raise BeltOutOfReach(f"arm {station.name!r}: no pick on the belt is feasible at {belt.speed} m/s{why} "
                             f"(slow the belt or lengthen the tracking's descend, or move the fixtures)")
    extra = spec.track_time + spec.release
    fields: dict[str, Any] = {"yaw_spread": 0.0}
    if station.robot.can_yaw:
        yaw = np.linspace(-spec.yaw_period / 2.0, spec.yaw_period / 2.0, yaw_nodes)
        yaw[yaw_nodes // 2] = 0.0
        YA, YC = yaw_layers(station.robot, A, C, yaw)
        with np.errstate(invalid="ignore"):
            rel = np.abs(YA + YC - A - C) / (A + C + extra)
        spread = float(np.nanmax(rel)) if np.isfinite(rel).any() else 0.0
        fields = {"yaw_spread": spread}
        if spread > YAW_TOLERANCE:
            fields.update(yaw=yaw, yaw_approach=YA[:, None], yaw_leave=YC[:, None])
    seconds = time.perf_counter() - start
    m = TaskMap(station.name, du, w, A, C, spec.track_time, spec.release, belt.speed, float(mass), seconds,
                yaw_period=spec.yaw_period, fixture_infeasible=blocked, **fields)
    return MapResult(MapStatus.BUILT, "", m, nu * nw, blocked, seconds)


def _fixture_view(cell: Any, station: Station, clearance: float) -> Any:
    """The cell seen with its arm–fixture pairs only (None without a cell); InvalidInput unless the station is one
    of its deltas, or the clearance is not a length > 0."""
    if cell is None:
        return None
    from pinarms.optim.line.fixtures import check_in_cell

    check_in_cell(cell, station)
    if station.name not in {d.name for d in cell.deltas}:
        raise InvalidInput(f"station {station.name!r} is not a delta of cell {cell.name!r}: place it in the cell "
                           "description with delta = \"<name>\"")
    if not (isinstance(clearance, (int, float)) and np.isfinite(clearance) and clearance > 0.0):
        raise InvalidInput(f"clearance to the fixtures must be a finite length > 0 [m], got {clearance!r}")
    return cell.with_pairs("arm-fixture")


def delta_map_error(task_map: TaskMap, station: Station, belt: Belt, spec: TrackingSpec = TrackingSpec(), *,
                    n: int = 30, item_height: float = 0.04, seed: int = 0, grid: int = 24) -> MapError:
    """The map against exact timing (:func:`~.delta_tracking.delta_pick_times` with ``grid`` TOPP intervals,
    the tool's turn exact) at ``n`` seeded random feasible points, each item at a random yaw (as
    :func:`~.task_map_error.map_error` does for serial arms)."""
    rng = np.random.default_rng(seed)
    arm: DeltaArm = station.robot
    u0 = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    period = spec.yaw_period
    rel, pts, yaws = [], [], []
    start = time.perf_counter()
    for _ in range(50 * n):
        if len(rel) >= n:
            break
        du, w = rng.uniform(task_map.du[0], task_map.du[-1]), rng.uniform(task_map.w[0], task_map.w[-1])
        yaw = rng.uniform(-np.pi, np.pi)
        tA, tC = task_map.times(du, w, yaw)
        if not (np.isfinite(tA) and np.isfinite(tC)):
            continue
        try:
            a, c = delta_pick_times(station, belt, spec, u0 + du, w, mass=task_map.mass, item_height=item_height,
                                    n=grid)
        except InfeasibleProblem:
            continue
        tool = (yaw + period / 2.0) % period - period / 2.0 if arm.can_yaw else 0.0
        if arm.can_yaw:
            turn = tool_turn_time(tool, float(arm.velocity_limit[3]), float(arm.acceleration_limit[3]))
            a, c = max(a, turn), max(c, turn)
        exact = a + c + task_map.track + task_map.release
        rel.append(abs(float(tA + tC) + task_map.track + task_map.release - exact) / exact)
        pts.append((du, w))
        yaws.append(tool)
    return MapError(np.array(rel), np.array(pts).reshape(-1, 2), time.perf_counter() - start, np.array(yaws), period)
