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

Units: m, rad, s; yaw about the line frame's vertical axis (the base stands upright).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from pinarms.optim.caps import (MAX_CLEARANCE, MAX_PLACEMENTS, MAX_POINT_PAIRS, MAX_REFINE,
                               MAX_REFINE_EVALUATIONS, MAX_WORKSPACE_SAMPLES, count_setting, number_setting)
from pinarms.optim.cycle import CYCLE_KINDS, PickPlace
from pinarms.optim.errors import InvalidSettings, SettingOutOfRange
from pinarms.errors import InvalidInput

from pinarms.optim.layout.candidates import (_PPM_RTOL, AXES, FAILURES, _rot_z, base_to_world, grid_candidates,
                         points_in_base_frame, random_candidates)
from pinarms.optim.layout.evaluate import (_CELLS, _CellRecipe, _ChunkTask, _Clock, _evaluate, _evaluate_chunk, _RefineTask, _refine,
                       _Settings)
from pinarms.optim.layout.result import LayoutSearch, Refinement

__all__ = [
    "FAILURES",
    "LayoutSearch",
    "Refinement",
    "grid_candidates",
    "random_candidates",
    "base_to_world",
    "points_in_base_frame",
    "search_layout",
]


# ------------------------------------------------------------------------ search
def _points(value: Any, what: str) -> np.ndarray:
    try:
        P = np.atleast_2d(np.asarray(value, dtype=float))
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be points (3,) or (N, 3) in m, got {value!r}") from exc
    if P.ndim != 2 or P.shape[1] != 3 or P.shape[0] == 0:
        raise InvalidInput(f"{what} must be points (3,) or (N, 3) in m, got shape {np.shape(value)}")
    if not np.all(np.isfinite(P)):
        raise InvalidInput(f"{what} holds NaN or inf")
    return P


def _screen(robot: Any, cand: np.ndarray, st: _Settings) -> tuple[list[str], list[str], np.ndarray | None]:
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
        T[:, :, :3, :3] = np.einsum("mij,jk->mik", np.stack([_rot_z(-y) for y in cand[:, 3]]), st.orientation)[:, None]
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

    order = argsort_tied(-ppm, rtol=_PPM_RTOL)
    out, i = [], 0
    while i < order.size:
        j = i + 1
        ref = -ppm[order[i]]
        while j < order.size and -ppm[order[j]] <= ref + _PPM_RTOL * abs(ref) + 1e-12:
            j += 1
        run = sorted(order[i:j].tolist(), key=lambda k: (-margin[k], k))
        out.extend(run)
        i = j
    return np.asarray(out, dtype=np.intp)


def _cell_target(robot: Any, arm: str | None, clearance: float, carry: tuple[str, ...],
                 token: str) -> tuple[Any, "_CellRecipe | None"]:
    """The arm to place and, when ``robot`` is a cell, the recipe its workers rebuild the cell from."""
    if hasattr(robot, "arms") and hasattr(robot, "with_arm_base"):  # a cell
        cell = robot
        if arm is None:
            if len(cell.arms) != 1:
                raise InvalidInput(f"cell {cell.name!r} has arms {[a.name for a in cell.arms]}: name the one to place (arm=)")
            arm = cell.arms[0].name
        robot = cell.arm(arm).robot
        number_setting(clearance, "clearance", 0.0, MAX_CLEARANCE, unit="m")
        for name in carry:
            cell.fixture(name)
        recipe = _CellRecipe(token, cell.urdf_text, cell.source, str(cell.base_dir),
                             tuple(sorted((k, str(v)) for k, v in cell.packages.items())),
                             tuple(sorted((k, str(v)) for k, v in cell.args.items())), int(cell.seed), str(arm),
                             tuple(carry), float(clearance), tuple(cell.arm_placements))
        _CELLS[token] = cell  # this process uses the caller's cell; workers rebuild it from the recipe
        return robot, recipe
    if arm is not None or carry:
        raise InvalidInput("arm= and carry= name an arm and fixtures of a cell: pass the cell as the first argument")
    return robot, None


def _checked_inputs(picks: Any, places: Any, candidates: Any, kind: str, counts: dict[str, int],
                    orientation: Any, lift: float, dwell: float,
                    min_margin: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """Points, candidates, orientation and counts of a search, checked before any work (:mod:`pinarms.optim.caps`)."""
    picks_w, places_w = _points(picks, "picks"), _points(places, "places")
    cand = np.asarray(candidates, dtype=float) if not isinstance(candidates, str) else np.zeros(0)
    if cand.ndim != 2 or cand.shape[1] != 4 or cand.shape[0] == 0 or not np.all(np.isfinite(cand)):
        raise InvalidInput(f"candidates must be finite placements (M, 4) = (x, y, z, yaw) [m, rad], got shape {cand.shape}")
    if kind not in CYCLE_KINDS:
        raise InvalidSettings(f"kind={kind!r}: use one of {CYCLE_KINDS}")
    if cand.shape[0] > MAX_PLACEMENTS:
        raise SettingOutOfRange(f"{cand.shape[0]:,} candidates, more than the {MAX_PLACEMENTS:,} a layout search takes")
    if len(picks_w) * len(places_w) > MAX_POINT_PAIRS:
        raise SettingOutOfRange(f"{len(picks_w)} picks × {len(places_w)} places = {len(picks_w) * len(places_w):,} "
                                f"cycles per placement, more than the {MAX_POINT_PAIRS:,} allowed: give fewer points")
    for name, least, most in (("refine", 0, MAX_REFINE), ("refine_evaluations", 1, MAX_REFINE_EVALUATIONS),
                              ("workspace_samples", 1000, MAX_WORKSPACE_SAMPLES),
                              ("chunk_size", 1, MAX_PLACEMENTS), ("seed", 0, 2**64 - 1)):
        count_setting(counts[name], name, least, most)
    R = None
    if orientation is not None:
        R = np.asarray(orientation, dtype=float)
        if R.shape != (3, 3) or not np.all(np.isfinite(R)) or np.abs(R @ R.T - np.eye(3)).max() > 1e-6 \
                or np.linalg.det(R) < 0:
            raise InvalidInput(f"orientation must be a (3, 3) proper rotation matrix, got {orientation!r}")
    PickPlace(picks_w[0], places_w[0], lift=lift, dwell=dwell)  # checks lift and dwell (names them)
    number_setting(min_margin, "min_margin", 0.0, unit="m")
    return picks_w, places_w, cand, R


def _margins(robot: Any, st: _Settings, cand: np.ndarray, samples: int) -> tuple[Any, np.ndarray]:
    """The workspace's voxel map and the boundary margin of every pick and place (M, P + Q) [m] from each candidate."""
    from pinarms.robots.reach.workspace import sample_workspace

    ws = sample_workspace(robot, int(samples), seed=int(st.seed), frame="tcp")
    vmap = ws.voxel_map()
    pts = points_in_base_frame(np.vstack([st.picks, st.places]), cand)
    return vmap, vmap.query(pts.reshape(-1, 3)).margin.reshape(cand.shape[0], -1)


def _boundary_failures(failure: list[str], reason: list[str], point_margin: np.ndarray, st: _Settings,
                       min_margin: float) -> None:
    """Mark the candidates still in the running with a point closer than ``min_margin`` to the edge ``"boundary"``."""
    margin = point_margin.min(axis=1)
    names = [f"pick {i + 1}" for i in range(len(st.picks))] + [f"place {j + 1}" for j in range(len(st.places))]
    for m in np.flatnonzero((margin < min_margin) & np.array([not f for f in failure])):
        k = int(np.argmin(point_margin[m]))
        failure[m] = "boundary"
        reason[m] = (f"{names[k]} is {point_margin[m, k] * 1e3:.0f} mm from the edge of the workspace, "
                     f"less than min_margin {min_margin * 1e3:.0f} mm")


def _plan_candidates(robot: Any, token: str, cand: np.ndarray, st: _Settings, failure: list[str], reason: list[str],
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
        tasks = [_ChunkTask(robot, token, cand[wave[s : s + chunk_size]], st) for s in range(0, len(wave), chunk_size)]
        step = None if progress is None else (lambda d, _t, o=done: progress(o + d, n_tasks))
        chunks = map_chunks(_evaluate_chunk, tasks, scheduler=scheduler, progress=step)
        done += len(tasks)
        for m, o in zip(wave, (o for chunk in chunks for o in chunk)):
            failure[m], reason[m] = o.failure, o.reason
            if not o.failure:
                cycle_time[m], branch[m], manip[m] = o.cycle_time, o.branch, o.manipulability
                times.append(float(o.cycle_time))
    return cycle_time, branch, manip


def _refine_best(robot: Any, token: str, cand: np.ndarray, st: _Settings, ppm: np.ndarray, ok: np.ndarray,
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
    rtasks = [_RefineTask(robot, token, cand[i].copy(), free, bounds, step, int(evaluations), st) for i in starts]
    found = map_chunks(_refine, rtasks, scheduler=scheduler, progress=progress)
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
    if np.isfinite(eligible[k]) and eligible[k] > best_ppm * (1.0 + _PPM_RTOL):
        best_placement, best_ppm = refinement.placements[k].copy(), float(refinement.picks_per_minute[k])
    return refinement, best_placement, best_ppm


def _lower_bounds(robot: Any, st: _Settings, targets: np.ndarray | None, M: int) -> np.ndarray:
    """Each candidate's lower bound of its cycle time [s] (:mod:`.bound`; 0 without a closed form)."""
    from pinarms.optim.layout.bound import cycle_lower_bounds

    if targets is None:
        return np.zeros(M)
    return cycle_lower_bounds(robot, targets[:, : len(st.picks) + len(st.places)], len(st.picks), st.dwell, st.vmax)


def _phase(progress: Callable[[int, int], None] | None, offset: int, total: int) -> Any:
    """The progress callback of one phase of the search (tasks counted from ``offset`` of ``total``), or None."""
    if progress is None:
        return None
    return lambda done, _total: progress(offset + done, total)


def search_layout(robot: Any, picks: Any, places: Any, candidates: Any, *, lift: float = 0.05, dwell: float = 0.2,
                  orientation: Any = None, kind: str = "multi-quintic", vmax: Any = None, amax: Any = None,
                  jmax: Any = None, refine: int = 2, refine_evaluations: int = 30, workspace_samples: int = 200_000,
                  seed: int = 0, chunk_size: int = 4, scheduler: Any = None,
                  progress: Callable[[int, int], None] | None = None, arm: str | None = None,
                  clearance: float = 0.02, carry: tuple[str, ...] = (), min_margin: float = 0.0,
                  screen: bool = True, bound: bool = False) -> LayoutSearch:
    """Rank base placements of ``robot`` by the picks per minute of its pick-and-place cycle.

    Args:
        robot: a :class:`pinarms.robots.Robot` (the arm to place), or a :class:`pinarms.robots.cell.Cell`:
            then the arm ``arm`` of the cell (its only arm by default) is moved among the
            cell's fixtures (the line frame is the cell's world; :meth:`Cell.with_arm_base`,
            the fixtures named in ``carry``, e.g. its stand, move with it) and every cycle
            must keep ``clearance`` [m] from the fixtures and the other arms
            (:func:`pinarms.optim.plan_cycle` with ``cell=``: re-planned with a higher lift or via
            points when needed); a candidate whose cycle cannot clear fails as ``"collision"``.
            ``screen``: each re-planning attempt is first screened by exact distances at its
            via points and a few timed states (:class:`pinarms.optim.CellSettings`; proofs of failure
            only, so the same verdicts; ``False``: every attempt timed and checked in full).
        picks, places: points ``(3,)`` or ``(N, 3)`` in the line frame [m]; every pick is
            paired with every place.
        candidates: placements ``(M, 4)`` ``(x, y, z, yaw)`` of the base in the line frame
            [m, rad] (:func:`grid_candidates`, :func:`random_candidates`).
        lift, dwell, kind, vmax, amax, jmax: the cycle (see :class:`pinarms.optim.PickPlace` and
            :func:`pinarms.optim.plan_cycle`).
        orientation: tool orientation ``(3, 3)`` in the line frame at the points; default
            the robot's (tool down for six-axis arms), in its base frame.
        min_margin: smallest boundary margin [m] a pick or place may have; candidates below
            fail as ``"boundary"`` before any cycle is planned (0: no such rule). The fastest
            cycles are often near the edge of the workspace, where the arm is stretched.
        refine: how many of the best candidates start a continuous search (0: none).
        refine_evaluations: cycles each continuous search may plan.
        workspace_samples: samples of the workspace whose voxel map gives the boundary margins.
        seed: seed of the workspace samples and of the timing optimiser (results repeat).
        chunk_size: candidates per task (a task plans ``chunk_size × pairs`` cycles, ~0.5 s each
            for a six-axis arm).
        scheduler, progress: see :func:`pinarms.execution.map_chunks` (progress counts the
            candidate tasks, then the refinement tasks).
        bound: branch and bound (:mod:`pinarms.optim.layout.bound`): the candidates are planned in
            increasing order of a proven lower bound of their cycle time, and those that cannot
            reach the first ``max(1, refine)`` places of the ranking are not planned (they fail
            as ``"outranked"``): the best placement, the refinement starts and every planned
            candidate's outcome are those of the exhaustive search (``False``, default).

    Raises:
        InvalidInput: malformed points, candidates, orientation or counts.
        InvalidSettings: unknown ``kind``.
        ExecutionError: a task failed on the scheduler (chunk index named).
    """
    import uuid

    token = uuid.uuid4().hex
    robot, recipe = _cell_target(robot, arm, clearance, carry, token)
    counts = {"refine": refine, "refine_evaluations": refine_evaluations, "workspace_samples": workspace_samples,
              "chunk_size": chunk_size, "seed": seed}
    picks_w, places_w, cand, R = _checked_inputs(picks, places, candidates, kind, counts, orientation, lift, dwell,
                                                 min_margin)
    st = _Settings(picks_w, places_w, R, float(lift), float(dwell), kind, vmax, amax, jmax, int(seed), recipe,
                   bool(screen))

    clock = _Clock()
    failure, reason, targets = _screen(robot, cand, st)
    lower = _lower_bounds(robot, st, targets, cand.shape[0]) if bound else None
    vmap, point_margin = _margins(robot, st, cand, workspace_samples)
    margin = point_margin.min(axis=1)
    if min_margin > 0:
        _boundary_failures(failure, reason, point_margin, st, min_margin)
    plan_chunk = 1 if bound and scheduler in (None, "serial") else chunk_size  # serial: a bound checked per candidate
    n_tasks = -(-sum(1 for f in failure if not f) // plan_chunk)
    total = n_tasks + int(refine)
    clock.lap("screen")

    cycle_time, branch, manip = _plan_candidates(robot, token, cand, st, failure, reason, plan_chunk, scheduler,
                                                 _phase(progress, 0, total), lower, max(1, int(refine)))
    clock.lap("cycles")
    ok = np.array([f == "" for f in failure])
    ppm = np.where(ok, 60.0 / np.where(ok, cycle_time, 1.0), 0.0)
    order = _ranking(ppm, margin)
    refinement, best_placement, best_ppm = _refine_best(robot, token, cand, st, ppm, ok, order, int(refine),
                                                        refine_evaluations, vmap, min_margin, scheduler,
                                                        _phase(progress, n_tasks, total))
    clock.lap("refine")
    best_cycle = None
    if best_placement is not None:
        best_cycle = _evaluate(robot, best_placement, st, keep_cycle=True)[1]
    clock.lap("best")
    return LayoutSearch(robot=str(robot.name), picks=picks_w, places=places_w, candidates=cand, failure=tuple(failure),
                        reason=tuple(reason), cycle_time=cycle_time, picks_per_minute=ppm, branch=branch,
                        manipulability=manip, margin=margin, order=order, refinement=refinement,
                        best_placement=best_placement, best_picks_per_minute=best_ppm, best_cycle=best_cycle,
                        seed=int(seed), lower_bound=lower, seconds=clock.laps)
