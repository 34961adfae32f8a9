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
2. plans the time-optimal cycle (:func:`optim.plan_cycle`, ``method="exact"``) of every
   (pick, place) pair: IK branch, moves, dwells; ``picks_per_minute = 60 / mean cycle time``
   over the pairs (a line cycling through them); a failing plan is classified the same way
   (``"timing"`` when no timing meets the limits);
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

import math
from collections import Counter
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from pinarms.optim.cycle import CYCLE_KINDS, CycleResult, PickPlace, plan_cycle
from pinarms.optim.caps import (MAX_AXIS_VALUES, MAX_CLEARANCE, MAX_PLACEMENTS, MAX_POINT_PAIRS, MAX_REFINE,
                               MAX_REFINE_EVALUATIONS, MAX_WORKSPACE_SAMPLES, count_setting, number_setting)
from pinarms.optim.errors import InfeasibleProblem, InvalidSettings, SettingOutOfRange
from pinarms.robots.errors import InvalidInput, LimitViolation, PinarmsError, UnreachableTarget

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

#: Why a candidate fails, in the order they are checked.
FAILURES = ("unreachable", "joint limit", "boundary", "collision", "timing")
#: Names of the placement coordinates (columns of a candidate array).
AXES = ("x", "y", "z", "yaw")
_PPM_RTOL = 1e-9


# ------------------------------------------------------------------ candidates
def _axis(value: Any, name: str) -> np.ndarray:
    """One coordinate: a number (fixed) or ``(lo, hi, step)`` (lo, lo+step, …, up to hi inclusive)."""
    unit = "rad" if name == "yaw" else "m"
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        if not np.isfinite(value):
            raise InvalidInput(f"{name} must be finite, got {value!r}")
        return np.array([float(value)])
    try:
        lo, hi, step = (float(v) for v in value)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{name} must be a number or (lo, hi, step) in {unit}, got {value!r}") from exc
    if not (np.isfinite(lo) and np.isfinite(hi) and np.isfinite(step)) or step <= 0 or hi < lo:
        raise InvalidInput(f"{name} = ({lo}, {hi}, {step}): need finite lo <= hi and step > 0 [{unit}]")
    span = (hi - lo) / step  # may be inf for a tiny step: compared before any int()
    if not span < MAX_AXIS_VALUES:
        raise SettingOutOfRange(f"{name} = ({lo}, {hi}, {step}) gives more than {MAX_AXIS_VALUES:,} values, the most "
                                "one grid coordinate may have: use a larger step")
    count = int(np.floor(span + 1e-9)) + 1
    return lo + step * np.arange(count)


def grid_candidates(x: Any, y: Any, z: Any = 0.0, yaw: Any = 0.0) -> np.ndarray:
    """Base placements ``(M, 4)`` = every combination of the coordinates' values.

    Each coordinate is a number or ``(lo, hi, step)`` [m, yaw in rad]; rows are ordered with
    ``x`` varying slowest and ``yaw`` fastest.
    """
    axes = [_axis(v, n) for v, n in zip((x, y, z, yaw), AXES)]
    count = math.prod(int(a.size) for a in axes)  # Python ints: no wrap-around
    if count > MAX_PLACEMENTS:
        raise SettingOutOfRange(f"the grid has {count:,} placements, more than the {MAX_PLACEMENTS:,} a layout search "
                                "takes: use larger steps or random_candidates")
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.column_stack([m.reshape(-1) for m in mesh])


def random_candidates(n: int, x: Any, y: Any, z: Any = 0.0, yaw: Any = 0.0, seed: int = 0) -> np.ndarray:
    """``n`` base placements ``(n, 4)`` uniform within bounds, from ``numpy.random.default_rng(seed)``.

    Each coordinate is a number (fixed) or ``(lo, hi)`` [m, yaw in rad]; the draws are made
    column by column in the order x, y, z, yaw (fixed coordinates draw nothing).
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise InvalidInput(f"n must be a positive number of placements, got {n!r}")
    n = count_setting(n, "n (random placements)", 1, MAX_PLACEMENTS)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInput(f"seed must be an integer >= 0, got {seed!r}")
    rng = np.random.default_rng(int(seed))
    out = np.empty((int(n), 4))
    for k, (value, name) in enumerate(zip((x, y, z, yaw), AXES)):
        if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
            if not np.isfinite(value):
                raise InvalidInput(f"{name} must be finite, got {value!r}")
            out[:, k] = float(value)
            continue
        try:
            lo, hi = (float(v) for v in value)
        except (TypeError, ValueError) as exc:
            raise InvalidInput(f"{name} must be a number or (lo, hi), got {value!r}") from exc
        if not (np.isfinite(lo) and np.isfinite(hi)) or hi < lo:
            raise InvalidInput(f"{name} = ({lo}, {hi}): need finite lo <= hi")
        out[:, k] = rng.uniform(lo, hi, size=int(n))
    return out


def base_to_world(placement: Any) -> np.ndarray:
    """``T_base_to_world (4, 4)`` of a placement ``(x, y, z, yaw)`` (or ``(N, 4, 4)`` for ``(N, 4)``)."""
    P = np.asarray(placement, dtype=float)
    single = P.ndim == 1
    P = np.atleast_2d(P)
    c, s = np.cos(P[:, 3]), np.sin(P[:, 3])
    T = np.zeros((P.shape[0], 4, 4))
    T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = c, -s, s, c
    T[:, 2, 2] = T[:, 3, 3] = 1.0
    T[:, :3, 3] = P[:, :3]
    return T[0] if single else T


def points_in_base_frame(points: np.ndarray, placements: np.ndarray) -> np.ndarray:
    """Points ``(K, 3)`` of the line frame in the base frames of ``(M, 4)`` placements: ``(M, K, 3)``.

    ``p_base = R_z(-yaw) (p - (x, y, z))``, the inverse of :func:`base_to_world`.
    """
    d = points[None, :, :] - placements[:, None, :3]
    c, s = np.cos(placements[:, 3])[:, None], np.sin(placements[:, 3])[:, None]
    out = np.empty_like(d)
    out[..., 0] = c * d[..., 0] + s * d[..., 1]
    out[..., 1] = -s * d[..., 0] + c * d[..., 1]
    out[..., 2] = d[..., 2]
    return out


def _rot_z(yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


# --------------------------------------------------------------------- settings
@dataclass(frozen=True)
class _Settings:
    """What every candidate's evaluation needs (shipped with each task)."""

    picks: np.ndarray  # (P, 3) line frame
    places: np.ndarray  # (Q, 3)
    orientation: np.ndarray | None  # (3, 3) tool orientation in the line frame, or None (robot default)
    lift: float
    dwell: float
    kind: str
    vmax: Any
    amax: Any
    jmax: Any
    seed: int
    cell: "_CellRecipe | None" = None


@dataclass(frozen=True)
class _CellRecipe:
    """How a worker rebuilds the cell (a Cell holds coal objects that do not pickle)."""

    token: str
    urdf_text: str
    source: str
    base_dir: str
    packages: tuple[tuple[str, str], ...]
    args: tuple[tuple[str, str], ...]
    seed: int
    arm: str
    carry: tuple[str, ...]
    clearance: float


#: Cells by search token in this process (the caller's own cell, or one rebuilt from its recipe).
_CELLS: dict[str, Any] = {}


def _cell_of(recipe: _CellRecipe) -> Any:
    if recipe.token not in _CELLS:
        from pinarms.robots.cell import Cell

        if len(_CELLS) >= 2:
            _CELLS.pop(next(iter(_CELLS)))
        _CELLS[recipe.token] = Cell(recipe.urdf_text, source=recipe.source, base_dir=recipe.base_dir,
                                    packages=dict(recipe.packages), args=dict(recipe.args), seed=recipe.seed)
    return _CELLS[recipe.token]


@dataclass(frozen=True)
class _Outcome:
    """One candidate's evaluation."""

    failure: str = ""  # "" when the cycle was planned
    reason: str = ""
    cycle_time: float = float("nan")  # mean over the pairs [s]
    branch: int = -1
    manipulability: float = float("nan")

    @property
    def picks_per_minute(self) -> float:
        return 60.0 / self.cycle_time if not self.failure else 0.0


def _classify(exc: PinarmsError) -> str:
    text = str(exc)
    if isinstance(exc, LimitViolation) or "outside its limits" in text or "outside their limits" in text:
        return "joint limit"
    if isinstance(exc, UnreachableTarget):
        return "unreachable"
    if isinstance(exc, InfeasibleProblem):
        return "timing"
    if "collision" in type(exc).__name__.lower() or "collid" in text:
        return "collision"
    return "timing"


def _evaluate(robot: Any, placement: np.ndarray, st: _Settings, keep_cycle: bool = False):
    """Plan every (pick, place) pair's cycle from this placement; ``_Outcome`` (and the first cycle)."""
    picks_b = points_in_base_frame(st.picks, placement[None, :])[0]
    places_b = points_in_base_frame(st.places, placement[None, :])[0]
    R = None if st.orientation is None else _rot_z(-placement[3]) @ st.orientation
    in_cell: dict[str, Any] = {}
    if st.cell is not None:
        try:
            moved = _cell_of(st.cell).with_arm_base(st.cell.arm, base_to_world(placement), carry=st.cell.carry)
        except PinarmsError as exc:
            return _Outcome("collision" if "collision" in str(exc).lower() else "timing",
                            f"the cell cannot hold the arm there: {exc}"), None
        robot = moved.arm(st.cell.arm).robot
        in_cell = {"cell": moved, "arm": st.cell.arm, "clearance": st.cell.clearance}
    times, w_min, branch, first = [], np.inf, -1, None
    for i, pick in enumerate(picks_b):
        for j, place in enumerate(places_b):
            spec = PickPlace(pick, place, lift=st.lift, dwell=st.dwell, orientation=R)
            try:
                cycle = plan_cycle(robot, spec, kind=st.kind, vmax=st.vmax, amax=st.amax, jmax=st.jmax,
                                   method="exact", seed=st.seed, **in_cell)
            except PinarmsError as exc:
                where = f"pick {i + 1} → place {j + 1}"
                return _Outcome(_classify(exc), f"{where}: {exc}"), None
            times.append(cycle.cycle_time)
            k = len(spec.names) - 1
            w = robot.manipulability(cycle.q_via[[0, k]], part="position")
            w_min = min(w_min, float(np.min(w)))
            if first is None:
                first, branch = cycle, int(cycle.branches[0])
    outcome = _Outcome("", "", float(np.mean(times)), branch, w_min)
    return outcome, (first if keep_cycle else None)


#: Robots already used in this process, by search token: a worker unpickles the robot with
#: every task, but keeps using the first copy, whose IK caches are warm (~10 % of a cycle plan).
_WARM: dict[str, Any] = {}


def _warm(robot: Any, token: str) -> Any:
    if token not in _WARM:
        if len(_WARM) >= 4:
            _WARM.pop(next(iter(_WARM)))
        _WARM[token] = robot
    return _WARM[token]


@dataclass(frozen=True)
class _ChunkTask:
    robot: Any
    token: str  # one per search (and robot)
    placements: np.ndarray  # (m, 4)
    settings: _Settings


def _evaluate_chunk(task: _ChunkTask) -> list[_Outcome]:
    robot = _warm(task.robot, task.token)
    return [_evaluate(robot, p, task.settings)[0] for p in task.placements]


@dataclass(frozen=True)
class _RefineTask:
    robot: Any
    token: str
    start: np.ndarray  # (4,)
    free: np.ndarray  # (k,) indices of the free coordinates
    bounds: np.ndarray  # (4, 2)
    step: np.ndarray  # (4,) initial simplex step
    evaluations: int
    settings: _Settings


def _refine(task: _RefineTask) -> tuple[np.ndarray, float, int]:
    """Bounded Nelder-Mead from ``start`` over the free coordinates: (placement, picks/min, evaluations)."""
    from scipy.optimize import minimize

    robot = _warm(task.robot, task.token)
    free, lo, hi = task.free, task.bounds[task.free, 0], task.bounds[task.free, 1]
    seen: dict[bytes, float] = {}
    best = {"placement": task.start.copy(), "ppm": None}

    def placement(z: np.ndarray) -> np.ndarray:
        p = task.start.copy()
        p[free] = np.clip(z, lo, hi)
        return p

    def cost(z: np.ndarray) -> float:
        p = placement(z)
        key = p.tobytes()
        if key not in seen:
            ppm = _evaluate(robot, p, task.settings)[0].picks_per_minute
            seen[key] = -ppm
            # strictly better by more than the tie tolerance: the earliest evaluation wins ties
            if best["ppm"] is None or ppm > best["ppm"] * (1.0 + _PPM_RTOL) + 1e-12:
                best["placement"], best["ppm"] = p, ppm
        return seen[key]

    z0 = task.start[free]
    simplex = [z0]
    for k in range(free.size):
        z = z0.copy()
        z[k] = z[k] + task.step[free][k] if z[k] + task.step[free][k] <= hi[k] else z[k] - task.step[free][k]
        simplex.append(z)
    minimize(cost, z0, method="Nelder-Mead", bounds=list(zip(lo, hi)),
                   options={"initial_simplex": np.array(simplex), "maxfev": task.evaluations,
                            "xatol": 1e-4, "fatol": 1e-6})
    return best["placement"], float(best["ppm"]), len(seen)


# ----------------------------------------------------------------------- results
@dataclass(frozen=True)
class Refinement:
    """The continuous improvement of the best grid candidates.

    Attributes:
        starts: ``(k,)`` indices of the candidates started from.
        start_picks_per_minute: ``(k,)`` their picks/min.
        placements: ``(k, 4)`` placement reached from each.
        picks_per_minute: ``(k,)`` picks/min there.
        evaluations: ``(k,)`` cycles planned by each search.
        free: names of the coordinates searched (those the candidates vary).
        margin: ``(k,)`` boundary margin [m] of each refined placement; one below the
            search's ``min_margin`` is reported but never taken as the best placement.
    """

    starts: np.ndarray
    start_picks_per_minute: np.ndarray
    placements: np.ndarray
    picks_per_minute: np.ndarray
    evaluations: np.ndarray
    free: tuple[str, ...]
    margin: np.ndarray | None = None

    @property
    def gain(self) -> float:
        """Best refined picks/min minus the best grid candidate's (≥ 0: a start is kept if nothing better)."""
        return float(np.max(self.picks_per_minute) - np.max(self.start_picks_per_minute))


@dataclass(frozen=True, eq=False)
class LayoutSearch:
    """Result of :func:`search_layout` (per-candidate columns are ``(M,)`` arrays).

    Attributes:
        robot: name of the arm.
        picks, places: ``(P, 3)``, ``(Q, 3)`` points in the line frame [m].
        candidates: ``(M, 4)`` placements ``(x, y, z, yaw)`` of the base in the line frame [m, rad].
        failure: per candidate ``""`` (planned) or one of :data:`FAILURES`.
        reason: per candidate, why it failed (names the point) or ``""``.
        cycle_time: mean cycle time over the (pick, place) pairs [s] (NaN when failed).
        picks_per_minute: ``60 / cycle_time`` (0 when failed).
        branch: closed-form IK branch label at the first pick (-1: failed or numerical IK).
        manipulability: smallest position manipulability at the picks and places (NaN when failed).
        margin: smallest distance of the picks and places to the workspace boundary [m] (0 outside).
        order: ``(M,)`` ranking (see the module docstring).
        refinement: the continuous improvement, or ``None``.
        best_placement: ``(4,)`` the best placement found (refined when that gained), or None.
        best_picks_per_minute: its picks/min (0 if no candidate succeeded).
        best_cycle: its first pair's cycle (:class:`optim.CycleResult`, in the base frame), or None.
        seed: seed of the search (optimiser starts; random candidates are drawn by the caller).
    """

    robot: str
    picks: np.ndarray = field(repr=False)
    places: np.ndarray = field(repr=False)
    candidates: np.ndarray = field(repr=False)
    failure: tuple[str, ...] = field(repr=False)
    reason: tuple[str, ...] = field(repr=False)
    cycle_time: np.ndarray = field(repr=False)
    picks_per_minute: np.ndarray = field(repr=False)
    branch: np.ndarray = field(repr=False)
    manipulability: np.ndarray = field(repr=False)
    margin: np.ndarray = field(repr=False)
    order: np.ndarray = field(repr=False)
    refinement: Refinement | None
    best_placement: np.ndarray | None
    best_picks_per_minute: float
    best_cycle: CycleResult | None = field(repr=False)
    seed: int = 0

    @property
    def ok(self) -> np.ndarray:
        """``(M,)`` bool: the cycle was planned."""
        return np.array([f == "" for f in self.failure], dtype=bool)

    @property
    def best_index(self) -> int:
        """Index of the best grid candidate (-1 if none succeeded)."""
        return int(self.order[0]) if self.ok[self.order[0]] else -1

    def failures(self) -> dict[str, int]:
        """Number of candidates per failure kind (only kinds that occur)."""
        counts = Counter(f for f in self.failure if f)
        return {k: counts[k] for k in FAILURES if counts[k]}

    def table(self, top: int = 10, *, failed: int = 3) -> str:
        """The ranked table (mm, degrees): the ``top`` candidates and the first ``failed`` failures."""
        mm = 1000.0
        ok = self.ok
        head = (f"layout search of {self.robot}: {len(self.candidates)} placements, {int(ok.sum())} planned"
                + "".join(f", {n} {k}" for k, n in self.failures().items()))
        lines = [head, "rank   x [mm]   y [mm]   z [mm]  yaw [°]  picks/min  cycle [s]  branch  manip.   margin [mm]"]
        for rank, i in enumerate(self.order[: int(top)]):
            if not ok[i]:
                break
            x, y, z, yaw = self.candidates[i]
            lines.append(f"{rank + 1:4d} {x * mm:8.0f} {y * mm:8.0f} {z * mm:8.0f} {np.degrees(yaw):8.1f} "
                         f"{self.picks_per_minute[i]:10.2f} {self.cycle_time[i]:10.3f} {self.branch[i]:7d} "
                         f"{self.manipulability[i]:7.4f} {self.margin[i] * mm:12.0f}")
        bad = [i for i in range(len(self.failure)) if self.failure[i]][: int(failed)]
        for i in bad:
            x, y, z, yaw = self.candidates[i]
            lines.append(f"  failed ({x * mm:.0f}, {y * mm:.0f}, {z * mm:.0f}) mm, yaw {np.degrees(yaw):.1f}°: "
                         f"{self.failure[i]}: {self.reason[i]}")
        if self.refinement is not None:
            r = self.refinement
            k = int(np.argmax(r.picks_per_minute))
            x, y, z, yaw = r.placements[k]
            lines.append(f"refined over {', '.join(r.free)} from the best {len(r.starts)}: "
                         f"{np.max(r.start_picks_per_minute):.2f} → {r.picks_per_minute[k]:.2f} picks/min "
                         f"(+{r.gain:.2f}, {int(r.evaluations.sum())} cycles planned) at "
                         f"({x * mm:.0f}, {y * mm:.0f}, {z * mm:.0f}) mm, yaw {np.degrees(yaw):.1f}°")
        if self.best_placement is not None:
            x, y, z, yaw = self.best_placement
            lines.append(f"best placement: base at ({x * mm:.0f}, {y * mm:.0f}, {z * mm:.0f}) mm, yaw "
                         f"{np.degrees(yaw):.1f}°: {self.best_picks_per_minute:.2f} picks/min")
        else:
            lines.append("no placement can run the cycle: see the failures above")
        return "\n".join(lines)

    def as_dict(self) -> dict[str, Any]:
        """JSON-able result (SI units), candidates in ranking order."""
        rows = []
        for i in self.order:
            rows.append({
                "index": int(i),
                "placement": dict(zip(("x_m", "y_m", "z_m", "yaw_rad"), self.candidates[i].tolist())),
                "ok": self.failure[i] == "",
                "failure": self.failure[i] or None,
                "reason": self.reason[i] or None,
                "cycle_time_s": None if self.failure[i] else float(self.cycle_time[i]),
                "picks_per_minute": float(self.picks_per_minute[i]),
                "branch": int(self.branch[i]),
                "manipulability": None if self.failure[i] else float(self.manipulability[i]),
                "boundary_margin_m": float(self.margin[i]),
            })
        out: dict[str, Any] = {
            "robot": self.robot,
            "picks_m": self.picks.tolist(),
            "places_m": self.places.tolist(),
            "seed": self.seed,
            "failures": self.failures(),
            "candidates": rows,
            "best": None if self.best_placement is None else {
                "placement": dict(zip(("x_m", "y_m", "z_m", "yaw_rad"), self.best_placement.tolist())),
                "picks_per_minute": self.best_picks_per_minute,
                "cycle": None if self.best_cycle is None else self.best_cycle.as_dict(),
            },
            "refinement": None,
        }
        if self.refinement is not None:
            r = self.refinement
            out["refinement"] = {
                "free": list(r.free),
                "starts": r.starts.tolist(),
                "start_picks_per_minute": r.start_picks_per_minute.tolist(),
                "placements": r.placements.tolist(),
                "picks_per_minute": r.picks_per_minute.tolist(),
                "evaluations": r.evaluations.tolist(),
                "boundary_margin_m": None if r.margin is None else r.margin.tolist(),
                "gain_picks_per_minute": r.gain,
            }
        return out


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


def _screen(robot: Any, cand: np.ndarray, st: _Settings) -> tuple[list[str], list[str]]:
    """Batched closed-form IK of every waypoint from every placement: failure and reason per candidate."""
    from pinarms.robots.layout import default_orientation

    M = cand.shape[0]
    failure, reason = [""] * M, [""] * M
    if not getattr(robot, "has_analytic_ik", False):
        return failure, reason  # numerical IK: each cycle plan finds and names the problem
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
    return failure, reason


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


def search_layout(
    robot: Any,
    picks: Any,
    places: Any,
    candidates: Any,
    *,
    lift: float = 0.05,
    dwell: float = 0.2,
    orientation: Any = None,
    kind: str = "multi-quintic",
    vmax: Any = None,
    amax: Any = None,
    jmax: Any = None,
    refine: int = 2,
    refine_evaluations: int = 30,
    workspace_samples: int = 200_000,
    seed: int = 0,
    chunk_size: int = 4,
    scheduler: Any = None,
    progress: Callable[[int, int], None] | None = None,
    arm: str | None = None,
    clearance: float = 0.02,
    carry: tuple[str, ...] = (),
    min_margin: float = 0.0,
) -> LayoutSearch:
    """Rank base placements of ``robot`` by the picks per minute of its pick-and-place cycle.

    Args:
        robot: a :class:`robots.Robot` (the arm to place), or a :class:`robots.cell.Cell`:
            then the arm ``arm`` of the cell (its only arm by default) is moved among the
            cell's fixtures (the line frame is the cell's world; :meth:`Cell.with_arm_base`,
            the fixtures named in ``carry``, e.g. its stand, move with it) and every cycle
            must keep ``clearance`` [m] from the fixtures and the other arms
            (:func:`optim.plan_cycle` with ``cell=``: re-planned with a higher lift or via
            points when needed); a candidate whose cycle cannot clear fails as ``"collision"``.
        picks, places: points ``(3,)`` or ``(N, 3)`` in the line frame [m]; every pick is
            paired with every place.
        candidates: placements ``(M, 4)`` ``(x, y, z, yaw)`` of the base in the line frame
            [m, rad] (:func:`grid_candidates`, :func:`random_candidates`).
        lift, dwell, kind, vmax, amax, jmax: the cycle (see :class:`optim.PickPlace` and
            :func:`optim.plan_cycle`).
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

    Raises:
        InvalidInput: malformed points, candidates, orientation or counts.
        InvalidSettings: unknown ``kind``.
        ExecutionError: a task failed on the scheduler (chunk index named).
    """
    import uuid

    from pinarms.execution import map_chunks
    from pinarms.robots.workspace import sample_workspace

    token = uuid.uuid4().hex
    recipe = None
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
        recipe = _CellRecipe(token, cell.urdf_text, cell.source, str(cell._base_dir),
                             tuple(sorted((k, str(v)) for k, v in cell._packages.items())),
                             tuple(sorted((k, str(v)) for k, v in cell.args.items())), int(cell._seed), str(arm),
                             tuple(carry), float(clearance))
        _CELLS[token] = cell  # this process uses the caller's cell; workers rebuild it from the recipe
    elif arm is not None or carry:
        raise InvalidInput("arm= and carry= name an arm and fixtures of a cell: pass the cell as the first argument")

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
    for name, v, least, most in (("refine", refine, 0, MAX_REFINE),
                                 ("refine_evaluations", refine_evaluations, 1, MAX_REFINE_EVALUATIONS),
                                 ("workspace_samples", workspace_samples, 1000, MAX_WORKSPACE_SAMPLES),
                                 ("chunk_size", chunk_size, 1, MAX_PLACEMENTS), ("seed", seed, 0, 2**64 - 1)):
        count_setting(v, name, least, most)
    R = None
    if orientation is not None:
        R = np.asarray(orientation, dtype=float)
        if R.shape != (3, 3) or not np.all(np.isfinite(R)) or np.abs(R @ R.T - np.eye(3)).max() > 1e-6 \
                or np.linalg.det(R) < 0:
            raise InvalidInput(f"orientation must be a (3, 3) proper rotation matrix, got {orientation!r}")
    PickPlace(picks_w[0], places_w[0], lift=lift, dwell=dwell)  # checks lift and dwell (names them)
    number_setting(min_margin, "min_margin", 0.0, unit="m")
    st = _Settings(picks_w, places_w, R, float(lift), float(dwell), kind, vmax, amax, jmax, int(seed), recipe)
    M = cand.shape[0]

    failure, reason = _screen(robot, cand, st)
    ws = sample_workspace(robot, int(workspace_samples), seed=int(seed), frame="tcp")
    vmap = ws.voxel_map()
    pts = points_in_base_frame(np.vstack([picks_w, places_w]), cand)
    point_margin = vmap.query(pts.reshape(-1, 3)).margin.reshape(M, -1)
    margin = point_margin.min(axis=1)
    if min_margin > 0:
        names = [f"pick {i + 1}" for i in range(len(picks_w))] + [f"place {j + 1}" for j in range(len(places_w))]
        for m in np.flatnonzero((margin < min_margin) & np.array([not f for f in failure])):
            k = int(np.argmin(point_margin[m]))
            failure[m] = "boundary"
            reason[m] = (f"{names[k]} is {point_margin[m, k] * 1e3:.0f} mm from the edge of the workspace, "
                         f"less than min_margin {min_margin * 1e3:.0f} mm")
    todo = [m for m in range(M) if not failure[m]]
    tasks = [_ChunkTask(robot, token, cand[todo[s : s + chunk_size]], st) for s in range(0, len(todo), chunk_size)]
    n_refine = int(refine)
    total = len(tasks) + n_refine

    def phase(offset: int):
        if progress is None:
            return None
        return lambda done, _total: progress(offset + done, total)

    outcomes = [o for chunk in map_chunks(_evaluate_chunk, tasks, scheduler=scheduler, progress=phase(0)) for o in chunk]
    cycle_time = np.full(M, np.nan)
    branch = np.full(M, -1)
    manip = np.full(M, np.nan)
    for m, o in zip(todo, outcomes):
        failure[m], reason[m] = o.failure, o.reason
        if not o.failure:
            cycle_time[m], branch[m], manip[m] = o.cycle_time, o.branch, o.manipulability
    ok = np.array([f == "" for f in failure])
    ppm = np.where(ok, 60.0 / np.where(ok, cycle_time, 1.0), 0.0)

    order = _ranking(ppm, margin)

    refinement = None
    best_placement = cand[order[0]].copy() if ok[order[0]] else None
    best_ppm = float(ppm[order[0]])
    free = np.flatnonzero(np.ptp(cand, axis=0) > 0)
    starts = [int(i) for i in order[:n_refine] if ok[i]]
    if starts and free.size:
        bounds = np.column_stack([cand.min(axis=0), cand.max(axis=0)])
        step = np.ptp(cand, axis=0) / max(2.0, M ** (1.0 / free.size))  # about the grid's spacing
        rtasks = [_RefineTask(robot, token, cand[i].copy(), free, bounds, step, int(refine_evaluations), st) for i in starts]
        found = map_chunks(_refine, rtasks, scheduler=scheduler, progress=phase(len(tasks)))
        refinement = Refinement(
            starts=np.array(starts),
            start_picks_per_minute=ppm[starts],
            placements=np.array([f[0] for f in found]),
            picks_per_minute=np.array([f[1] for f in found]),
            evaluations=np.array([f[2] for f in found]),
            free=tuple(AXES[k] for k in free),
            margin=vmap.query(points_in_base_frame(np.vstack([picks_w, places_w]),
                                                   np.array([f[0] for f in found])).reshape(-1, 3))
            .margin.reshape(len(found), -1).min(axis=1),
        )
        eligible = np.where(refinement.margin >= min_margin, refinement.picks_per_minute, -np.inf)
        k = int(np.argmax(eligible))
        if np.isfinite(eligible[k]) and eligible[k] > best_ppm * (1.0 + _PPM_RTOL):
            best_placement, best_ppm = refinement.placements[k].copy(), float(refinement.picks_per_minute[k])
    best_cycle = None
    if best_placement is not None:
        best_cycle = _evaluate(robot, best_placement, st, keep_cycle=True)[1]
    return LayoutSearch(
        robot=str(robot.name),
        picks=picks_w,
        places=places_w,
        candidates=cand,
        failure=tuple(failure),
        reason=tuple(reason),
        cycle_time=cycle_time,
        picks_per_minute=ppm,
        branch=branch,
        manipulability=manip,
        margin=margin,
        order=order,
        refinement=refinement,
        best_placement=best_placement,
        best_picks_per_minute=best_ppm,
        best_cycle=best_cycle,
        seed=int(seed),
    )
