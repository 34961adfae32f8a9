"""Compiled loop of :func:`pinarms.planning.extrema.piece_extrema` (numba) for next derivatives of degree <= 4.

The same operations in the same order as the numpy code (derivative coefficients, the degree
of each next derivative, its real roots in closed form up to degree 3, Horner at the piece
ends and the roots), one piece, joint and order at a time, without the numpy calls' overhead
(about 40 of them per call, which dominated the timing of a short trajectory). A next
derivative of degree 4 (the velocity of a degree-6 piece, as the time-optimal timing's
pieces are) has its sign changes in [0, 1] found between the roots of its own derivative
(Newton steps kept in the bracket) where the numpy code takes companion-matrix eigenvalues:
the same extrema (a complex pair or a root without sign change is no extremum), to rounding.
Higher degrees stay on the numpy path.
"""

from __future__ import annotations

import numpy as np

from pinarms.compiled import jit

__all__ = ["extrema_values", "multi_quintic_peaks", "MAX_WIDTH"]

#: Widest piece (coefficients, degree + 1) the kernel takes: a next derivative of degree <= 4 for orders >= 1.
MAX_WIDTH = 7


@jit
def _falling(k, r):
    """``k (k-1) ... (k-r+1)`` as a float (1 for r = 0)."""
    f = 1.0
    for i in range(r):
        f *= k - i
    return f


@jit
def _roots(R, d, out):
    """Real parts of the roots of ``R[0] + ... + R[d] s^d`` (1 <= d <= 3) into ``out[:d]``, as the numpy code."""
    if d == 1:
        out[0] = -R[0] / R[1]
    elif d == 2:
        a, b, c = R[2], R[1], R[0]
        sq = np.sqrt(max(b * b - 4.0 * a * c, 0.0))
        q = -0.5 * (b + np.copysign(sq, b))
        out[0] = q / a
        out[1] = c / q if q != 0.0 else 0.0
    else:
        inv = 1.0 / R[3]
        B3 = R[2] * inv / 3.0
        C = R[1] * inv
        p = C - 3.0 * B3 * B3
        q = B3 * (2.0 * B3 * B3 - C) + R[0] * inv
        disc = 0.25 * q * q + p * p * p / 27.0
        if disc > 0.0:
            u = np.cbrt(-0.5 * q - np.copysign(np.sqrt(max(disc, 0.0)), q))
            y1 = u - p / (3.0 * u) if u != 0.0 else 0.0
            out[0] = y1 - B3
            out[1] = -0.5 * y1 - B3
            out[2] = -0.5 * y1 - B3
        else:
            mag = 2.0 * np.sqrt(max(-p, 0.0) / 3.0)
            arg = -4.0 * q / (mag * mag * mag) if mag > 0.0 else 1.0
            theta = np.arccos(min(max(arg, -1.0), 1.0)) / 3.0
            third = 2.0 * np.pi / 3.0
            for k in range(3):
                out[k] = mag * np.cos(theta - third * k) - B3


@jit
def _quartic_value(R, x):
    return (((R[4] * x + R[3]) * x + R[2]) * x + R[1]) * x + R[0]


@jit
def _quartic_roots(R, out):
    """The real roots in [0, 1] where ``R[0] + ... + R[4] s^4`` (R[4] != 0) changes sign, into ``out[:4]``; returns
    how many. Between two of the roots of its derivative (a cubic, closed form) it is monotone: a sign change
    there is one root, found by Newton steps kept inside the bracket (bisection when a step leaves it). A root
    where it touches zero without changing sign is no extremum of the integral, and a complex pair none either:
    the extrema found are those of the numpy route's eigenvalues."""
    D = np.zeros(4)
    for k in range(4):
        D[k] = (k + 1) * R[k + 1]
    crit = np.zeros(3)
    big = max(max(abs(D[0]), abs(D[1])), max(abs(D[2]), abs(D[3])))
    d = 0
    for k in range(4):
        if abs(D[k]) > 1e-12 * big:
            d = k
    if d >= 1:
        _roots(D, d, crit)
    ends = np.zeros(5)
    ends[0] = 0.0
    m = 1
    for k in range(d):
        x = min(max(crit[k], 0.0), 1.0)
        ends[m] = x
        m += 1
    ends[m] = 1.0
    m += 1
    ends[:m].sort()
    count = 0
    for k in range(1, m - 1):  # a root at a critical point (of odd multiplicity: a sign change) is found here
        if _quartic_value(R, ends[k]) == 0.0 and ends[k] != ends[k - 1] and count < 4:
            out[count] = ends[k]
            count += 1
    for k in range(m - 1):
        lo, hi = ends[k], ends[k + 1]
        flo, fhi = _quartic_value(R, lo), _quartic_value(R, hi)
        if hi <= lo or flo == 0.0 or fhi == 0.0 or (flo < 0.0) == (fhi < 0.0):
            continue
        x = 0.5 * (lo + hi)
        for _ in range(100):
            fx = _quartic_value(R, x)
            if fx == 0.0:
                break
            if (fx < 0.0) == (flo < 0.0):
                lo = x
            else:
                hi = x
            dfx = ((4.0 * R[4] * x + 3.0 * R[3]) * x + 2.0 * R[2]) * x + R[1]
            step = x - fx / dfx if dfx != 0.0 else 0.5 * (lo + hi)
            nxt = step if lo < step < hi else 0.5 * (lo + hi)
            if abs(nxt - x) <= 4e-16 * max(abs(x), 1e-300) or hi - lo <= 4e-16:
                x = nxt
                break
            x = nxt
        if count < 4:
            out[count] = x
            count += 1
    return count


@jit
def _derivatives(c, r, scale, W, P, R):
    """Fill ``P`` with the coefficients of the ``r``-th derivative of the piece ``c (W,)`` (normalised
    time, times ``scale``) and ``R`` with those of the next one (unscaled: only its roots matter);
    return the degree of ``R`` (its coefficients below 1e-12 of its largest count as zero)."""
    for k in range(W):
        P[k] = c[k + r] * _falling(k + r, r) * scale if k + r < W else 0.0
    top = 0.0
    for k in range(R.shape[0]):
        R[k] = c[k + r + 1] * _falling(k + r + 1, r + 1) if k + r + 1 < W else 0.0
        top = max(top, abs(R[k]))
    threshold = 1e-12 * top
    d = 0
    if threshold != 0.0:
        for k in range(R.shape[0]):
            if abs(R[k]) > threshold:
                d = k
    return d


@jit
def extrema_values(normalised, durations, orders):
    """``(values (o, M, n, C), s (o * M * n, C))`` of :func:`pinarms.planning.extrema.piece_extrema`.

    ``normalised (M, n, W)`` with W <= :data:`MAX_WIDTH`, ``durations (M,)``, ``orders (o,)`` every
    order >= 1; C = 2 + max(W - 2, 1): the piece ends, then the clipped roots (zero padded).
    """
    M, n, W = normalised.shape
    o = orders.shape[0]
    nroot = max(W - 2, 1)
    C = nroot + 2
    values = np.zeros((o, M, n, C))
    s = np.zeros((o * M * n, C))
    P = np.zeros(W)
    R = np.zeros(max(W - 1, 1))
    roots = np.zeros(4)
    for a in range(o):
        r = orders[a]
        for i in range(M):
            scale = durations[i] ** -float(r)
            for j in range(n):
                d = _derivatives(normalised[i, j], r, scale, W, P, R)
                row = (a * M + i) * n + j
                s[row, 1] = 1.0
                if d == 4:
                    for k in range(_quartic_roots(R, roots)):
                        s[row, 2 + k] = roots[k]
                elif d >= 1:
                    _roots(R, d, roots)
                    for k in range(d):
                        s[row, 2 + k] = min(max(roots[k], 0.0), 1.0)
                for m in range(C):
                    x = s[row, m]
                    v = 0.0
                    for k in range(W - 1, -1, -1):
                        v = v * x + P[k]
                    values[a, i, j, m] = v
    return values, s


@jit
def _piece_peaks(c, h, W, orders, top, P, R, roots):
    """Raise ``top[a]`` to the peak of ``|d^r q / dt^r|`` (r = ``orders[a]``) on one piece ``c (W,)`` (normalised)."""
    for a in range(orders.shape[0]):
        r = orders[a]
        scale = h ** -float(r)
        d = _derivatives(c, r, scale, W, P, R)
        if d >= 1:
            _roots(R, d, roots)
        for m in range(2 + d):
            x = float(m) if m < 2 else min(max(roots[m - 2], 0.0), 1.0)
            v = 0.0
            for k in range(W - 1, -1, -1):
                v = v * x + P[k]
            if abs(v) > top[a]:
                top[a] = abs(v)


@jit
def multi_quintic_peaks(times, positions, heuristic):
    """Peaks ``(P, 3, n)`` of |velocity|, |acceleration|, |jerk| of multi-quintic trajectories.

    ``times (P, m+1)`` strictly increasing knot times, ``positions (m+1, n)`` shared via points;
    via velocities by the sign-of-slopes rule (``heuristic``) or zero, via accelerations zero
    (:func:`pinarms.planning.multi_quintic_batch` with ``velocities="heuristic"``/None, then
    :func:`pinarms.planning.peaks_batch`, in the same operations).
    """
    Pn, m1 = times.shape
    m = m1 - 1
    n = positions.shape[1]
    out = np.zeros((Pn, 3, n))
    orders = np.array([1, 2, 3])
    v = np.zeros((m1, n))
    c = np.zeros(6)
    Pc = np.zeros(6)
    R = np.zeros(5)
    roots = np.zeros(3)
    top = np.zeros(3)
    for p in range(Pn):
        for j in range(n):
            for k in range(1, m):
                if heuristic:
                    s0 = (positions[k, j] - positions[k - 1, j]) / (times[p, k] - times[p, k - 1])
                    s1 = (positions[k + 1, j] - positions[k, j]) / (times[p, k + 1] - times[p, k])
                    v[k, j] = 0.5 * (s0 + s1) if np.sign(s0) == np.sign(s1) else 0.0
        for i in range(m):
            H = times[p, i + 1] - times[p, i]
            for j in range(n):
                q0, q1 = positions[i, j], positions[i + 1, j]
                v0, v1 = v[i, j], v[i + 1, j]
                d = q1 - q0
                c[0] = q0
                c[1] = v0
                c[2] = 0.5 * 0.0
                c[3] = (20.0 * d - (8.0 * v1 + 12.0 * v0) * H - (3.0 * 0.0 - 0.0) * H ** 2.0) / (2.0 * H ** 3.0)
                c[4] = (-30.0 * d + (14.0 * v1 + 16.0 * v0) * H + (3.0 * 0.0 - 2.0 * 0.0) * H ** 2.0) / (2.0 * H ** 4.0)
                c[5] = (12.0 * d - 6.0 * (v1 + v0) * H + (0.0 - 0.0) * H ** 2.0) / (2.0 * H ** 5.0)
                for k in range(6):
                    c[k] = c[k] * H ** float(k)
                top[:] = 0.0
                _piece_peaks(c, H, 6, orders, top, Pc, R, roots)
                for a in range(3):
                    if top[a] > out[p, a, j]:
                        out[p, a, j] = top[a]
    return out
