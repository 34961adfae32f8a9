"""Constraint handling: violation measure, adaptive penalty (seed 002) and Deb's rules.

Constraints are arrays ``g`` of shape (pop, n_con) with ``g <= 0`` feasible. Scale them
(e.g. ``peak / limit - 1``) so that one unit of violation means the same everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["violation", "AdaptivePenalty", "penalty_fitness", "rank_penalty",
           "rank_feasibility_rules", "FEASIBILITY_TOLERANCE"]

#: Violation below which an individual counts as feasible.
FEASIBILITY_TOLERANCE = 1e-12


def violation(g: np.ndarray | None, pop: int) -> np.ndarray:
    """Total violation ``sum_j max(0, g_j)`` per individual, (pop,); zeros if no constraints."""
    if g is None:
        return np.zeros(pop)
    g = np.asarray(g, dtype=float).reshape(pop, -1)
    return np.sum(np.maximum(g, 0.0), axis=1)


@dataclass
class AdaptivePenalty:
    """Penalty ``p(X) = lambda * v(X)`` with lambda adapted from the best's feasibility.

    Seed 002 uses an adaptive penalty and fitness = 1 / (f + p); its equation is lost in
    the text, so the classic adaptive rule of Hadj-Alouane and Bean (1997) is used: if
    the best individual was infeasible in each of the last ``window`` generations,
    lambda *= ``increase``; if it was feasible in each of them, lambda /= ``decrease``;
    otherwise lambda stays. The state is mutable on purpose (it is the GA's memory).
    """

    lam: float
    increase: float
    decrease: float
    window: int
    _history: list[bool] = field(default_factory=list)

    def penalty(self, v: np.ndarray) -> np.ndarray:
        """Penalty per individual for violations ``v`` (pop,)."""
        return self.lam * np.asarray(v, dtype=float)

    def update(self, best_feasible: bool) -> None:
        """Record whether this generation's best is feasible and adapt lambda."""
        self._history.append(bool(best_feasible))
        recent = self._history[-self.window:]
        if len(recent) < self.window:
            return
        if all(recent):
            self.lam = max(self.lam / self.decrease, 1e-6)
        elif not any(recent):
            self.lam = min(self.lam * self.increase, 1e12)


def penalty_fitness(score: np.ndarray) -> np.ndarray:
    """Fitness, larger is better, from a penalised score ``f + p`` to minimise.

    ``1 / (f + p)`` (seed 002) when every score is positive (e.g. a duration); otherwise
    the scores are shifted so that the smallest becomes 1 first (same ordering).
    """
    score = np.asarray(score, dtype=float)
    if np.all(score > 0.0):
        return 1.0 / score
    return 1.0 / (1.0 + score - np.min(score))


def _ranks(order: np.ndarray) -> np.ndarray:
    rank = np.empty_like(order)
    rank[order] = np.arange(order.shape[0])
    return rank


def rank_penalty(f: np.ndarray, v: np.ndarray, lam: float) -> tuple[np.ndarray, np.ndarray]:
    """Ranks (0 = best) and fitness of a population under the penalty ``f + lam * v``."""
    score = np.asarray(f, dtype=float) + lam * np.asarray(v, dtype=float)
    order = np.argsort(score, kind="stable")
    return _ranks(order), penalty_fitness(score)


def rank_feasibility_rules(f: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ranks and fitness under Deb's (2000) feasibility rules.

    Feasible beats infeasible; two feasible compare by f; two infeasible by violation.
    The returned fitness is the linear-ranking value (best 2, worst 0), used by the
    adaptive probabilities.
    """
    f = np.asarray(f, dtype=float)
    v = np.asarray(v, dtype=float)
    infeasible = v > FEASIBILITY_TOLERANCE
    primary = np.where(infeasible, 1.0, 0.0)
    secondary = np.where(infeasible, v, f)
    order = np.lexsort((secondary, primary))
    rank = _ranks(order)
    pop = f.shape[0]
    fitness = 2.0 * (pop - 1 - rank) / max(pop - 1, 1)
    return rank, fitness
