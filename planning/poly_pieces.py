"""Arrays of polynomial pieces: derivatives, re-expansion about a new origin, padding, blocked evaluation.

Pieces are stored as coefficients ``(m, K+1, n)``: piece i, ascending powers of the local
variable (the time since the piece's start for a :class:`pinarms.planning.Trajectory`), one column
per joint. These functions work on such arrays, for every piece and joint at once.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["derivative_stack", "taylor_shift", "pad_degree", "evaluate_by_piece", "matmul_rows", "GEMM_ONE_THREAD"]

# OpenBLAS runs a matrix product on several threads above M·N·K = 4 · 65536: on a busy machine
# those threads wait for cores and a 10 000 × 6 by 6 × 24 product takes 1-30 ms instead of
# 0.1 ms. Sampling multiplies in row blocks below that size (one thread each).
GEMM_ONE_THREAD = 4 * 65536


def derivative_stack(c: np.ndarray) -> np.ndarray:
    """(m, K+1, 4*n): coefficients of q, qd, qdd, qddd side by side, from pieces ``c`` (m, K+1, n)."""
    m, width, n = c.shape
    stack = np.zeros((m, width, 4 * n))
    k = np.arange(width, dtype=float)
    falling = np.ones(width)
    for r in range(4):  # d^r/dτ^r of Σ c_k τ^k: coefficient j is c_(j+r) · (j+r)!/j!
        if r:
            falling = falling[1:] * k[1 : width - r + 1]  # (j+r)!/j! = ((j+1)+(r−1))!/(j+1)! · (j+1)
        if r < width:
            np.multiply(c[:, r:, :], falling[None, :, None], out=stack[:, : width - r, r * n : (r + 1) * n])
    return stack


def taylor_shift(coefs: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Re-expand pieces about a later origin: coefficients of ``q(offset + u)`` in ``u``.

    ``coefs`` (m, K+1, n) ascending powers; ``offset`` (m,) in s. Returns (m, K+1, n).
    """
    width = coefs.shape[1]
    i = np.arange(width)
    binom = np.array([[math.comb(int(b), int(a)) if b >= a else 0 for b in i] for a in i], dtype=float)
    expo = np.clip(i[None, :] - i[:, None], 0, None)
    M = binom[None] * np.asarray(offset, dtype=float)[:, None, None] ** expo[None]
    M = np.where((i[None, :] >= i[:, None])[None], M, 0.0)
    return np.einsum("ski,sij->skj", M, coefs)


def pad_degree(coefs: np.ndarray, width: int) -> np.ndarray:
    """Zero-pad coefficients (m, K+1, n) to (m, width, n)."""
    if coefs.shape[1] == width:
        return coefs
    out = np.zeros((coefs.shape[0], width, coefs.shape[2]))
    out[:, : coefs.shape[1]] = coefs
    return out


def evaluate_by_piece(powers: np.ndarray, D: np.ndarray, seg: np.ndarray | None, out: np.ndarray) -> None:
    """``out[i] = powers[i] @ D[seg[i]]``, grouped by piece (``seg`` None: one piece)."""
    m = D.shape[0]
    if m == 1:
        matmul_rows(powers, D[0], out)
    else:
        sorted_input = seg.size < 2 or bool(np.all(seg[1:] >= seg[:-1]))
        order = None if sorted_input else np.argsort(seg, kind="stable")
        seg_sorted = seg if order is None else seg[order]
        edges = np.searchsorted(seg_sorted, np.arange(m + 1))
        for s in np.flatnonzero(np.diff(edges)):
            lo, hi = edges[s], edges[s + 1]
            if order is None:
                matmul_rows(powers[lo:hi], D[s], out[lo:hi])
            else:
                idx = order[lo:hi]
                out[idx] = powers[idx] @ D[s]


def matmul_rows(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
    """``out = a @ b`` in row blocks small enough for OpenBLAS to use one thread (see ``GEMM_ONE_THREAD``)."""
    rows = max(1, GEMM_ONE_THREAD // max(1, a.shape[1] * b.shape[1]))
    if a.shape[0] <= rows:
        np.matmul(a, b, out=out)
        return
    for s in range(0, a.shape[0], rows):
        np.matmul(a[s : s + rows], b, out=out[s : s + rows])
