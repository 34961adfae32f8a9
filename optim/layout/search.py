"""Where to bolt the arm: a search over base placements for the most picks per minute.

A line engineer has pick points (a conveyor segment) and place points (a crate), fixed in
the **line frame** (world, m), and asks where to put the arm. :func:`search_layout` takes
candidate base placements ``(x, y, z, yaw)`` of the arm's base frame in the line frame
(:func:`grid_candidates`, :func:`random_candidates`) and, for each:

1. moves the points into the base frame (``p_base = R_z(-yaw) (p - t)``) and screens every
   waypoint of the cycle (each pick and place, and the lift points above them) with one
   batched closed-form IK over all candidates: a candidate with a point beyond reach is
   ``"unreachable"``, one whose point is within reach but needs a joint outside its limits
   is ``"joint limit"`` (both named with the point);
2. plans the time-optimal cycle (:func:`pinarms.optim.plan_cycle`, ``method="exact"``) of every
   (pick, place) pair: IK branch, moves, dwells; ``picks_per_minute = 60 / mean cycle time``
   over the pairs (a line cycling through them); a failing plan is classified the same way
   (``"timing"`` when no timing meets the limits); with ``bound=True`` in increasing order of a
   proven lower bound of the cycle time, skipping those that cannot reach the top of the
   ranking (:mod:`.bound`, branch and bound: they fail as ``"outranked"``);
3. reports the position manipulability at the picks and places (the cycle's own joint
   values, smallest over the points) and the boundary margin (distance of the points to
   the edge of the arm's sampled workspace, smallest over the points; one voxel map serves
   every candidate, since a placement only moves the points in the base frame).

Candidates are ranked by picks/min (larger first; values within 1e-9 relative of each other
tie), then by boundary margin (larger first), then by index. Then the best ``refine``
candidates are improved by a bounded Nelder-Mead search over the free coordinates of the
placement (those the candidates vary), each start one task; the gain is reported.

The cycles run through :func:`pinarms.execution.map_chunks` (``scheduler``: serial, local
processes or a Dask cluster): results are identical whoever runs them (the plans are
deterministic and every task is a pure function of its candidates).

One input, one result (:mod:`pinarms.optim.status`): :func:`search_layout` takes a
:class:`LayoutRequest` (checked when built: bad input raises there, naming the field) and
returns a :class:`LayoutSearch` whose ``status`` is :attr:`LayoutStatus.FOUND` or, when every
candidate failed, :attr:`LayoutStatus.NO_PLACEMENT` with a ``status_reason``; per candidate,
``failure`` is a :class:`CandidateFailure` (None where the cycle was planned).

Units: m, rad, s; yaw about the line frame's vertical axis (the base stands upright).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from pinarms.optim.layout.candidates import (PPM_RTOL, AXES, FAILURES, CandidateFailure, base_to_world, grid_candidates,
                         points_in_base_frame, random_candidates)
from pinarms.optim.layout.evaluate import (CellRecipe, ChunkTask, EvaluationSettings, PhaseClock, RefineTask, evaluate_chunk,
                                           evaluate_placement, keep_cell, refine_placement)
from pinarms.optim.layout.request import LayoutRequest, LayoutStatus, is_cell
from pinarms.optim.layout.result import LayoutSearch, Refinement
from pinarms.robots.so3 import rot_z

if TYPE_CHECKING:
    from pinarms.execution import Scheduler
    from pinarms.robots.robot import Robot

__all__ = [
    "FAILURES",
    "CandidateFailure",
    "LayoutRequest",
    "LayoutStatus",
    "LayoutSearch",
    "Refinement",
    "grid_candidates",
    "random_candidates",
    "base_to_world",
    "points_in_base_frame",
    "search_layout",
]


# ------------------------------------------------------------------------ search
def _screen(robot: Robot, cand: np.ndarray, st: EvaluationSettings) -> tuple[list[str], list[str], np.ndarray | None]:
    """Batched closed-form IK of every waypoint from every placement: failure and reason per candidate,
    and the tcp poses ``(M, K, 4, 4)`` of the picks, places and lift points in each base frame (None
    without a closed form)."""
    from pinarms.robots.reach.layout import default_orientation

    M = cand.shape[0]
    failure, reason = [""] * M, [""] * M
    if not getattr(robot, "has_analytic_ik", False):
        return failure, reason, None  # numerical IK: each cycle plan finds and names the problem
    names = [f"pick {i + 1}" for i in range(len(st.picks))] + [f"place {j + 1}" for j in range(len(st.places))]
    pts = np.vstack([st.picks, st.places])
    up = pts + [0.0, 0.0, st.lift]
    names = names + [f"above {n}" for n in names]  # the user's points first, then the lift points
    world = np.vstack([pts, up])
    K = world.shape[0]
    P = points_in_base_frame(world, cand)  # (M, K, 3)
    T = np.zeros((M, K, 4, 4))
    if st.orientation is None:
        T[:, :, :3, :3] = default_orientation(robot)
    else:
        T[:, :, :3, :3] = np.einsum("mij,jk->mik", np.stack([rot_z(-y) for y in cand[:, 3]]), st.orientation)[:, None]
    T[:, :, :3, 3] = P
    T[:, :, 3, 3] = 1.0
    flat = T.reshape(M * K, 4, 4)
    sols = robot.ik_all(flat)
    has = np.array([np.shape(s)[0] > 0 for s in sols]).reshape(M, K)
    bad = np.flatnonzero(~has.all(axis=1))
    if bad.size:
        missing = [(m, int(np.flatnonzero(~has[m])[0])) for m in bad]
        free = robot.ik_all(np.stack([T[m, k] for m, k in missing]), respect_limits=False)
        for (m, k), f in zip(missing, free):
            at = "({:.3f}, {:.3f}, {:.3f}) m".format(*world[k])
            if np.shape(f)[0]:
                failure[m] = "joint limit"
                why = robot.ik_failure_reason(T[m, k]) or "needs a joint outside its limits"
                reason[m] = f"{names[k]} {at}: {why}"
            else:
                failure[m] = "unreachable"
                reason[m] = f"{names[k]} {at}: beyond the arm's reach from this placement (no IK solution even without joint limits)"
    return failure, reason, T


def _ranking(ppm: np.ndarray, margin: np.ndarray) -> np.ndarray:
    """Picks/min descending (1e-9 relative ties), then margin descending, then index; failures last."""
    from pinarms.robots.ties import argsort_tied

    order = argsort_tied(-ppm, rtol=PPM_RTOL)
    out, i = [], 0
    while i < order.size:
        j = i + 1
        ref = -ppm[order[i]]
        while j < order.size and -ppm[order[j]] <= ref + PPM_RTOL * abs(ref) + 1e-12:
            j += 1
        run = sorted(order[i:j].tolist(), key=lambda k: (-margin[k], k))
        out.extend(run)
        i = j
    return np.asarray(out, dtype=np.intp)


def _cell_recipe(request: LayoutRequest, token: str) -> "CellRecipe | None":
    """When ``request.robot`` is a cell, the recipe its workers rebuild the cell from (None for a robot)."""
    if not is_cell(request.robot):
        return None
    cell = request.robot
    recipe = CellRecipe(token, cell.urdf_text, cell.source, str(cell.base_dir),
                         tuple(sorted((k, str(v)) for k, v in cell.packages.items())),
                         tuple(sorted((k, str(v)) for k, v in cell.args.items())), int(cell.seed), str(request.arm),
                         tuple(request.carry), float(request.clearance), tuple(cell.arm_placements))
    keep_cell(token, cell)  # this process uses the caller's cell; workers rebuild it from the recipe
    return recipe


def _margins(robot: Any, st: EvaluationSettings, cand: np.ndarray, samples: int) -> tuple[Any, np.ndarray]:
    """The workspace's voxel map and the boundary margin of every pick and place (M, P + Q) [m] from each candidate."""
    from pinarms.robots.reach.workspace import sample_workspace

    ws = sample_workspace(robot, int(samples), seed=int(st.seed), frame="tcp")
    vmap = ws.voxel_map()
    pts = points_in_base_frame(np.vstack([st.picks, st.places]), cand)
    return vmap, vmap.query(pts.reshape(-1, 3)).margin.reshape(cand.shape[0], -1)


def _boundary_failures(failure: list[str], reason: list[str], point_margin: np.ndarray, st: EvaluationSettings,
                       min_margin: float) -> None:
    """Mark the candidates still in the running with a point closer than ``min_margin`` to the edge ``"boundary"``."""
    margin = point_margin.min(axis=1)
    names = [f"pick {i + 1}" for i in range(len(st.picks))] + [f"place {j + 1}" for j in range(len(st.places))]
    for m in np.flatnonzero((margin < min_margin) & np.array([not f for f in failure])):
        k = int(np.argmin(point_margin[m]))
        failure[m] = "boundary"
        reason[m] = (f"{names[k]} is {point_margin[m, k] * 1e3:.0f} mm from the edge of the workspace, "
                     f"less than min_margin {min_margin * 1e3:.0f} mm")


def _plan_candidates(robot: Any, token: str, cand: np.ndarray, st: EvaluationSettings, failure: list[str], reason: list[str],
                     chunk_size: int, scheduler: Any, progress: Any,
                     lower: np.ndarray | None = None, keep: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Plan the cycles of every candidate still in the running, in tasks of ``chunk_size``; record the failures.

    ``lower``: each candidate's lower bound [s]: branch and bound (:mod:`.bound`), the ``keep``
    best kept. Returns (M,) mean cycle time [s], IK branch and manipulability (NaN, -1 where it failed).
    """
    from pinarms.execution import map_chunks

    from pinarms.optim.layout.bound import SLACK, outranked, threshold, wave_size

    M = cand.shape[0]
    todo = [m for m in range(M) if not failure[m]]
    cycle_time = np.full(M, np.nan)
    branch = np.full(M, -1)
    manip = np.full(M, np.nan)
    n_tasks = -(-len(todo) // chunk_size)
    size = len(todo) if lower is None else wave_size(scheduler, chunk_size) or len(todo)
    if lower is not None:
        todo.sort(key=lambda m: (lower[m], m))
    times: list[float] = []
    done, i = 0, 0
    while i < len(todo):
        limit = threshold(times, keep)
        wave = todo[i : i + max(size, 1)]
        if lower is not None:  # sorted: the first that cannot win ends the wave, and the search
            wave = wave[: next((k for k, m in enumerate(wave) if lower[m] > limit * (1.0 + SLACK)), len(wave))]
        if not wave:
            for m in todo[i:]:
                failure[m], reason[m] = "outranked", outranked(float(lower[m]), limit, keep)
            if progress is not None:
                progress(n_tasks, n_tasks)
            break
        i += len(wave)
        tasks = [ChunkTask(robot, token, cand[wave[s : s + chunk_size]], st) for s in range(0, len(wave), chunk_size)]
        step = None if progress is None else (lambda d, _t, o=done: progress(o + d, n_tasks))
        chunks = map_chunks(evaluate_chunk, tasks, scheduler=scheduler, progress=step)
        done += len(tasks)
        for m, o in zip(wave, (o for chunk in chunks for o in chunk)):
            failure[m], reason[m] = o.failure, o.reason
            if not o.failure:
                cycle_time[m], branch[m], manip[m] = o.cycle_time, o.branch, o.manipulability
                times.append(float(o.cycle_time))
    return cycle_time, branch, manip


def _refine_best(robot: Any, token: str, cand: np.ndarray, st: EvaluationSettings, ppm: np.ndarray, ok: np.ndarray,
                 order: np.ndarray, n_refine: int, evaluations: int, vmap: Any, min_margin: float,
                 scheduler: Any, progress: Any) -> tuple[Refinement | None, np.ndarray | None, float]:
    """Refine the best ``n_refine`` candidates over the free coordinates.

    Returns the :class:`Refinement` (None without one), the best placement (None when every
    candidate failed) and its picks per minute.
    """
    from pinarms.execution import map_chunks

    M = cand.shape[0]
    refinement = None
    best_placement = cand[order[0]].copy() if ok[order[0]] else None
    best_ppm = float(ppm[order[0]])
    free = np.flatnonzero(np.ptp(cand, axis=0) > 0)
    starts = [int(i) for i in order[:n_refine] if ok[i]]
    if not (starts and free.size):
        return refinement, best_placement, best_ppm
    bounds = np.column_stack([cand.min(axis=0), cand.max(axis=0)])
    step = np.ptp(cand, axis=0) / max(2.0, M ** (1.0 / free.size))  # about the grid's spacing
    rtasks = [RefineTask(robot, token, cand[i].copy(), free, bounds, step, int(evaluations), st) for i in starts]
    found = map_chunks(refine_placement, rtasks, scheduler=scheduler, progress=progress)
    refinement = Refinement(
        starts=np.array(starts),
        start_picks_per_minute=ppm[starts],
        placements=np.array([f[0] for f in found]),
        picks_per_minute=np.array([f[1] for f in found]),
        evaluations=np.array([f[2] for f in found]),
        free=tuple(AXES[k] for k in free),
        margin=vmap.query(points_in_base_frame(np.vstack([st.picks, st.places]),
                                               np.array([f[0] for f in found])).reshape(-1, 3))
        .margin.reshape(len(found), -1).min(axis=1),
    )
    eligible = np.where(refinement.margin >= min_margin, refinement.picks_per_minute, -np.inf)
    k = int(np.argmax(eligible))
    if np.isfinite(eligible[k]) and eligible[k] > best_ppm * (1.0 + PPM_RTOL):
        best_placement, best_ppm = refinement.placements[k].copy(), float(refinement.picks_per_minute[k])
    return refinement, best_placement, best_ppm


def _lower_bounds(robot: Any, st: EvaluationSettings, targets: np.ndarray | None, M: int) -> np.ndarray:
    """Each candidate's lower bound of its cycle time [s] (:mod:`.bound`; 0 without a closed form)."""
    from pinarms.optim.layout.bound import cycle_lower_bounds

    if targets is None:
        return np.zeros(M)
    return cycle_lower_bounds(robot, targets[:, : len(st.picks) + len(st.places)], len(st.picks), st.dwell, st.vmax,
                              st.amax)


def _phase(progress: Callable[[int, int], None] | None, offset: int, total: int) -> Any:
    """The progress callback of one phase of the search (tasks counted from ``offset`` of ``total``), or None."""
    if progress is None:
        return None
    return lambda done, _total: progress(offset + done, total)


def search_layout(request: LayoutRequest, *, scheduler: Scheduler = None,
                  progress: Callable[[int, int], None] | None = None) -> LayoutSearch:
    """Rank the base placements of ``request`` by the picks per minute of its pick-and-place cycle.

    Args:
        request: the arm (or cell), points, candidates and cycle (:class:`LayoutRequest`,
            checked when built).
        scheduler, progress: see :func:`pinarms.execution.map_chunks` (progress counts the
            candidate tasks, then the refinement tasks); the result is the same on any scheduler.

    Returns:
        :class:`LayoutSearch`: ``status`` :attr:`LayoutStatus.FOUND` with the best placement, or
        :attr:`LayoutStatus.NO_PLACEMENT` (every candidate failed; ``status_reason`` counts why).

    Raises:
        ExecutionError: a task failed on the scheduler (chunk index named).
    """
    import uuid

    rq = request
    token = uuid.uuid4().hex
    robot = rq.arm_robot
    recipe = _cell_recipe(rq, token)
    cand = rq.candidates
    st = EvaluationSettings(rq.picks, rq.places, rq.orientation, float(rq.lift), float(rq.dwell), rq.kind, rq.vmax, rq.amax,
                   rq.jmax, int(rq.seed), recipe, bool(rq.screen))

    clock = PhaseClock()
    failure, reason, targets = _screen(robot, cand, st)
    lower = _lower_bounds(robot, st, targets, cand.shape[0]) if rq.bound else None
    vmap, point_margin = _margins(robot, st, cand, rq.workspace_samples)
    margin = point_margin.min(axis=1)
    if rq.min_margin > 0:
        _boundary_failures(failure, reason, point_margin, st, rq.min_margin)
    plan_chunk = 1 if rq.bound and scheduler in (None, "serial") else rq.chunk_size  # serial: a bound per candidate
    n_tasks = -(-sum(1 for f in failure if not f) // plan_chunk)
    total = n_tasks + int(rq.refine)
    clock.lap("screen")

    cycle_time, branch, manip = _plan_candidates(robot, token, cand, st, failure, reason, plan_chunk, scheduler,
                                                 _phase(progress, 0, total), lower, max(1, int(rq.refine)))
    clock.lap("cycles")
    ok = np.array([f == "" for f in failure])
    ppm = np.where(ok, 60.0 / np.where(ok, cycle_time, 1.0), 0.0)
    order = _ranking(ppm, margin)
    refinement, best_placement, best_ppm = _refine_best(robot, token, cand, st, ppm, ok, order, int(rq.refine),
                                                        rq.refine_evaluations, vmap, rq.min_margin, scheduler,
                                                        _phase(progress, n_tasks, total))
    clock.lap("refine")
    best_cycle = None
    if best_placement is not None:
        best_cycle = evaluate_placement(robot, best_placement, st, keep_cycle=True)[1]
    clock.lap("best")
    failed = tuple(CandidateFailure(f) if f else None for f in failure)
    status, why = LayoutStatus.FOUND, ""
    if best_placement is None:
        counts = {k: sum(f is k for f in failed) for k in CandidateFailure}
        status = LayoutStatus.NO_PLACEMENT
        why = (f"every one of the {cand.shape[0]} candidates failed ("
               + ", ".join(f"{n} {k}" for k, n in counts.items() if n)
               + "): move the candidates nearer the points or relax the cycle")
    return LayoutSearch(robot=str(robot.name), picks=rq.picks, places=rq.places, candidates=cand, failure=failed,
                        reason=tuple(reason), cycle_time=cycle_time, picks_per_minute=ppm, branch=branch,
                        manipulability=manip, margin=margin, order=order, refinement=refinement,
                        best_placement=best_placement, best_picks_per_minute=best_ppm, best_cycle=best_cycle,
                        seed=int(rq.seed), lower_bound=lower, seconds=clock.laps, status=status, status_reason=why)
