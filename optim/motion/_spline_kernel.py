"""Compiled part of :mod:`.spline_proof` (numba): the smoothed spline proven on the sphere cover.

The path ``q(s)`` is piecewise polynomial (``breaks (K+1,)``, ``coefs (K, W, n)`` ascending in
``s − breaks[k]``); ``T(s)`` is a cumulative travel bound of the arm's points (linear between
``nodes``, :func:`.smoothing._travel_bound`): between any ``s_a < s_b`` no point of the planned
arm moves more than ``T(s_b) − T(s_a)``. ``E(x)`` is the cover's lower bound of the excess
``min_k (d_k − margin_k)`` (:func:`._fast_kernel.state_excess`, capped), 1-Lipschitz in that
travel: an interval whose ends have ``E_a + E_b ≥ T(s_b) − T(s_a)`` keeps every margin (the
ladder's rule, :func:`pinarms.robots.cell.ladder.interval_proven`). An interval not proven is halved at
the middle of its travel bound, first in, first out, down to the exact proof's finest travel.
What is not proven — an end the cover does not prove clear, an end outside the joint limits, an
interval still unproven at the finest travel, the state budget spent — is returned as a range
of ``s`` for the exact proof: never called clear here. Cached on disk like the search's kernels.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pinarms.compiled import drop_stale_caches, jit
from pinarms.optim.motion import _fast_kernel
from pinarms.optim.motion._fast_kernel import state_scaled
from pinarms.robots.cell import box_kernel, cover_kernel, ladder
from pinarms.robots.cell.ladder import interval_proven

# these kernels call the search's state check, the cover's kernels and the ladder's rule (pinarms.compiled)
drop_stale_caches([Path(box_kernel.__file__), Path(cover_kernel.__file__), Path(ladder.__file__),
                   Path(_fast_kernel.__file__), Path(__file__)],
                  "spline_kernels.sha256")

#: Most intervals waiting at once (more: the rest is left to the exact proof).
QUEUE = 1 << 15


@jit
def _last_at_most(a, v):
    """The largest ``k`` in ``[0, a.size − 2]`` with ``a[k] ≤ v`` (0 below ``a[0]``); ``a`` ascending."""
    lo, hi = 0, a.shape[0] - 2
    if hi < 0:
        return 0
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if a[mid] <= v:
            lo = mid
        else:
            hi = mid - 1
    return lo


@jit
def q_at(breaks, coefs, s, out):
    """``q(s)`` into ``out (n,)`` (Horner on the piece ``s`` lies in; the last piece past the end)."""
    k = _last_at_most(breaks, s)
    sigma = s - breaks[k]
    top = coefs.shape[1] - 1
    for j in range(out.shape[0]):
        v = coefs[k, top, j]
        for d in range(top - 1, -1, -1):
            v = v * sigma + coefs[k, d, j]
        out[j] = v


@jit
def bound_at(nodes, T, s):
    """``T(s)``: the cumulative travel bound, linear between its nodes (clamped to its ends)."""
    j = _last_at_most(nodes, s)
    width = nodes[j + 1] - nodes[j]
    t = 1.0 if width <= 0.0 else min(max((s - nodes[j]) / width, 0.0), 1.0)
    return T[j] + (T[j + 1] - T[j]) * t


@jit
def _middle(nodes, T, sa, sb):
    """The position between ``sa < sb`` where ``T`` reaches the middle of its values at both (the middle
    of ``s`` when that is not strictly inside: a flat or rounded bound)."""
    ta, tb = bound_at(nodes, T, sa), bound_at(nodes, T, sb)
    goal = 0.5 * (ta + tb)
    j = _last_at_most(T, goal)
    rise = T[j + 1] - T[j]
    s = nodes[j] if rise <= 0.0 else nodes[j] + (goal - T[j]) / rise * (nodes[j + 1] - nodes[j])
    if not (sa < s < sb):
        s = 0.5 * (sa + sb)
    return s


@jit
def _excess(s, breaks, coefs, lower, upper, inv, hold, cols, fk, cov, grp, cap, work, q, x):
    """``Ẽ(q(s))``: the cover's scaled excess (group weights ``1 / inv``) capped at ``cap``; −1 outside the
    joint limits (not proven here)."""
    q_at(breaks, coefs, s, x)
    for j in range(x.shape[0]):
        if x[j] < lower[j] or x[j] > upper[j]:
            return -1.0
    return state_scaled(x, inv, hold, cols, fk, cov, grp, cap, work, q)


@jit
def _push(queue, tail, sa, sb, ea, eb, block):
    queue[tail, 0], queue[tail, 1], queue[tail, 2], queue[tail, 3], queue[tail, 4] = sa, sb, ea, eb, block
    return (tail + 1) % queue.shape[0]


#: The fields of a proof's state array ``st (6,) int64`` (kept between calls of :func:`spline_open`).
HEAD, TAIL, SIZE, COUNT, STATES, STARTED = range(6)


@jit
def spline_open(breaks, coefs, nodes, T, s0, block, inv, lower, upper, min_budget, max_states, hold, cols, fk, cov,
                grp, cap, work, opened, queue, st, stop):
    """Prove the path between the samples ``s0`` (ascending, its ends included) on the cover (module docstring).

    ``inv (B, G)``: the groups' inverse weights of each block of first intervals, ``block (n0,)``
    the block of each (:func:`.spline_proof._group_weights`): on a block, the distance of the
    pairs of group ``g`` changes at most ``1 / inv[b, g]`` times as fast as ``T``, so the scaled
    excess ``min_k inv · ê_k`` is 1-Lipschitz in ``T`` there. ``opened (M, 2)``: receives the
    ranges ``[s_a, s_b]`` left to the exact proof. ``min_budget``: intervals of less travel still
    unproven are left open; ``max_states``: most states evaluated (the intervals left then are open).

    ``queue (QUEUE, 5)`` and ``st`` (:data:`HEAD` …: all 0 at first) hold the proof between calls: a
    call returns once ``stop`` ranges are open in all (or the queue is empty: ``st[SIZE] == 0``) and
    the next call goes on from there. Returns the ranges open so far, or −1 when they did not fit
    (then nothing is proven here)."""
    n = cols.shape[0]
    q = np.empty(hold.shape[0])
    x = np.empty(n)
    head, tail, size, count, states = st[HEAD], st[TAIL], st[SIZE], st[COUNT], st[STATES]
    if st[STARTED] == 0:
        st[STARTED] = 1
        last = -1
        eb = 0.0
        for i in range(s0.shape[0] - 1):
            b = block[i]
            if b != last:  # the start of a block: its first end under the block's weights
                eb = _excess(s0[i], breaks, coefs, lower, upper, inv[b], hold, cols, fk, cov, grp, cap, work, q, x)
                states += 1
                last = b
            ea = eb
            eb = _excess(s0[i + 1], breaks, coefs, lower, upper, inv[b], hold, cols, fk, cov, grp, cap, work, q, x)
            states += 1
            if size == QUEUE:
                return -1
            tail = _push(queue, tail, s0[i], s0[i + 1], ea, eb, b)
            size += 1
    while size > 0 and count < stop:
        sa, sb, ea, eb, b = queue[head, 0], queue[head, 1], queue[head, 2], queue[head, 3], int(queue[head, 4])
        head = (head + 1) % QUEUE
        size -= 1
        budget = bound_at(nodes, T, sb) - bound_at(nodes, T, sa)
        if ea >= 0.0 and eb >= 0.0 and interval_proven(ea, eb, budget):
            continue
        sm = _middle(nodes, T, sa, sb)
        em = -1.0
        if ea >= 0.0 and eb >= 0.0 and budget >= min_budget and states < max_states and size + 2 <= QUEUE:
            tm = bound_at(nodes, T, sm)
            half = max(tm - bound_at(nodes, T, sa), bound_at(nodes, T, sb) - tm)
            # Ẽ at the midpoint is needed up to the larger half's travel, no more (a smaller cap prunes more pairs)
            em = _excess(sm, breaks, coefs, lower, upper, inv[b], hold, cols, fk, cov, grp, min(cap, half), work, q, x)
            states += 1
        if em < 0.0:
            if count == opened.shape[0]:
                return -1
            opened[count, 0], opened[count, 1] = sa, sb
            count += 1
            continue
        tail = _push(queue, tail, sa, sm, ea, em, b)
        tail = _push(queue, tail, sm, sb, em, eb, b)
        size += 2
    st[HEAD], st[TAIL], st[SIZE], st[COUNT], st[STATES] = head, tail, size, count, states
    return count


@jit
def _slope_peak(c1, c2, c3, a, b):
    """``max |c1 + 2 c2 t + 3 c3 t²|`` over ``[a, b]``: at an end or at the vertex of the quadratic."""
    best = max(abs(c1 + a * (2.0 * c2 + 3.0 * c3 * a)), abs(c1 + b * (2.0 * c2 + 3.0 * c3 * b)))
    if c3 != 0.0:
        v = -c2 / (3.0 * c3)
        if a < v < b:
            best = max(best, abs(c1 + v * (2.0 * c2 + 3.0 * c3 * v)))
    return best


@jit
def travel_parts(breaks, coefs, levers, step, fine, safety):
    """:func:`.smoothing._travel_parts` of a path of degree ≤ 3: ``(nodes (M+1,), T (M+1,), V (M, n))``.

    Piece ``k`` is cut in ``max(1, ⌈fine · P_k h_k / step⌉)`` equal parts (``P_k``: the piece's peak of
    ``Σ_j ℓ_j |q_j'|``); on each, ``V`` holds every joint's exact peak of ``|q_j'|`` (the quadratic's
    ends and vertex) and ``T`` grows by ``safety · (V · ℓ) ·`` the part's length."""
    K, W, n = coefs.shape
    m = np.empty(K, dtype=np.int64)
    total = 0
    for k in range(K):
        h = breaks[k + 1] - breaks[k]
        peak = 0.0
        for j in range(n):
            c2 = coefs[k, 2, j] if W > 2 else 0.0
            c3 = coefs[k, 3, j] if W > 3 else 0.0
            peak += _slope_peak(coefs[k, 1, j], c2, c3, 0.0, h) * levers[j]
        m[k] = max(1, int(np.ceil(fine * peak * h / step * (1.0 + 1e-12))))
        total += m[k]
    nodes = np.empty(total + 1)
    T = np.empty(total + 1)
    V = np.empty((total, n))
    nodes[0], T[0] = breaks[0], 0.0
    p = 0
    for k in range(K):
        h = breaks[k + 1] - breaks[k]
        for i in range(m[k]):
            t0, t1 = h * i / m[k], h * (i + 1) / m[k]
            density = 0.0
            for j in range(n):
                c2 = coefs[k, 2, j] if W > 2 else 0.0
                c3 = coefs[k, 3, j] if W > 3 else 0.0
                V[p, j] = _slope_peak(coefs[k, 1, j], c2, c3, t0, t1)
                density += V[p, j] * levers[j]
            nodes[p + 1] = breaks[k + 1] if i == m[k] - 1 else breaks[k] + t1  # a piece's last part ends on its break
            T[p + 1] = T[p] + density * (nodes[p + 1] - nodes[p]) * safety
            p += 1
    return nodes, T, V


@jit
def _cubic_at(c0, c1, c2, c3, t):
    return c0 + t * (c1 + t * (c2 + t * c3))


@jit
def outside_limits(breaks, coefs, lower, upper, out):
    """``out[k]``: whether piece ``k`` of a path of degree ≤ 3 leaves ``[lower, upper]`` in some joint (its
    extrema: the piece's ends and the real roots of the quadratic ``q'`` inside it)."""
    K, W, n = coefs.shape
    for k in range(K):
        h = breaks[k + 1] - breaks[k]
        out[k] = False
        for j in range(n):
            c0 = coefs[k, 0, j]
            c1 = coefs[k, 1, j] if W > 1 else 0.0
            c2 = coefs[k, 2, j] if W > 2 else 0.0
            c3 = coefs[k, 3, j] if W > 3 else 0.0
            lo = min(c0, _cubic_at(c0, c1, c2, c3, h))
            hi = max(c0, _cubic_at(c0, c1, c2, c3, h))
            a, b, c = 3.0 * c3, 2.0 * c2, c1  # q' = a t² + b t + c
            if a != 0.0:
                disc = b * b - 4.0 * a * c
                if disc >= 0.0:
                    r = np.sqrt(disc)
                    for t in ((-b - r) / (2.0 * a), (-b + r) / (2.0 * a)):
                        if 0.0 < t < h:
                            v = _cubic_at(c0, c1, c2, c3, t)
                            lo, hi = min(lo, v), max(hi, v)
            elif b != 0.0:
                t = -c / b
                if 0.0 < t < h:
                    v = _cubic_at(c0, c1, c2, c3, t)
                    lo, hi = min(lo, v), max(hi, v)
            if lo < lower[j] or hi > upper[j]:
                out[k] = True
                break
