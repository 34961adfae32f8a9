"""Deterministic minimum-time timing by the scaling laws (the GA's yardstick).

For ratios ``r`` on the simplex (durations ``s * r``), the smallest feasible total is
``s*(r)`` (see :mod:`optim.problem`); with duration bounds ``lo <= s r_i <= hi`` the
best total for those ratios is ``max(s*(r), max_i lo_i / r_i)``, feasible iff it also
keeps ``s r_i <= hi_i``. Every feasible timing has such a representation, so minimising
this function over ``r`` solves the problem exactly up to the local optimiser's
precision. ``r = softmax(z)`` keeps the search unconstrained; Nelder-Mead runs from
deterministic starts (equal ratios, ratios from the segment lengths) plus seeded random
ones, restarted from its best point until it stops improving.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import minimize

from optim.problem import SAFETY, TimingProblem

__all__ = ["ExactSolution", "solve_exact", "ratios_objective", "minimize_over_ratios"]


@dataclass(frozen=True)
class ExactSolution:
    """Best durations (m,) (s), their total (s), whether they meet the bounds, and the
    number of trajectory evaluations."""

    durations: np.ndarray
    total: float
    feasible: bool
    evaluations: int


def _softmax(z: np.ndarray) -> np.ndarray:
    e = np.exp(z - np.max(z))
    return e / e.sum()


def ratios_objective(problem: TimingProblem) -> Callable[[np.ndarray], tuple[float, np.ndarray, float]]:
    """``z -> (total, durations, bound excess)`` for ratios ``softmax(z)``."""
    lo, hi = problem.bounds[:, 0], problem.bounds[:, 1]

    def evaluate(z: np.ndarray) -> tuple[float, np.ndarray, float]:
        r = _softmax(np.asarray(z, dtype=float))
        s = problem.minimal_scale(r) * (1.0 + SAFETY)
        s = max(s, float(np.max(lo / r)))
        h = s * r
        excess = float(np.max(np.maximum(h - hi, 0.0) / hi))
        return s, h, excess

    return evaluate


def start_ratios(problem: TimingProblem, n_random: int, seed: int) -> list[np.ndarray]:
    """Deterministic start points: equal, ∝ segment length / vmax, ∝ its square root,
    the mid-point of the bounds, plus ``n_random`` seeded Dirichlet draws."""
    m = problem.n_segments
    dq = np.max(np.abs(np.diff(problem.positions, axis=0)) / problem.vmax, axis=1) + 1e-6
    mid = problem.bounds.mean(axis=1)
    starts = [np.full(m, 1.0 / m), dq / dq.sum(), np.sqrt(dq) / np.sqrt(dq).sum(), mid / mid.sum()]
    rng = np.random.default_rng(seed)
    starts += [rng.dirichlet(np.ones(m)) for _ in range(n_random)]
    return starts


def minimize_over_ratios(score: Callable[[np.ndarray], float], starts: list[np.ndarray],
                         m: int, restarts: int = 6) -> np.ndarray:
    """Multi-start Nelder-Mead over ``z`` (ratios = softmax(z)); returns the best z."""
    if m == 1:
        return np.zeros(1)
    best_z, best_val = None, np.inf
    for r0 in starts:
        z = np.log(np.asarray(r0, dtype=float))
        val = score(z)
        for _ in range(restarts):
            res = minimize(score, z, method="Nelder-Mead",
                           options={"xatol": 1e-9, "fatol": 1e-13, "maxiter": 300 * m,
                                    "maxfev": 400 * m, "adaptive": m > 3})
            improved = res.fun < val * (1.0 - 1e-12)
            if res.fun <= val:
                z, val = res.x, float(res.fun)
            if not improved:
                break
        if val < best_val:
            best_z, best_val = z, val
    return np.asarray(best_z)


def solve_exact(problem: TimingProblem, n_random: int = 4, seed: int = 0) -> ExactSolution:
    """Minimum total duration of ``problem`` by the scaling laws (deterministic).

    Args:
        problem: The timing problem.
        n_random: Random starts beside the deterministic ones.
        seed: Seed of those starts (the result is reproducible).
    """
    before = problem.evaluations
    evaluate = ratios_objective(problem)

    def score(z: np.ndarray) -> float:
        s, _, excess = evaluate(z)
        return s * (1.0 + 1e3 * excess)

    z = minimize_over_ratios(score, start_ratios(problem, n_random, seed), problem.n_segments)
    s, h, excess = evaluate(z)
    return ExactSolution(durations=h, total=float(h.sum()), feasible=excess <= 0.0,
                         evaluations=problem.evaluations - before)
