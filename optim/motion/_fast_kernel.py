"""Compiled parts of :mod:`.fast` (numba): the edge proof on the cover, RRT-Connect and shortcutting.

A state is the planned arms' joint vector ``x``; the cell configuration is ``hold`` with
``x`` written at ``cols``. ``E(x)`` is the cover's lower bound of the excess
(:func:`pinarms.robots.cell.cover_kernel.excess_one`), capped at ``cap``. An edge ``x_a → x_b`` is
proven on the *scaled* excess ``Ẽ(x) = min_k ê_k(x) / w_g`` (:func:`excess_scaled`): ``w_g``
bounds how much the distance of the pairs of group ``g`` (two links, or a link and a
fixture) changes along the whole edge (``Σ_j |Δx_j| λ_{g,j}``, at most the whole-arm travel
``T = Σ |Δx_j| ℓ_j``; :mod:`.link_levers` states the Lipschitz argument); an interval
``[s_a, s_b]`` of the edge is proven when ``Ẽ_a + Ẽ_b ≥ s_b − s_a``, all ``Ẽ ≥ 0`` (the ladder's rule,
:func:`pinarms.robots.cell.ladder.interval_proven`, where the argument is written); ``Ẽ`` is
capped at ``cap / T`` (the pairs left out are more than ``cap`` above their thresholds).
An interval not proven is halved (splitting at the middle of the stretch its ends do not
prove instead checked as many states on the Panda scenes); intervals are taken first in,
first out (the middle of the edge first, then its quarters: an edge through an obstacle
fails after a few states; the middle even before the edge's start when the ends cannot prove the
whole edge: the same states and verdict, one state fewer when the middle fails); the new state's
``Ẽ`` is capped at the larger half's length. The random numbers are a SplitMix64 stream held in
an array: a search is the same for the same seed, whatever the chunks it is run in. Cached on
disk like the cover's kernels.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pinarms.compiled import drop_stale_caches, jit
from pinarms.robots.cell import box_kernel, cover_kernel, ladder
from pinarms.robots.cell.cover_kernel import excess_placed, place_moving
from pinarms.robots.cell.ladder import interval_proven

# these kernels call the cover's and the ladder's rule: their changes must compile them again (pinarms.compiled)
drop_stale_caches([Path(box_kernel.__file__), Path(cover_kernel.__file__), Path(ladder.__file__), Path(__file__)],
                  "fast_kernels.sha256")

#: Most intervals waiting in one edge proof (more: the edge counts as not proven).
QUEUE = 4096
ADVANCED, REACHED, TRAPPED = 0, 1, 2
#: When the smaller tree grows, this share of its samples is drawn near one of its own nodes (a random one):
#: within ``LOCAL_SPREAD`` times the search's range of it in every joint (inside the limits). A tree deep in
#: a narrow passage (an end in a crate under a guard) finds the way out sooner than from uniform samples,
#: most of whose long steps leave the passage through its walls. Measured (states checked per search,
#: median of the benchmark's 25 queries; in brackets of 100 searches, 4 seeds each): ``aubo_crate_guard``
#: 2266 -> 1612 (2856 -> 2441), ``panda_shelf`` 465 -> 385 (482 -> 437), ``aubo_two_belt`` 116 -> 103
#: (115 -> 106), ``panda_table_box`` 67 -> 88 (70 -> 76: searches of two or three rounds).
LOCAL_SHARE = 0.5
LOCAL_SPREAD = 0.5


@jit
def _uniform(rng):
    """The next number in [0, 1) of the SplitMix64 stream ``rng (1,) uint64``."""
    rng[0] += np.uint64(0x9E3779B97F4A7C15)
    z = rng[0]
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@jit
def state_excess(x, hold, cols, fk, cov, grp, cap, work, q):
    """``E(x)``: the cover's lower bound of the excess at planned state ``x`` (early out below 0).

    ``q``: scratch cell configuration ``(nq,)``, or ``(nq + 1,)`` whose last entry counts the calls."""
    return state_scaled(x, np.empty(0), hold, cols, fk, cov, grp, cap, work, q)  # not UNWEIGHTED: see there


@jit
def state_scaled(x, inv, hold, cols, fk, cov, grp, cap, work, q):
    """``Ẽ(x)``: the scaled excess at planned state ``x`` with group weights ``1 / inv`` (early out below 0;
    ``inv`` empty: the excess itself, :func:`state_excess`)."""
    n = hold.shape[0]
    if q.shape[0] > n:
        q[n] += 1.0
    for i in range(n):
        q[i] = hold[i]
    for j in range(cols.shape[0]):
        q[cols[j]] = x[j]
    # work: placed at hold once (FastCheck); per state only the planned arms' joints and the points on them
    place_moving(q, fk, cov, grp, work, work[6])
    return excess_placed(cov, grp, inv, cap, 0.0, work)


@jit
def edge_proven(xa, xb, levers, lam, min_budget, max_states, hold, cols, fk, cov, grp, cap, work, q, xm, queue, inv):
    """Whether the cover proves the straight edge ``xa → xb`` keeps every threshold (module docstring).

    ``lam (G, n)``: the groups' levers (:func:`.link_levers.group_levers`); ``inv (G,)``:
    scratch. ``min_budget``: intervals of less travel still unproven fail the edge (the finest
    level of the exact proof's ladder); so does an edge that needs more than ``max_states``
    states (one that runs long close to something: the search looks elsewhere, never calls it
    clear)."""
    T = 0.0
    for j in range(xa.shape[0]):
        T += abs(xb[j] - xa[j]) * levers[j]
    if T <= 0.0:
        return state_excess(xa, hold, cols, fk, cov, grp, cap, work, q) >= 0.0
    for g in range(inv.shape[0]):
        w = 0.0
        for j in range(xa.shape[0]):
            d = abs(xb[j] - xa[j])
            if d > 0.0:  # an unbounded lever (inf) of a joint that stays: no travel, not nan
                w += d * lam[g, j]
        inv[g] = 1.0 / max(min(w, T), 1e-12)  # a larger weight is still a bound
    c = min(cap / T, 1.0)
    eb = state_scaled(xb, inv, hold, cols, fk, cov, grp, c, work, q)  # the new end first: more often not clear
    if eb < 0.0:
        return False
    tail = 1
    if interval_proven(c, eb, 1.0):  # Ẽ_a ≤ c: the whole edge may be proven by its ends
        ea = state_scaled(xa, inv, hold, cols, fk, cov, grp, c, work, q)
        if ea < 0.0:
            return False
        if interval_proven(ea, eb, 1.0):
            return True
        queue[0, 0], queue[0, 1], queue[0, 2], queue[0, 3] = 0.0, 1.0, ea, eb
    else:  # no Ẽ_a proves [0, 1]: its middle is needed anyway, and fails an edge through something before its start
        if T < min_budget or max_states <= 0:
            return False
        max_states -= 1
        for j in range(xa.shape[0]):
            xm[j] = xa[j] + 0.5 * (xb[j] - xa[j])  # as the loop below places a middle
        em = state_scaled(xm, inv, hold, cols, fk, cov, grp, min(c, 0.5), work, q)
        if em < 0.0:
            return False
        ea = state_scaled(xa, inv, hold, cols, fk, cov, grp, c, work, q)
        if ea < 0.0:
            return False
        queue[0, 0], queue[0, 1], queue[0, 2], queue[0, 3] = 0.0, 0.5, ea, em
        queue[1, 0], queue[1, 1], queue[1, 2], queue[1, 3] = 0.5, 1.0, em, eb
        tail = 2
    head, n = 0, queue.shape[0]
    while head != tail:
        fa, fb, a, b = queue[head, 0], queue[head, 1], queue[head, 2], queue[head, 3]
        head = (head + 1) % n
        B = fb - fa
        if interval_proven(a, b, B):
            continue
        if T * B < min_budget or max_states <= 0:
            return False
        max_states -= 1
        fm = 0.5 * (fa + fb)
        for j in range(xa.shape[0]):
            xm[j] = xa[j] + fm * (xb[j] - xa[j])
        # Ẽ at the new state is needed up to the larger half's length, no more (a smaller cap prunes more pairs)
        em = state_scaled(xm, inv, hold, cols, fk, cov, grp, min(c, max(fm - fa, fb - fm)), work, q)
        if em < 0.0:
            return False
        queue[tail, 0], queue[tail, 1], queue[tail, 2], queue[tail, 3] = fa, fm, a, em
        tail = (tail + 1) % n
        if tail == head:  # full: not proven (never called clear)
            return False
        queue[tail, 0], queue[tail, 1], queue[tail, 2], queue[tail, 3] = fm, fb, em, b
        tail = (tail + 1) % n
        if tail == head:
            return False
    return True


@jit
def _nearest(nodes, count, x):
    best, arg = np.inf, 0
    for i in range(count):
        d = 0.0
        for j in range(x.shape[0]):
            e = nodes[i, j] - x[j]
            d += e * e
        if d < best:
            best, arg = d, i
    return arg


@jit
def _extend(t, nodes, parent, counts, target, step_range, levers, lam, min_budget, max_states, hold, cols, fk, cov,
            grp, cap, work, q, xm, xn, queue, inv):
    """One RRT step of tree ``t`` towards ``target``: ADVANCED, REACHED or TRAPPED (full tree: TRAPPED)."""
    count = counts[t]
    if count >= nodes.shape[1]:
        return TRAPPED
    near = _nearest(nodes[t], count, target)
    d = 0.0
    for j in range(target.shape[0]):
        e = target[j] - nodes[t, near, j]
        d += e * e
    d = math.sqrt(d)
    reach = d <= step_range
    for j in range(target.shape[0]):
        xn[j] = target[j] if reach else nodes[t, near, j] + (target[j] - nodes[t, near, j]) * (step_range / d)
    if not edge_proven(nodes[t, near], xn, levers, lam, min_budget, max_states, hold, cols, fk, cov, grp, cap, work,
                       q, xm, queue, inv):
        return TRAPPED
    for j in range(target.shape[0]):
        nodes[t, count, j] = xn[j]
    parent[t, count] = near
    counts[t] = count + 1
    return REACHED if reach else ADVANCED


@jit
def rrt_connect(nodes, parent, counts, status, rng, lower, upper, step_range, iterations, levers, lam, min_budget,
                max_states, hold, cols, fk, cov, grp, cap, work):
    """``iterations`` rounds of RRT-Connect between tree 0 (the start) and tree 1 (the goals).

    ``status (5,) int64``: [found, node of tree 0, node of tree 1, tree that grows next when the two
    are of one size, states checked so far]; the
    trees ``nodes (2, cap, n)``, ``parent``, ``counts`` are
    continued from call to call. Returns 1 when connected, 0 otherwise."""
    n = lower.shape[0]
    q = np.zeros(hold.shape[0] + 1)  # the last entry counts the states checked: status[4]
    xm = np.empty(n)
    xn = np.empty(n)
    xr = np.empty(n)
    target = np.empty(n)
    queue = np.empty((QUEUE, 4))
    inv = np.empty(lam.shape[0])
    for _ in range(iterations):
        # the smaller tree grows (ties: in turn): a tree stuck in a narrow passage (an end deep in a crate)
        # gets the samples it needs instead of half of them going to the other tree's aimless growth
        a = 0 if counts[0] < counts[1] else 1 if counts[1] < counts[0] else status[3]
        b = 1 - a
        if counts[a] < counts[b] and _uniform(rng) < LOCAL_SHARE:  # near a node of the smaller tree
            i = min(int(_uniform(rng) * counts[a]), counts[a] - 1)
            for j in range(n):
                x = nodes[a, i, j] + LOCAL_SPREAD * step_range * (2.0 * _uniform(rng) - 1.0)
                xr[j] = min(max(x, lower[j]), upper[j])
        else:
            for j in range(n):
                xr[j] = lower[j] + _uniform(rng) * (upper[j] - lower[j])
        s = _extend(a, nodes, parent, counts, xr, step_range, levers, lam, min_budget, max_states, hold, cols, fk,
                    cov, grp, cap, work, q, xm, xn, queue, inv)
        status[3] = b
        if s == TRAPPED:
            continue
        new_a = counts[a] - 1
        for j in range(n):
            target[j] = nodes[a, new_a, j]
        s = ADVANCED
        while s == ADVANCED:
            s = _extend(b, nodes, parent, counts, target, step_range, levers, lam, min_budget, max_states, hold,
                        cols, fk, cov, grp, cap, work, q, xm, xn, queue, inv)
        if s == REACHED:
            status[0] = 1
            status[1 + a] = new_a
            status[1 + b] = counts[b] - 1
            status[4] += int(q[hold.shape[0]])
            return 1
    status[4] += int(q[hold.shape[0]])
    return 0


@jit
def path_proven(P, levers, lam, min_budget, max_states, hold, cols, fk, cov, grp, cap, work):
    """Whether the cover proves every vertex and edge of the polyline ``P (M, n)``."""
    q = np.empty(hold.shape[0])
    xm = np.empty(P.shape[1])
    queue = np.empty((QUEUE, 4))
    inv = np.empty(lam.shape[0])
    if state_excess(P[0], hold, cols, fk, cov, grp, cap, work, q) < 0.0:
        return False
    for i in range(P.shape[0] - 1):
        if not edge_proven(P[i], P[i + 1], levers, lam, min_budget, max_states, hold, cols, fk, cov, grp, cap, work, q,
                           xm, queue, inv):
            return False
    return True


@jit
def _cumulative(P, m, out):
    out[0] = 0.0
    for i in range(1, m):
        d = 0.0
        for j in range(P.shape[1]):
            e = P[i, j] - P[i - 1, j]
            d += e * e
        out[i] = out[i - 1] + math.sqrt(d)


@jit
def _point_at(P, s, m, length, out):
    """The point at arc length ``length`` of the polyline's first ``m`` vertices; returns its segment."""
    k = 0
    while k < m - 2 and s[k + 1] < length:
        k += 1
    h = s[k + 1] - s[k]
    f = 0.0 if h <= 0.0 else min(max((length - s[k]) / h, 0.0), 1.0)
    for j in range(P.shape[1]):
        out[j] = P[k, j] + f * (P[k + 1, j] - P[k, j])
    return k


@jit
def shortcut(P, m, rng, tries, min_gain, levers, lam, min_budget, max_states, hold, cols, fk, cov, grp, cap, work):
    """Random shortcutting of the proven polyline ``P[:m]`` in place; returns its new vertex count.

    Each try joins two random points of the path (at random arc lengths) by a straight edge
    when the cover proves it and it is shorter than the stretch it replaces by at least
    ``min_gain`` times the path's length (a try that would gain less is not proven: its proof
    costs as much as a useful one); then every vertex is dropped whose neighbours join
    directly. ``P`` has room for ``m + 2 * tries`` rows."""
    n = P.shape[1]
    q = np.empty(hold.shape[0])
    xm = np.empty(n)
    pa = np.empty(n)
    pb = np.empty(n)
    queue = np.empty((QUEUE, 4))
    inv = np.empty(lam.shape[0])
    s = np.empty(P.shape[0])
    for _ in range(tries):
        if m < 3:
            break
        _cumulative(P, m, s)
        u, v = _uniform(rng) * s[m - 1], _uniform(rng) * s[m - 1]
        if u > v:
            u, v = v, u
        ka = _point_at(P, s, m, u, pa)
        kb = _point_at(P, s, m, v, pb)
        if kb - ka < 1:  # on one segment: nothing to cut
            continue
        chord = 0.0
        for j in range(n):
            chord += (pb[j] - pa[j]) ** 2
        if (v - u) - math.sqrt(chord) < min_gain * s[m - 1]:
            continue
        if not edge_proven(pa, pb, levers, lam, min_budget, max_states, hold, cols, fk, cov, grp, cap, work, q, xm,
                           queue, inv):
            continue
        # P[:ka+1], pa, pb, P[kb+1:m]
        tail = m - (kb + 1)
        shift = (ka + 3) - (kb + 1)
        if shift > 0:
            for i in range(m - 1, kb, -1):
                P[i + shift] = P[i]
        elif shift < 0:
            for i in range(kb + 1, m):
                P[i + shift] = P[i]
        P[ka + 1] = pa
        P[ka + 2] = pb
        m = ka + 3 + tail
    # drop vertices whose neighbours join directly
    i = 0
    while i + 2 < m:
        if edge_proven(P[i], P[i + 2], levers, lam, min_budget, max_states, hold, cols, fk, cov, grp, cap, work, q,
                       xm, queue, inv):
            for k in range(i + 1, m - 1):
                P[k] = P[k + 1]
            m -= 1
        else:
            i += 1
    return m
