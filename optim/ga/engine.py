"""The genetic algorithm: a real-coded, bounds-aware, vectorised minimiser.

The engine knows nothing about trajectories. It minimises ``objective(X)`` over the box
``bounds`` subject to ``constraints(X) <= 0``, where ``X`` is the whole population
(pop, dim) and both functions answer for all individuals at once ((pop,) and
(pop, n_con)).

One generation: rank the population (adaptive penalty or feasibility rules), keep the
elites, select parents (tournament or rank + SUS), cross pairs (SBX / arithmetic /
blend, fixed or adaptive pc), mutate (non-uniform / polynomial, fixed or adaptive pm),
evaluate the children.

:func:`run_ga` takes one :class:`~pinarms.optim.ga.request.GARequest` (checked when built: bad bounds,
settings, seed or budgets raise there) and returns a :class:`GAResult` whose ``stop_reason``
is a :class:`~pinarms.optim.ga.request.GAStop` (:mod:`pinarms.optim.status`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from pinarms.optim.ga import adaptive, crossover, mutation, selection
from pinarms.optim.ga.constraints import (FEASIBILITY_TOLERANCE, AdaptivePenalty, rank_feasibility_rules,
                               rank_penalty, violation)
from pinarms.optim.errors import InvalidSettings
from pinarms.optim.ga.request import GARequest, GAStop, Objective, random_generator, run_budget
from pinarms.optim.ga.settings import GASettings

__all__ = ["run_ga", "GAResult", "GAHistory", "GAProgress"]


@dataclass(frozen=True)
class GAHistory:
    """Per-generation record (index 0 = initial population), for plots.

    Attributes:
        best: (G+1,) objective of the best-so-far individual (feasibility rules order).
        mean: (G+1,) mean objective of the whole population (finite values only),
            infeasible individuals included: their objective is the raw one (no penalty), so
            when few individuals are feasible this mean can lie *below* ``best`` (they
            are faster than the limits allow).
        feasible_share: (G+1,) share of feasible individuals in the population.
        best_violation: (G+1,) total constraint violation of the best-so-far.
        feasible_mean: (G+1,) mean objective of the feasible individuals of the
            generation (``inf`` when none is feasible); never below ``best`` once a
            feasible individual has been found (the best-so-far is the least of them all).
    """

    best: np.ndarray
    mean: np.ndarray
    feasible_share: np.ndarray
    best_violation: np.ndarray
    feasible_mean: np.ndarray

    def as_dict(self) -> dict[str, list[float]]:
        """JSON-able copy."""
        return {k: getattr(self, k).tolist()
                for k in ("best", "mean", "feasible_share", "best_violation", "feasible_mean")}


@dataclass(frozen=True)
class GAProgress:
    """What the optional callback receives after each generation."""

    generation: int
    best_x: np.ndarray
    best_f: float
    best_feasible: bool
    evaluations: int
    elapsed: float


@dataclass(frozen=True)
class GAResult:
    """Outcome of :func:`run_ga`.

    Attributes:
        x: (dim,) best individual found (feasible ones beat infeasible ones).
        f: Its objective value.
        feasible: Whether ``x`` satisfies every constraint.
        violation: Its total violation (0 if feasible).
        history: Per-generation :class:`GAHistory`.
        generations: Generations run.
        evaluations: Individuals evaluated (objective calls count rows).
        stop_reason: why the run stopped (:class:`GAStop`: ``"max_generations"``, ``"stall"``,
            ``"time_limit"`` or ``"callback"``).
        wall_time: Seconds spent.
    """

    x: np.ndarray
    f: float
    feasible: bool
    violation: float
    history: GAHistory
    generations: int
    evaluations: int
    stop_reason: GAStop
    wall_time: float


class _Evaluator:
    def __init__(self, objective: Objective, constraints: Objective | None) -> None:
        self.objective = objective
        self.constraints = constraints
        self.count = 0

    def __call__(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pop = x.shape[0]
        f = np.asarray(self.objective(x), dtype=float).reshape(-1)
        if f.shape[0] != pop:
            raise InvalidSettings(f"objective returned shape {f.shape} for a population of "
                                  f"{pop}: return one value per row")
        v = violation(None if self.constraints is None else self.constraints(x), pop)
        bad = ~np.isfinite(f) | ~np.isfinite(v)
        f = np.where(np.isfinite(f), f, np.inf)
        v = np.where(bad, np.inf, v)
        self.count += pop
        return f, v


def _better(f_a: float, v_a: float, f_b: float, v_b: float) -> bool:
    """Deb's order: is (f_a, v_a) strictly better than (f_b, v_b)?"""
    feas_a, feas_b = v_a <= FEASIBILITY_TOLERANCE, v_b <= FEASIBILITY_TOLERANCE
    if feas_a != feas_b:
        return feas_a
    if feas_a:
        return f_a < f_b
    return v_a < v_b


def _initial_population(evaluate: _Evaluator, lower: np.ndarray, upper: np.ndarray,
                        pop: int, initial: np.ndarray | None, rng: np.random.Generator,
                        draw_feasible: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    dim = lower.shape[0]
    rows: list[np.ndarray] = []
    if initial is not None:  # checked by GARequest
        rows.append(np.clip(initial[:pop], lower, upper))
    n_given = sum(r.shape[0] for r in rows)
    x = np.concatenate(rows + [lower + rng.random((pop - n_given, dim)) * (upper - lower)])
    f, v = evaluate(x)
    if draw_feasible:
        # Seed 002: the initial population is drawn to satisfy the constraints. Redraw
        # the infeasible random rows (a bounded number of times) and keep feasible draws.
        for _ in range(25):
            redraw = np.nonzero((v > FEASIBILITY_TOLERANCE) & (np.arange(pop) >= n_given))[0]
            if redraw.size == 0:
                break
            cand = lower + rng.random((4 * redraw.size, dim)) * (upper - lower)
            fc, vc = evaluate(cand)
            best = np.argsort(vc, kind="stable")[: redraw.size]
            take = vc[best] < v[redraw]
            slot, src = redraw[take], best[take]
            x[slot], f[slot], v[slot] = cand[src], fc[src], vc[src]
    return x, f, v


class _BestSoFar:
    """The best individual seen (Deb's order, whatever the constraint handling), the stall count
    and the per-generation history."""

    def __init__(self, x0: np.ndarray, stall_tolerance: float) -> None:
        self.x, self.f, self.v = x0.copy(), np.inf, np.inf
        self.stall_tolerance = stall_tolerance
        self.stall_count = 0
        self.rows: dict[str, list[float]] = {k: [] for k in ("best", "mean", "feasible_share", "best_violation",
                                                            "feasible_mean")}

    @property
    def feasible(self) -> bool:
        return bool(self.v <= FEASIBILITY_TOLERANCE)

    def record(self, x: np.ndarray, f: np.ndarray, v: np.ndarray) -> None:
        """Take the generation's best if it beats the best so far, count a stall, append the history."""
        order_deb = rank_feasibility_rules(f, v)[0]
        i_best = int(np.argmin(order_deb))
        improved = False
        if _better(f[i_best], v[i_best], self.f, self.v):
            feas_now = v[i_best] <= FEASIBILITY_TOLERANCE
            was_feas = self.v <= FEASIBILITY_TOLERANCE
            if feas_now and was_feas and np.isfinite(self.f):
                improved = self.f - f[i_best] > self.stall_tolerance * max(abs(self.f), 1e-300)
            else:
                improved = True
            self.x, self.f, self.v = x[i_best].copy(), float(f[i_best]), float(v[i_best])
        self.stall_count = 0 if improved else self.stall_count + 1
        finite = np.isfinite(f)
        feasible_now = (v <= FEASIBILITY_TOLERANCE) & finite
        self.rows["best"].append(self.f)
        self.rows["mean"].append(float(np.mean(f[finite])) if np.any(finite) else np.inf)
        self.rows["feasible_share"].append(float(np.mean(v <= FEASIBILITY_TOLERANCE)))
        self.rows["best_violation"].append(self.v if self.v > FEASIBILITY_TOLERANCE else 0.0)
        self.rows["feasible_mean"].append(float(np.mean(f[feasible_now])) if np.any(feasible_now) else np.inf)

    def history(self) -> GAHistory:
        return GAHistory(*(np.asarray(self.rows[k]) for k in ("best", "mean", "feasible_share", "best_violation",
                                                              "feasible_mean")))


def _children(x: np.ndarray, rank: np.ndarray, fitness: np.ndarray, n_children: int, settings: GASettings,
              lower: np.ndarray, upper: np.ndarray, generation: int, G: int,
              rng: np.random.Generator) -> np.ndarray:
    """Select parents, cross them and mutate the children (fixed or adaptive rates), in that draw order."""
    n_pairs = (n_children + 1) // 2
    if settings.selection == "tournament":
        parents = selection.tournament(rank, 2 * n_pairs, settings.tournament_size, rng)
    else:
        parents = selection.rank_sus(rank, 2 * n_pairs, settings.rank_pressure, rng)
    ia, ib = parents[:n_pairs], parents[n_pairs:]
    f_max, f_avg = float(np.max(fitness)), float(np.mean(fitness))
    if settings.adaptive:
        pc: float | np.ndarray = adaptive.adaptive_crossover_probability(
            fitness[ia], fitness[ib], f_max, f_avg, settings.pc1, settings.pc2)
    else:
        pc = settings.crossover_probability
    a, b = x[ia], x[ib]
    if settings.crossover == "sbx":
        c1, c2 = crossover.sbx(a, b, lower, upper, pc, settings.sbx_eta, rng)
    elif settings.crossover == "arithmetic":
        c1, c2 = crossover.arithmetic(a, b, lower, upper, pc, rng)
    else:
        c1, c2 = crossover.blend(a, b, lower, upper, pc, settings.blend_alpha, rng)
    children = np.concatenate([c1, c2])[:n_children]
    origin = np.concatenate([ia, ib])[:n_children]
    if settings.adaptive:
        pm: float | np.ndarray = adaptive.adaptive_mutation_probability(
            fitness[origin], f_max, f_avg, settings.pm1, settings.pm2)
    else:
        pm = settings.mutation_probability
    if settings.mutation == "non-uniform":
        return mutation.non_uniform(children, lower, upper, pm, generation, G, settings.nonuniform_shape, rng)
    return mutation.polynomial(children, lower, upper, pm, settings.polynomial_eta, rng)


def _stop_reason(generation: int, G: int, stall: int | None, best: _BestSoFar, time_limit: float | None,
                 elapsed: float) -> GAStop | None:
    """Why the run stops after this generation (budget, stall, time), or None to go on."""
    if generation >= G:
        return GAStop.MAX_GENERATIONS
    if stall is not None and best.stall_count >= stall:
        return GAStop.STALL
    if time_limit is not None and elapsed >= time_limit:
        return GAStop.TIME_LIMIT
    return None


def run_ga(request: GARequest, *, callback: Callable[[GAProgress], bool | None] | None = None) -> GAResult:
    """Minimise ``request.objective`` over its box with a real-coded GA.

    Args:
        request: objective, bounds, constraints, settings, seed, budgets and initial
            individuals (:class:`GARequest`, checked when built).
        callback: Called with a :class:`GAProgress` after each generation; returning
            True stops the run (``stop_reason`` :attr:`GAStop.CALLBACK`).

    Returns:
        :class:`GAResult`. ``feasible`` is False if no feasible individual was ever seen.
    """
    settings, constraints = request.settings, request.constraints
    time_limit, initial = request.time_limit, request.initial
    lower, upper = request.bounds[:, 0].copy(), request.bounds[:, 1].copy()
    rng = random_generator(request.seed)
    G, stall = run_budget(settings, request.max_generations, request.stall_generations, time_limit)
    pop = settings.population
    t0 = time.perf_counter()
    evaluate = _Evaluator(request.objective, constraints)
    penalty = AdaptivePenalty(settings.penalty_initial, settings.penalty_increase,
                              settings.penalty_decrease, settings.penalty_window)
    use_penalty = settings.constraint_handling == "adaptive-penalty"

    x, f, v = _initial_population(evaluate, lower, upper, pop, initial, rng,
                                  draw_feasible=constraints is not None)
    best = _BestSoFar(x[0], settings.stall_tolerance)
    generation = 0
    while True:
        best.record(x, f, v)
        elapsed = time.perf_counter() - t0
        if generation > 0 and callback is not None and callback(
                GAProgress(generation, best.x.copy(), best.f, best.feasible, evaluate.count, elapsed)):
            stop_reason = GAStop.CALLBACK
            break
        stop_reason = _stop_reason(generation, G, stall, best, time_limit, elapsed)
        if stop_reason is not None:
            break
        generation += 1
        rank, fitness = rank_penalty(f, v, penalty.lam) if use_penalty else rank_feasibility_rules(f, v)
        if use_penalty:
            penalty.update(bool(v[int(np.argmin(rank))] <= FEASIBILITY_TOLERANCE))
        elites = np.argsort(rank, kind="stable")[:settings.elitism]
        children = _children(x, rank, fitness, pop - settings.elitism, settings, lower, upper, generation, G, rng)
        fc, vc = evaluate(children)
        x = np.concatenate([x[elites], children])
        f = np.concatenate([f[elites], fc])
        v = np.concatenate([v[elites], vc])

    feasible = best.feasible
    return GAResult(x=best.x, f=best.f, feasible=feasible,
                    violation=0.0 if feasible else best.v, history=best.history(),
                    generations=generation, evaluations=evaluate.count,
                    stop_reason=stop_reason, wall_time=time.perf_counter() - t0)
