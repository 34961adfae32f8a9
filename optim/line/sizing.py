"""Sizing a line: the fewest arms, their places along the belt and the belt speed for a flow.

For ``n = n_min, n_min + 1, …`` arms the project's GA (:func:`pinarms.optim.run_ga`) searches the
gaps between neighbouring arms (each in ``[min_gap, max_gap]`` m) and the belt speed (one of
the given speeds, a gene rounded to the nearest) for the lowest mean miss rate over the
seeds (Monte Carlo: every individual of a generation is one task on the execution layer,
simulating its seeds in turn — serial by default, a Dask cluster by address; tasks are pure
functions of their seeds, so the result is the same either way). The first ``n`` whose best
line misses no more than asked is the answer, with its positions and speed.

``n_min`` defaults to the flow over one saturated arm's rate. The maps (one per belt speed)
are built once: moving an arm along the belt keeps its map valid (:mod:`~.task_maps`).

One input, one result (:mod:`pinarms.optim.status`): :func:`size_line` takes a :class:`SizingProblem`
(checked when built: bad maps, gaps, counts raise ``InvalidInput`` naming the field) and
returns a :class:`SizingResult` whose ``status`` is :attr:`SizingStatus.OK` or, when no
``n <= max_arms`` meets the miss rate, :attr:`SizingStatus.NOT_FOUND` with a ``status_reason``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from pinarms.optim.types import Scheduler

from pinarms.optim.caps import MAX_GENERATIONS, MAX_POPULATION, count_setting, number_setting
from pinarms.optim.line.items import ItemType, poisson_items
from pinarms.optim.line.rules import Rule
from pinarms.optim.line.simulate import SimArm, simulate
from pinarms.optim.line.task_maps import TaskMap
from pinarms.optim.status import Status
from pinarms.errors import InvalidInput

__all__ = ["SizingProblem", "SizingResult", "SizingStatus", "size_line", "evaluate_layouts"]

#: Most arms a sizing tries (as many as one line may hold, :data:`pinarms.optim.line.api.MAX_LINE_ARMS`).
MAX_SIZING_ARMS = 64


class SizingStatus(Status):
    """Whether a sizing found a line (the value is the word printed)."""

    #: a line of ``arms`` arms meets the miss rate
    OK = "ok"
    #: no ``n <= max_arms`` does (``SizingResult.status_reason`` gives the best miss rate found)
    NOT_FOUND = "not found"


@dataclass(frozen=True, eq=False)
class SizingProblem:
    """What to size. ``maps``: ``{belt speed [m/s]: TaskMap}`` of one arm model (arms shifted
    along the belt reuse it); ``rest``: the arm's box relative to its base on the belt
    (du, w) [m]; ``rate``: flow [items/min] (Poisson); ``max_miss``: miss rate asked for;
    ``min_gap``/``max_gap``: distance between neighbouring arms [m]; ``first_u``: the first
    arm's place along the belt [m]; ``seeds``, ``duration`` [s] of each simulation.
    ``far_maps``: ``{belt speed: TaskMap}`` of the same arm standing on the belt's other side (its
    box at ``far_rest``): each arm's side is then a gene too. Neighbours on opposite sides keep the
    same ``min_gap`` along the belt (no arms facing each other: no neighbour check needed).

    The search: ``n_min`` arms first (None: the flow over one saturated arm's rate), then one
    more up to ``max_arms``; for each, the GA (:func:`pinarms.optim.run_ga`) with ``population``
    individuals over ``generations`` generations, seeded ``seed + n``."""

    maps: dict
    rate: float
    max_miss: float = 0.01
    min_gap: float = 0.9
    max_gap: float = 1.5
    first_u: float = 0.6
    rest: tuple[float, float] = (-0.2, 0.45)
    item: ItemType = ItemType("item")
    width: float = 0.3
    rule: Rule = Rule()
    seeds: tuple[int, ...] = (0, 1, 2, 3)
    duration: float = 300.0
    far_maps: dict | None = None
    far_rest: tuple[float, float] = (-0.2, -0.45)
    n_min: int | None = None
    max_arms: int = 12
    population: int = 12
    generations: int = 8
    seed: int = 0

    def __post_init__(self) -> None:
        number_setting(self.rate, "rate", 0.0, open_low=True, unit="items/min")
        number_setting(self.max_miss, "max_miss", 0.0, 1.0)
        count_setting(self.max_arms, "max_arms", 1, MAX_SIZING_ARMS)
        if self.n_min is not None:
            count_setting(self.n_min, "n_min", 1, self.max_arms)
        count_setting(self.population, "population", 4, MAX_POPULATION)  # the GA's own least (GASettings)
        count_setting(self.generations, "generations", 1, MAX_GENERATIONS)
        count_setting(self.seed, "seed", 0, 2**63 - 1)
        if not self.maps or not all(isinstance(m, TaskMap) for m in self.maps.values()):
            raise InvalidInput("maps must be {belt speed: TaskMap}, at least one")
        if self.far_maps is not None:
            if set(map(float, self.far_maps)) != set(map(float, self.maps)) or not all(
                    isinstance(m, TaskMap) and abs(m.speed - float(v)) <= 1e-9 for v, m in self.far_maps.items()):
                raise InvalidInput("far_maps must be {belt speed: TaskMap} for the same speeds as maps, each built "
                                   "for its speed (the arm model standing on the belt's other side)")
        for v, m in self.maps.items():
            if abs(m.speed - float(v)) > 1e-9:
                raise InvalidInput(f"the map given for {v} m/s was built for {m.speed} m/s")
        if not (0.0 < self.min_gap <= self.max_gap):
            raise InvalidInput(f"need 0 < min_gap <= max_gap [m], got {self.min_gap}, {self.max_gap}")

    @property
    def speeds(self) -> np.ndarray:
        return np.array(sorted(float(v) for v in self.maps))


@dataclass(frozen=True)
class SizingResult:
    """``status``: :class:`SizingStatus` (``"ok"``, or ``"not found"`` when no ``n <= max_arms``
    meets the miss rate; ``status_reason`` says so with the best found); ``arms``: how many (None
    when not found); ``positions``: along the belt [m]; ``speed`` [m/s]; ``miss_rate``:
    mean over the seeds; ``picks_per_minute``; ``tried``: ``{n: best miss rate}``;
    ``evaluations``: simulations run; ``sides``: per arm 0 (near side) or 1 (far side, ``far_maps``)."""

    status: SizingStatus
    arms: int | None
    positions: tuple[float, ...]
    speed: float
    miss_rate: float
    picks_per_minute: float
    tried: dict = field(default_factory=dict)
    evaluations: int = 0
    sides: tuple[int, ...] = ()
    status_reason: str = ""


def _layout(problem: SizingProblem, genes: np.ndarray) -> tuple[np.ndarray, float, tuple[int, ...]]:
    """(positions, speed, sides) of a genome: gaps, [sides (0 near, 1 far) when two sides], speed index."""
    speeds = problem.speeds
    k = int(np.clip(np.rint(genes[-1]), 0, speeds.size - 1))
    n = (genes.size + 1) // 2 if problem.far_maps is not None else genes.size
    gaps = genes[: n - 1]
    sides = tuple(int(np.rint(x) > 0) for x in genes[n - 1: -1]) if problem.far_maps is not None else (0,) * n
    return problem.first_u + np.concatenate([[0.0], np.cumsum(gaps)]), float(speeds[k]), sides


def _sim_task(task: dict) -> list[tuple[float, float]]:
    """(miss rate, picks/min) of one layout on each of its seeds: a task of the execution layer.

    One task per layout, not per seed: a task then carries the problem (its maps) once for all
    its seeds and runs long enough (seconds) that the cluster's per-task costs stay small."""
    from pinarms.optim.line.belt import Belt

    p: SizingProblem = task["problem"]
    sides = task.get("sides") or (0,) * len(task["positions"])
    maps = (p.maps[task["speed"]], (p.far_maps or p.maps)[task["speed"]])
    rests = (p.rest, p.far_rest)
    arms = [SimArm(f"arm {k + 1}", float(u), (maps[s],), (float(u) + rests[s][0], rests[s][1]))
            for k, (u, s) in enumerate(zip(task["positions"], sides))]
    belt = Belt((0.0, 0.0, 0.0), speed=task["speed"], width=p.width, length=1.0)
    out = []
    for seed in task["seeds"]:
        items = poisson_items(belt, p.rate / 60.0, p.duration, types=(p.item,), seed=seed)
        r = simulate(arms, items, task["speed"], p.rule, duration=p.duration, width=p.width)
        out.append((r.miss_rate, r.picks_per_minute))
    return out


def evaluate_layouts(problem: SizingProblem, layouts: Sequence[tuple], *, scheduler: Scheduler = None) -> np.ndarray:
    """Mean (miss rate, picks/min) over the seeds of each ``(positions, speed[, sides])``: (len, 2)."""
    from pinarms.execution import map_chunks

    tasks = [{"problem": problem, "positions": [float(x) for x in lay[0]], "speed": lay[1],
              "sides": [int(s) for s in lay[2]] if len(lay) > 2 else None, "seeds": list(problem.seeds),
              "seed": problem.seeds[0]} for lay in layouts]
    out = np.array(map_chunks(_sim_task, tasks, scheduler=scheduler), dtype=float).reshape(len(layouts),
                                                                                          len(problem.seeds), 2)
    return out.mean(axis=1)


def size_line(problem: SizingProblem, *, scheduler: Scheduler = None,
              progress: Callable[[str], None] | None = None) -> SizingResult:
    """The fewest arms, their places and the belt speed for ``problem`` (module doc).

    ``scheduler``: where the simulations run (:func:`pinarms.execution.map_chunks`; the same
    result anywhere); ``progress``: called with one line per number of arms tried.
    """
    from pinarms.optim.ga.engine import run_ga
    from pinarms.optim.ga.request import GARequest
    from pinarms.optim.ga.settings import GASettings

    n_min = problem.n_min
    if n_min is None:
        m = problem.maps[problem.speeds[-1]]
        cycle = float(np.nanmin(m.approach + m.leave)) + m.track + m.release
        n_min = max(1, int(np.floor(problem.rate * cycle / 60.0)))
    tried: dict = {}
    evals = 0
    best = None
    for n in range(n_min, problem.max_arms + 1):
        side_genes = [[-0.49, 1.49]] * n if problem.far_maps is not None else []
        bounds = np.array([[problem.min_gap, problem.max_gap]] * (n - 1) + side_genes
                          + [[-0.49, problem.speeds.size - 0.51]])

        def objective(pop: np.ndarray) -> np.ndarray:
            nonlocal evals
            layouts = [_layout(problem, g) for g in pop]
            res = evaluate_layouts(problem, layouts, scheduler=scheduler)
            evals += len(layouts) * len(problem.seeds)
            # lowest miss rate first; among equal ones the shorter line and slower belt
            span = np.array([lay[0][-1] - lay[0][0] for lay in layouts])
            return res[:, 0] + 1e-4 * span + 1e-5 * np.array([lay[1] for lay in layouts])

        settings = GASettings(population=problem.population, elitism=2)
        ga = run_ga(GARequest(objective, bounds, settings, seed=problem.seed + n, max_generations=problem.generations,
                              stall_generations=problem.generations))
        pos, speed, sides = _layout(problem, ga.x)
        miss, ppm = evaluate_layouts(problem, [(pos, speed, sides)], scheduler=scheduler)[0]
        tried[n] = float(miss)
        if progress:
            progress(f"{n} arms: best miss rate {100 * miss:.2f} % at {speed} m/s")
        best = (n, pos, speed, miss, ppm, sides)
        if miss <= problem.max_miss:
            return SizingResult(SizingStatus.OK, n, tuple(float(x) for x in pos), speed, float(miss), float(ppm),
                                tried, evals, sides)
    if best is None:  # one arm's rate puts n_min above max_arms: nothing tried
        return SizingResult(SizingStatus.NOT_FOUND, None, (), float(problem.speeds[-1]), math.nan, math.nan, tried, evals, (),
                            f"the flow needs at least {n_min} arms (the flow over one saturated arm's rate), "
                            f"more than max_arms = {problem.max_arms}: raise max_arms")
    n, pos, speed, miss, ppm, sides = best
    return SizingResult(SizingStatus.NOT_FOUND, None, tuple(float(x) for x in pos), speed, float(miss), float(ppm),
                        tried, evals, sides,
                        f"no line of {n_min} to {problem.max_arms} arms meets the miss rate "
                        f"{100 * problem.max_miss:g} %: the best, {n} arms, misses {100 * miss:.2f} %; "
                        "raise max_arms, widen the gaps or lower the flow")
