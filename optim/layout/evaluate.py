"""Evaluating one candidate placement of a layout search (stages 2 and 4 of
:func:`pinarms.optim.layout.search_layout`): the settings a search passes to its tasks, the cycle
plans of every (pick, place) pair, the failure classes, and the Nelder-Mead refinement of one
start. Every task is a pure function of its inputs (the execution layer may run it anywhere).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from pinarms.optim.cycle import CellSettings, CycleRequest, CycleTiming, PickPlace, plan_cycle
from pinarms.optim.errors import InfeasibleProblem
from pinarms.errors import LimitViolation, PinarmsError, UnreachableTarget

from pinarms.optim.layout.candidates import PPM_RTOL, base_to_world, points_in_base_frame
from pinarms.robots.so3 import rot_z

if TYPE_CHECKING:
    from pinarms.optim.cycle.spec import CycleResult
    from pinarms.robots.cell import Cell
    from pinarms.robots.robot import Robot

__all__ = ["EvaluationSettings", "PhaseClock", "CellRecipe", "keep_cell", "forget_cell", "evaluate_placement", "ChunkTask",
           "evaluate_chunk", "RefineTask", "refine_placement"]  # the tasks search_layout runs


# --------------------------------------------------------------------- settings
@dataclass(frozen=True)
class EvaluationSettings:
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
    cell: "CellRecipe | None" = None
    screen: bool = True  # CellSettings.screen of every cycle in the cell


class PhaseClock:
    """Wall and CPU seconds (this process) of a search's phases: ``laps[name] = (wall, cpu)``."""

    def __init__(self) -> None:
        import time

        self._time = time
        self.laps: dict[str, tuple[float, float]] = {}
        self._at = (time.perf_counter(), time.process_time())

    def lap(self, name: str) -> None:
        now = (self._time.perf_counter(), self._time.process_time())
        self.laps[name] = (now[0] - self._at[0], now[1] - self._at[1])
        self._at = now


@dataclass(frozen=True)
class CellRecipe:
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
    placements: tuple = ()  # the ArmPlacements of a composed cell (tcp, freeze, states, hold)


#: Cells by search token in this process (the caller's own cell, or one rebuilt from its recipe).
_CELLS: dict[str, Cell] = {}


def keep_cell(token: str, cell: Cell) -> None:
    """Use ``cell`` itself for the search ``token`` in this process (workers elsewhere rebuild it from its recipe)."""
    _CELLS[token] = cell


def forget_cell(token: str) -> None:
    """Drop the cell of search ``token`` from this process (the next task rebuilds it from its recipe)."""
    _CELLS.pop(token, None)


def _cell_of(recipe: CellRecipe) -> Cell:
    if recipe.token not in _CELLS:
        from pinarms.robots.cell import Cell

        if len(_CELLS) >= 2:
            _CELLS.pop(next(iter(_CELLS)))
        _CELLS[recipe.token] = Cell(recipe.urdf_text, source=recipe.source, base_dir=recipe.base_dir,
                                    packages=dict(recipe.packages), args=dict(recipe.args), seed=recipe.seed,
                                    placements=recipe.placements)
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


def evaluate_placement(robot: Robot, placement: np.ndarray, st: EvaluationSettings,
                       keep_cycle: bool = False) -> tuple[_Outcome, CycleResult | None]:
    """Plan every (pick, place) pair's cycle from ``placement`` (4,) (x, y, z [m], yaw [rad]): its outcome, and its
    first cycle when ``keep_cycle``."""
    picks_b = points_in_base_frame(st.picks, placement[None, :])[0]
    places_b = points_in_base_frame(st.places, placement[None, :])[0]
    R = None if st.orientation is None else rot_z(-placement[3]) @ st.orientation
    in_cell = None
    if st.cell is not None:
        try:
            moved = _cell_of(st.cell).with_arm_base(st.cell.arm, base_to_world(placement), carry=st.cell.carry)
        except PinarmsError as exc:
            return _Outcome("collision" if "collision" in str(exc).lower() else "timing",
                            f"the cell cannot hold the arm there: {exc}"), None
        # ``robot`` stays the task's own (warm IK caches): the arm's kinematics in its base frame
        # do not change when its base moves, and the cell's arm is named
        in_cell = CellSettings(moved, clearance=st.cell.clearance, arm=st.cell.arm, screen=st.screen,
                               recheck=keep_cycle)
    times, w_min, branch, first = [], np.inf, -1, None
    for i, pick in enumerate(picks_b):
        for j, place in enumerate(places_b):
            spec = PickPlace(pick, place, lift=st.lift, dwell=st.dwell, orientation=R)
            try:
                timing = CycleTiming(st.kind, st.vmax, st.amax, st.jmax, method="exact", seed=st.seed)
                cycle = plan_cycle(CycleRequest(robot, spec, timing=timing, cell=in_cell))
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
class ChunkTask:
    """A worker's share of the grid: ``placements`` (m, 4) evaluated with ``robot`` under ``settings``."""

    robot: Any
    token: str  # one per search (and robot)
    placements: np.ndarray  # (m, 4)
    settings: EvaluationSettings


def evaluate_chunk(task: ChunkTask) -> list[_Outcome]:
    """The outcomes of the task's placements (a worker's share of the grid)."""
    robot = _warm(task.robot, task.token)
    return [evaluate_placement(robot, p, task.settings)[0] for p in task.placements]


@dataclass(frozen=True)
class RefineTask:
    """One Nelder-Mead refinement from ``start`` (4,) over the ``free`` coordinates within ``bounds`` (4, 2)."""

    robot: Any
    token: str
    start: np.ndarray  # (4,)
    free: np.ndarray  # (k,) indices of the free coordinates
    bounds: np.ndarray  # (4, 2)
    step: np.ndarray  # (4,) initial simplex step
    evaluations: int
    settings: EvaluationSettings


def refine_placement(task: RefineTask) -> tuple[np.ndarray, float, int]:
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
            ppm = evaluate_placement(robot, p, task.settings)[0].picks_per_minute
            seen[key] = -ppm
            # strictly better by more than the tie tolerance: the earliest evaluation wins ties
            if best["ppm"] is None or ppm > best["ppm"] * (1.0 + PPM_RTOL) + 1e-12:
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
