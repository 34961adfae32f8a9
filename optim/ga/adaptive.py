"""Adaptive crossover and mutation probabilities (Srinivas and Patnaik 1994; seed 002).

Fitness here is "larger is better" (seed 002: fitness = 1 / (f + penalty)). Individuals
at or below the average fitness get the full probabilities pc1 / pm1; better ones get
less, decreasing linearly to pc2 / pm2 at the population's best, so good solutions are
kept while poor ones are disrupted::

    pc = pc1 - (pc1 - pc2) (f' - f_avg) / (f_max - f_avg)   if f' >= f_avg, else pc1
    pm = pm1 - (pm1 - pm2) (f  - f_avg) / (f_max - f_avg)   if f  >= f_avg, else pm1

f' is the larger fitness of the two parents to cross, f the fitness of the individual to
mutate. (Seed 002's printed equation is lost in the text; this is the rule it names, in
the variant with non-zero pc2/pm2 at the best so the best is never frozen.)
"""

from __future__ import annotations

import numpy as np

__all__ = ["adaptive_probability", "adaptive_crossover_probability",
           "adaptive_mutation_probability"]


def adaptive_probability(fitness: np.ndarray, f_max: float, f_avg: float,
                         p_high: float, p_low: float) -> np.ndarray:
    """p_high for fitness <= f_avg, linear down to p_low at f_max (vectorised)."""
    fitness = np.asarray(fitness, dtype=float)
    spread = f_max - f_avg
    if not spread > 0.0:
        return np.full(fitness.shape, p_high)
    frac = np.clip((fitness - f_avg) / spread, 0.0, 1.0)
    return p_high - (p_high - p_low) * frac


def adaptive_crossover_probability(fitness_a: np.ndarray, fitness_b: np.ndarray,
                                   f_max: float, f_avg: float, pc1: float,
                                   pc2: float) -> np.ndarray:
    """pc per pair from the larger of the two parents' fitness."""
    return adaptive_probability(np.maximum(fitness_a, fitness_b), f_max, f_avg, pc1, pc2)


def adaptive_mutation_probability(fitness: np.ndarray, f_max: float, f_avg: float,
                                  pm1: float, pm2: float) -> np.ndarray:
    """pm per individual from its own fitness."""
    return adaptive_probability(fitness, f_max, f_avg, pm1, pm2)
