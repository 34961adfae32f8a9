"""Parent selection on a ranking (rank 0 = best), vectorised over the population.

Both operators only need each individual's rank, so they work the same with a penalty
fitness and with feasibility rules.
"""

from __future__ import annotations

import numpy as np

__all__ = ["tournament", "linear_rank_fitness", "stochastic_universal_sampling", "rank_sus"]


def tournament(rank: np.ndarray, n: int, size: int, rng: np.random.Generator) -> np.ndarray:
    """Indices of ``n`` parents, each the best-ranked of ``size`` random contestants.

    Args:
        rank: (pop,) integer rank of every individual, 0 = best.
        n: Number of parents to select.
        size: Contestants per tournament (drawn with replacement).
        rng: Random generator.

    Returns:
        (n,) indices into the population.
    """
    rank = np.asarray(rank)
    contestants = rng.integers(0, rank.shape[0], size=(n, size))
    winner = np.argmin(rank[contestants], axis=1)
    return contestants[np.arange(n), winner]


def linear_rank_fitness(rank: np.ndarray, pressure: float = 2.0) -> np.ndarray:
    """Linear-ranking fitness (Baker): best gets ``pressure``, worst ``2 - pressure``.

    The values average to 1, i.e. they are expected copies per individual.
    """
    rank = np.asarray(rank, dtype=float)
    pop = rank.shape[0]
    if pop == 1:
        return np.ones(1)
    return (2.0 - pressure) + 2.0 * (pressure - 1.0) * (pop - 1 - rank) / (pop - 1)


def stochastic_universal_sampling(weights: np.ndarray, n: int,
                                  rng: np.random.Generator) -> np.ndarray:
    """Indices of ``n`` selections with equally spaced pointers on the cumulative weights.

    One random offset places all ``n`` pointers (Baker 1987): every individual gets
    floor or ceil of its expected number of copies. The result is shuffled so that
    consecutive parents are not copies of the same individual.
    """
    weights = np.asarray(weights, dtype=float)
    total = weights.sum()
    if not total > 0.0:
        weights = np.ones_like(weights)
        total = weights.sum()
    cumulative = np.cumsum(weights)
    pointers = (rng.random() + np.arange(n)) * (total / n)
    idx = np.searchsorted(cumulative, pointers, side="right")
    idx = np.minimum(idx, weights.shape[0] - 1)
    return rng.permutation(idx)


def rank_sus(rank: np.ndarray, n: int, pressure: float, rng: np.random.Generator) -> np.ndarray:
    """Linear-rank fitness + stochastic universal sampling (seed 000's selection)."""
    return stochastic_universal_sampling(linear_rank_fitness(rank, pressure), n, rng)
