"""Deterministic minimum-time timing (the GA's yardstick): SLSQP + the scaling laws.

Problem: minimise ``sum(h)`` over segment durations ``lo <= h <= hi`` subject to
``peak_{k,i,j}(h) <= L_{k,j}`` for every limit kind k (velocity, acceleration, jerk),
polynomial piece i and joint j. Taking the peak of each piece as its own constraint keeps
the constraints smooth almost everywhere (the maximum over pieces is not), so SLSQP with
forward-difference Jacobians (all perturbed timings evaluated in one batched peak search)
converges in a few dozen iterations.

Start points come from the scaling laws: for ratios ``r`` the smallest feasible total is
``s*(r)`` (see :mod:`pinarms.optim.ga.problem`), so ``h0 = s*(r) r`` is feasible for equal ratios,
ratios from the segment lengths, their square roots and seeded random ratios. The best
SLSQP answer is finally rescaled along its own ratios onto the limits
(``s*(r) (1 + SAFETY)``, within the bounds), which makes it feasible by construction
and tight to the active limit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from pinarms.optim.caps import MAX_EXACT_ITERATIONS, MAX_EXACT_STARTS, MAX_POLISH_EVALUATIONS, count_setting
from pinarms.optim.ga.problem import SAFETY, TimingProblem

__all__ = ["ExactSolution", "solve_exact", "start_ratios", "scaled_to_limits", "polish_durations"]


@dataclass(frozen=True)
class ExactSolution:
    """Best durations (m,) (s), their total (s), whether they meet the bounds, and the
    number of trajectory evaluations."""

    durations: np.ndarray
    total: float
    feasible: bool
    evaluations: int


def start_ratios(problem: TimingProblem, n_random: int, seed: int) -> list[np.ndarray]:
    """Start ratios: equal, ∝ segment length / vmax, ∝ its square root, the mid-point of
    the bounds, plus ``n_random`` seeded Dirichlet draws."""
    m = problem.n_segments
    dq = np.max(np.abs(np.diff(problem.positions, axis=0)) / problem.vmax, axis=1) + 1e-6
    mid = problem.bounds.mean(axis=1)
    starts = [np.full(m, 1.0 / m), dq / dq.sum(), np.sqrt(dq) / np.sqrt(dq).sum(), mid / mid.sum()]
    rng = np.random.default_rng(seed)
    starts += [rng.dirichlet(np.ones(m)) for _ in range(n_random)]
    return starts


def scaled_to_limits(problem: TimingProblem, ratios: np.ndarray) -> tuple[np.ndarray, bool]:
    """Durations ``s r`` with the smallest s meeting limits and lower bounds; and whether
    they also meet the upper bounds."""
    r = np.asarray(ratios, dtype=float)
    r = r / r.sum()
    s = problem.minimal_scale(r) * (1.0 + SAFETY)
    if not np.isfinite(s):  # no speed meets a limit with these ratios (e.g. gravity beyond a torque limit)
        return problem.bounds[:, 1].copy(), False
    s = max(s, float(np.max(problem.bounds[:, 0] / r)))
    h = s * r
    return h, bool(np.all(h <= problem.bounds[:, 1] * (1.0 + 1e-12)))


def _slsqp(problem: TimingProblem, h0: np.ndarray, maxiter: int) -> np.ndarray:
    lo, hi = problem.bounds[:, 0], problem.bounds[:, 1]
    m = h0.shape[0]
    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def values_and_jacobian(h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = np.asarray(h, dtype=float).tobytes()
        if key not in cache:
            step = 1e-7 * np.maximum(np.abs(h), 1e-3)
            trial = np.vstack([h, h + np.diag(step)])
            c = 1.0 - problem.piece_limit_ratios_batch(trial)
            cache.clear()
            cache[key] = (c[0], ((c[1:] - c[0]) / step[:, None]).T)
        return cache[key]

    res = minimize(lambda h: float(np.sum(h)), h0, jac=lambda h: np.ones(m), method="SLSQP",
                   bounds=list(zip(lo, hi)),
                   constraints=[{"type": "ineq", "fun": lambda h: values_and_jacobian(h)[0],
                                 "jac": lambda h: values_and_jacobian(h)[1]}],
                   options={"maxiter": maxiter, "ftol": 1e-10})
    return np.clip(np.asarray(res.x, dtype=float), lo, hi)


def polish_durations(problem: TimingProblem, durations: np.ndarray,
                     maxiter: int = 60) -> tuple[np.ndarray, bool]:
    """Local refinement of a timing: SLSQP started from ``durations``, rescaled onto the limits.

    The answer is the local minimum of the total nearest (for SLSQP) to the given timing,
    not a global search: :func:`pinarms.optim.minimize_time` uses it as the optional final polish
    of a GA answer (``polish=True``). Returns the better of the refined and the given
    timing (both rescaled onto the limits by :func:`scaled_to_limits`) and whether it
    meets the upper bounds.
    """
    h0 = np.clip(np.asarray(durations, dtype=float), problem.bounds[:, 0], problem.bounds[:, 1])
    given, ok_given = scaled_to_limits(problem, h0)
    refined, ok = scaled_to_limits(problem, _slsqp(problem, h0, maxiter))
    if (ok and not ok_given) or (ok == ok_given and refined.sum() < given.sum()):
        return refined, ok
    return given, ok_given


def _polish(problem: TimingProblem, h: np.ndarray, maxfev: int) -> np.ndarray:
    """Nelder-Mead on the ratios (softmax coordinates) of ``h``, total = scaled s*(r)."""
    m = h.shape[0]
    if m == 1:
        return h

    def total(z: np.ndarray) -> float:
        e = np.exp(z - np.max(z))
        hz, ok = scaled_to_limits(problem, e / e.sum())
        excess = float(np.max(np.maximum(hz / problem.bounds[:, 1] - 1.0, 0.0)))
        return float(hz.sum()) * (1.0 + 1e3 * excess)

    res = minimize(total, np.log(h / h.sum()), method="Nelder-Mead",
                   options={"xatol": 1e-9, "fatol": 1e-12, "maxfev": maxfev,
                            "adaptive": m > 3})
    e = np.exp(res.x - np.max(res.x))
    return e / e.sum()


def solve_exact(problem: TimingProblem, n_random: int = 0, seed: int = 0,
                maxiter: int = 60, polish_evaluations: int | None = None) -> ExactSolution:
    """Minimum total duration of ``problem`` (deterministic for a given seed).

    SLSQP from each start ratio, the best answer polished by Nelder-Mead on its ratios
    (total = s*(r), exact by the scaling laws), then rescaled onto the limits.

    Args:
        problem: The timing problem.
        n_random: Random start ratios beside the deterministic ones.
        seed: Seed of those starts.
        maxiter: SLSQP iterations per start.
        polish_evaluations: Nelder-Mead budget (default 150 per segment).
    """
    count_setting(n_random, "n_random (random starts)", 0, MAX_EXACT_STARTS)
    count_setting(seed, "seed", 0, 2**64 - 1)
    count_setting(maxiter, "maxiter (SLSQP iterations per start)", 1, MAX_EXACT_ITERATIONS)
    if polish_evaluations is not None:
        count_setting(polish_evaluations, "polish_evaluations", 0, MAX_POLISH_EVALUATIONS)
    before = problem.evaluations
    best_h, best_total, best_ok = None, np.inf, False
    seen: list[np.ndarray] = []
    for r0 in start_ratios(problem, n_random, seed):
        if any(np.allclose(r0, r) for r in seen):
            continue
        seen.append(r0)
        h0, ok0 = scaled_to_limits(problem, r0)
        if not ok0:
            h0 = np.clip(h0, problem.bounds[:, 0], problem.bounds[:, 1])
        h, ok = scaled_to_limits(problem, _slsqp(problem, h0, maxiter))
        total = float(h.sum())
        if (ok and not best_ok) or (ok == best_ok and total < best_total):
            best_h, best_total, best_ok = h, total, ok
    assert best_h is not None
    budget = 150 * problem.n_segments if polish_evaluations is None else polish_evaluations
    h, ok = scaled_to_limits(problem, _polish(problem, best_h, budget))
    if (ok and not best_ok) or (ok == best_ok and h.sum() < best_total):
        best_h, best_total, best_ok = h, float(h.sum()), ok
    return ExactSolution(durations=best_h, total=best_total, feasible=best_ok,
                         evaluations=problem.evaluations - before)
