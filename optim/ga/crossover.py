"""Real-coded crossover of parent pairs, vectorised, children kept inside the bounds.

Parents come as two (n, dim) arrays (pair i = ``a[i]``, ``b[i]``); a pair is crossed with
probability ``probability`` (a scalar or one value per pair, for adaptive pc), otherwise
the children are copies of the parents.
"""

from __future__ import annotations

import numpy as np

__all__ = ["sbx", "arithmetic", "blend"]


def _crossed(n: int, probability: float | np.ndarray, rng: np.random.Generator) -> np.ndarray:
    return rng.random(n) < np.broadcast_to(np.asarray(probability, dtype=float), (n,))


def sbx(a: np.ndarray, b: np.ndarray, lower: np.ndarray, upper: np.ndarray,
        probability: float | np.ndarray, eta: float,
        rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Simulated binary crossover, bounded form (Deb and Agrawal 1995; Deb 2000).

    Each gene of a crossed pair is recombined with probability 1/2. The spread factor
    follows the polynomial distribution of index ``eta``, truncated so that children
    stay within ``[lower, upper]``.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    n, dim = a.shape
    c1, c2 = a.copy(), b.copy()
    gene = _crossed(n, probability, rng)[:, None] & (rng.random((n, dim)) < 0.5)
    gene &= np.abs(a - b) > 1e-14
    y1 = np.minimum(a, b)
    y2 = np.maximum(a, b)
    span = np.where(gene, y2 - y1, 1.0)
    u = rng.random((n, dim))
    exponent = 1.0 / (eta + 1.0)

    def child(beta_bound: np.ndarray) -> np.ndarray:
        alpha = 2.0 - np.power(beta_bound, -(eta + 1.0))
        beta_q = np.where(u <= 1.0 / alpha, np.power(u * alpha, exponent),
                          np.power(1.0 / np.maximum(2.0 - u * alpha, 1e-300), exponent))
        return beta_q

    beta_low = 1.0 + 2.0 * (y1 - lower) / span
    beta_up = 1.0 + 2.0 * (upper - y2) / span
    low = 0.5 * ((y1 + y2) - child(beta_low) * (y2 - y1))
    up = 0.5 * ((y1 + y2) + child(beta_up) * (y2 - y1))
    low = np.clip(low, lower, upper)
    up = np.clip(up, lower, upper)
    swap = rng.random((n, dim)) < 0.5
    first = np.where(swap, up, low)
    second = np.where(swap, low, up)
    c1[gene] = first[gene]
    c2[gene] = second[gene]
    return c1, c2


def arithmetic(a: np.ndarray, b: np.ndarray, lower: np.ndarray, upper: np.ndarray,
               probability: float | np.ndarray,
               rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Arithmetic (whole) crossover: ``c1 = w a + (1-w) b``, ``c2 = (1-w) a + w b``.

    One weight ``w ~ U(0, 1)`` per crossed pair; convex combinations stay in the box.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    n = a.shape[0]
    w = rng.random((n, 1))
    crossed = _crossed(n, probability, rng)[:, None]
    c1 = np.where(crossed, w * a + (1.0 - w) * b, a)
    c2 = np.where(crossed, (1.0 - w) * a + w * b, b)
    return np.clip(c1, lower, upper), np.clip(c2, lower, upper)


def blend(a: np.ndarray, b: np.ndarray, lower: np.ndarray, upper: np.ndarray,
          probability: float | np.ndarray, alpha: float,
          rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """BLX-alpha (Eshelman and Schaffer 1993): genes uniform on the parents' interval
    extended by ``alpha`` times its length on each side, then limited to the bounds."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    n, dim = a.shape
    lo = np.minimum(a, b)
    hi = np.maximum(a, b)
    d = hi - lo
    crossed = _crossed(n, probability, rng)[:, None]
    c1 = lo - alpha * d + rng.random((n, dim)) * (1.0 + 2.0 * alpha) * d
    c2 = lo - alpha * d + rng.random((n, dim)) * (1.0 + 2.0 * alpha) * d
    c1 = np.where(crossed, c1, a)
    c2 = np.where(crossed, c2, b)
    return np.clip(c1, lower, upper), np.clip(c2, lower, upper)
