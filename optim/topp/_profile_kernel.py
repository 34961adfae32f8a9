"""Compiled loops of :mod:`pinarms.optim.topp.profile` (numba): the backward pass and the greedy forward pass.

Each step of both passes is a minimum and a maximum of rows ``slope · y + offset`` over every
row of one grid point (y: μ or λ of the next controllable set, or the state itself), the same
product and sum per row as the Python loops they replace, in the same order of grid points:
the same bits. A row that does not apply carries the neutral offset (+inf for an upper bound,
−inf for a lower one, :func:`pinarms.optim.topp.row_bounds.row_bounds`) and a zero slope, so it never
decides a minimum or a maximum; no row needs to be left out beforehand.
"""

from __future__ import annotations

import numpy as np

from pinarms.compiled import jit

__all__ = ["backward_pass", "forward_pass", "pair_states"]


@jit
def _lowest(slope, offset, i, y, start):
    """``min(start, min_k slope[i, k] y + offset[i, k])``."""
    best = start
    for k in range(slope.shape[1]):
        v = slope[i, k] * y + offset[i, k]
        if v < best:
            best = v
    return best


@jit
def _highest(slope, offset, i, y, start):
    """``max(start, max_k slope[i, k] y + offset[i, k])``."""
    best = start
    for k in range(slope.shape[1]):
        v = slope[i, k] * y + offset[i, k]
        if v > best:
            best = v
    return best


@jit
def backward_pass(Pu, Ou, Pl, Ol, Pz, Oz, Qu, Vu, Ql, Vl, Qz, Vz, up0, dn0, zero0, X, tol, K):
    """Controllable sets ``K`` (N+1, 2) backwards from ``K[N]`` (set by the caller).

    ``P*``/``O*``: the rows with μ of ``K_{i+1}`` (upper, lower, zero conditions), ``Q*``/``V*``
    those with λ; ``up0``, ``dn0``, ``zero0`` (N+1,) the λ rows reduced at λ = 0 (X folded in).
    Returns the grid point whose set is empty, or −1.
    """
    N = K.shape[0] - 1
    inf = np.inf
    for i in range(N - 1, -1, -1):
        lam = K[i + 1, 0]
        mu = K[i + 1, 1]
        if lam == 0.0:
            xhi, xlo, zero = up0[i], dn0[i], zero0[i]
        else:
            xhi = _lowest(Qu, Vu, i, lam, X[i, 1])
            xlo = _highest(Ql, Vl, i, lam, max(X[i, 0], 0.0))
            zero = _lowest(Qz, Vz, i, lam, inf)
        xhi = _lowest(Pu, Ou, i, mu, xhi)
        xlo = _highest(Pl, Ol, i, mu, xlo)
        zero = _lowest(Pz, Oz, i, mu, zero)
        if zero < -tol * max(1.0, abs(mu)) or mu < lam - tol * max(1.0, mu):
            xlo = inf
        if xlo > xhi + tol * max(1.0, abs(xhi)):
            return i
        K[i, 0] = xlo
        K[i, 1] = max(xlo, xhi)
    return -1


@jit
def forward_pass(up_s, up_o, dn_s, dn_o, delta, K, x_first, cap, xs, us):
    """The greedy pass from ``x_first``: the largest admissible ``u`` keeping ``x_{i+1}`` in ``K_{i+1}``
    (``u <= up_s x + up_o``, ``u >= dn_s x + dn_o``); fills ``xs`` (N+1,) and ``us`` (N,)."""
    N = delta.size
    xi = x_first
    xs[0] = xi
    for i in range(N):
        two = 2.0 * delta[i]
        k_lo = K[i + 1, 0]
        k_hi = K[i + 1, 1]
        upper = _lowest(up_s, up_o, i, xi, (k_hi - xi) / two)
        lower = _highest(dn_s, dn_o, i, xi, (k_lo - xi) / two)
        ui = lower if upper < lower else upper  # rounding only: stay controllable
        xn = min(max(xi + two * ui, k_lo), k_hi, cap)
        us[i] = (xn - xi) / two
        xs[i + 1] = xn
        xi = xn


@jit
def pair_states(a, b, lo, hi, lower, upper, xlo, xhi):
    """The x-interval each grid point's pairs of rows admit (:func:`pinarms.optim.topp.profile.feasible_states`).

    For a lower row ``(a, b, lo)`` and an upper row ``(a', b', hi')`` (``lower``/``upper`` say which
    rows are, a > 0) some u exists iff ``(a b' − a' b) x <= a hi' − a' lo``; ``xlo``, ``xhi`` (N,)
    are narrowed in place (``xlo = inf``: no x at all).
    """
    N, m = a.shape
    for i in range(N):
        top = np.inf
        bottom = -np.inf
        empty = False
        for l in range(m):
            if not lower[i, l]:
                continue
            for r in range(m):
                if not upper[i, r]:
                    continue
                c = a[i, l] * b[i, r] - a[i, r] * b[i, l]
                d = a[i, l] * hi[i, r] - a[i, r] * lo[i, l]
                if c > 0.0:
                    v = d / c
                    if v < top:
                        top = v
                elif c < 0.0:
                    v = d / c
                    if v > bottom:
                        bottom = v
                elif d < 0.0:
                    empty = True
        if top < xhi[i]:
            xhi[i] = top
        if bottom > xlo[i]:
            xlo[i] = bottom
        if empty:
            xlo[i] = np.inf
