"""Real-coded mutation, vectorised, results kept inside the bounds.

``probability`` is per gene: a scalar or one value per individual (adaptive pm).
"""

from __future__ import annotations

import numpy as np

__all__ = ["non_uniform", "polynomial"]


def _mask(shape: tuple[int, int], probability: float | np.ndarray,
          rng: np.random.Generator) -> np.ndarray:
    p = np.asarray(probability, dtype=float)
    if p.ndim == 1:
        p = p[:, None]
    return rng.random(shape) < p


def non_uniform(x: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                probability: float | np.ndarray, generation: int, max_generations: int,
                shape: float, rng: np.random.Generator) -> np.ndarray:
    """Non-uniform mutation (Michalewicz 1992), the formula of seed 002.

    A mutated gene moves towards the upper or the lower bound with equal chance::

        X' = X + (X_U - X) * (1 - r ** ((1 - g/G) ** c))
        X' = X - (X - X_L) * (1 - r ** ((1 - g/G) ** c))

    with ``r ~ U(0, 1)``, g the generation, G the generation budget and c the shape
    (seed 002: c = 2). The step shrinks to 0 as g -> G, so the search turns local.
    """
    x = np.asarray(x, dtype=float)
    mask = _mask(x.shape, probability, rng)
    r = rng.random(x.shape)
    progress = min(max(generation / max(max_generations, 1), 0.0), 1.0)
    step = 1.0 - np.power(r, (1.0 - progress) ** shape)
    up = rng.random(x.shape) < 0.5
    moved = np.where(up, x + (upper - x) * step, x - (x - lower) * step)
    return np.clip(np.where(mask, moved, x), lower, upper)


def polynomial(x: np.ndarray, lower: np.ndarray, upper: np.ndarray,
               probability: float | np.ndarray, eta: float,
               rng: np.random.Generator) -> np.ndarray:
    """Polynomial mutation, bounded form (Deb and Goyal 1996; as in NSGA-II)."""
    x = np.asarray(x, dtype=float)
    mask = _mask(x.shape, probability, rng)
    span = np.maximum(upper - lower, 1e-300)
    d1 = (x - lower) / span
    d2 = (upper - x) / span
    u = rng.random(x.shape)
    power = 1.0 / (eta + 1.0)
    left = u < 0.5
    val_l = 2.0 * u + (1.0 - 2.0 * u) * np.power(1.0 - d1, eta + 1.0)
    val_r = 2.0 * (1.0 - u) + 2.0 * (u - 0.5) * np.power(1.0 - d2, eta + 1.0)
    delta = np.where(left, np.power(val_l, power) - 1.0, 1.0 - np.power(val_r, power))
    return np.clip(np.where(mask, x + delta * span, x), lower, upper)
