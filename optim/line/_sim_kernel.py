"""The line simulator's event loop compiled (numba): the same decisions, in the same order, the same bits.

:func:`run_events` is the loop of :mod:`pinarms.optim.line.sim_loop` for the built-in rules
(:class:`~pinarms.optim.line.rules.base.KernelForm`) without a neighbour guard or trays: the arms' next
events (one per arm at most, so the earliest of an array is the heap's top, ties to the upstream
arm), each decision's window of items (binary searches on the arrival times), the intercepts of the
items left in it, scalar by scalar in the order numpy evaluates them in
:meth:`~pinarms.optim.line.sim_arm.ArmState.intercept`, the rule's choice, and the pick. The look-ahead's
branch and bound (:func:`~pinarms.optim.line.rules.lookahead.best_sequence`) runs here depth first with
an explicit stack, trying the items in the same order.

Arrays: ``t0``, ``w`` (n,) the items; per arm ``a`` (upstream first): ``group[a]`` its rows in
``RA``, ``RC`` (groups, n, K) (approach and leave times at its pre-grasp nodes, NaN: infeasible),
``EX`` (groups, n) track + release, ``U`` (arms, K) its nodes' absolute ``u`` [m], ``u_min``,
``u_max``, ``max_tA``, ``rest`` (arms, 2).
"""

from __future__ import annotations

import math

import numpy as np

from pinarms.compiled import jit, jit_inline

__all__ = ["run_events", "cell_rows", "spacing"]

EPS = 1e-9  # the same as optim.line.rules.base.EPS


@jit_inline
def spacing(x):
    """``np.spacing(x)`` of a finite ``x >= 0``: the gap to the next larger double."""
    if x == 0.0:
        return 5e-324
    _, e = math.frexp(x)
    return max(math.ldexp(1.0, e - 53), 5e-324)


@jit_inline
def _left(a, x):
    """``np.searchsorted(a, x)`` (side left)."""
    lo, hi = 0, a.size
    while lo < hi:
        mid = (lo + hi) >> 1
        if a[mid] < x:
            lo = mid + 1
        else:
            hi = mid
    return lo


@jit_inline
def _right(a, x):
    """``np.searchsorted(a, x, side="right")``."""
    lo, hi = 0, a.size
    while lo < hi:
        mid = (lo + hi) >> 1
        if a[mid] <= x:
            lo = mid + 1
        else:
            hi = mid
    return lo


@jit_inline
def _takes(share, arm, n_arms, i, wi, width):
    """Whether arm ``arm`` may take item ``i`` (:meth:`AssignmentRule.takes` of Bands, Split, the others)."""
    if share == 1:
        band = int((wi + width / 2.0) / width * n_arms)
        band = min(max(band, 0), n_arms - 1)
        return band == arm
    if share == 2:
        return i % n_arms == arm
    return True


@jit_inline
def intercept(t, i, a, g, t0, speed, U, RA, RC, EX, out):
    """The earliest reachable intercept of item ``i`` by arm ``a`` (rows ``g``) ready at ``t``: False
    when none, else True with ``out`` = (start, meet, finish, u)."""
    K = U.shape[1]
    k = -1
    for j in range(K):
        ta = RA[g, i, j]
        if ta == ta and (t + ta) - (t0[i] + U[a, j] / speed) <= 0.0:
            k = j
            break
    if k < 0:
        return False
    km = k - 1 if k > 0 else 0
    gk = (t + RA[g, i, k]) - (t0[i] + U[a, k] / speed)
    gp = 0.0
    prev = False
    if k > 0 and RA[g, i, km] == RA[g, i, km]:
        gp = (t + RA[g, i, km]) - (t0[i] + U[a, km] / speed)
        prev = gp > 0.0 and U[a, k] > U[a, km]
    if prev:
        f = gp / (gp - gk)
        u = U[a, km] + f * (U[a, k] - U[a, km])
        ta = RA[g, i, km] + f * (RA[g, i, k] - RA[g, i, km])
        tc = RC[g, i, km] + f * (RC[g, i, k] - RC[g, i, km])
    else:
        u, ta, tc = U[a, k], RA[g, i, k], RC[g, i, k]
    meet = t0[i] + u / speed
    out[0] = max(meet - ta, t)
    out[1] = meet
    out[2] = meet + EX[g, i] + tc
    out[3] = u
    return True


@jit_inline
def best_first(ready, pool, a, g, t0, speed, U, RA, RC, EX):
    """Position in ``pool`` of the first item of the best order (most picks, then earliest end), -1
    when no item can be picked: :func:`~pinarms.optim.line.rules.lookahead.best_sequence`, depth first."""
    P = pool.size
    used = np.zeros(P, dtype=np.bool_)
    seq = np.empty(P + 1, dtype=np.int64)
    pos = np.zeros(P + 1, dtype=np.int64)
    ready_at = np.empty(P + 1)
    out = np.empty(4)
    best_n, best_t, best_first_pos = -1, np.inf, -1
    d = 0
    ready_at[0] = ready
    enter = True
    while True:
        if enter:
            enter = False
            t = ready_at[d]
            if d > best_n or (d == best_n and -t > -best_t):
                best_n, best_t = d, t
                best_first_pos = seq[0] if d > 0 else -1
            if P < best_n or (P == best_n and t >= best_t):
                if d == 0:
                    break
                d -= 1
                used[seq[d]] = False
                continue
            pos[d] = 0
        t = ready_at[d]
        child = False
        while pos[d] < P:
            p = pos[d]
            pos[d] += 1
            if used[p]:
                continue
            if not intercept(t, pool[p], a, g, t0, speed, U, RA, RC, EX, out):
                continue
            seq[d] = p
            used[p] = True
            ready_at[d + 1] = out[2]
            d += 1
            enter = True
            child = True
            break
        if child:
            continue
        if d == 0:
            break
        d -= 1
        used[seq[d]] = False
    return best_first_pos


@jit_inline
def _key(order, t, i, k, t0, w, speed, rest, finish):
    if order == 1:
        return np.hypot(speed * (t - t0[i]) - rest[k, 0], w[i] - rest[k, 1])
    if order == 2:
        return finish
    return t0[i]


@jit_inline
def _choose(t, k, m, cand, cs, cf, order, horizon, t0, w, speed, rest, group, U, RA, RC, EX):
    """Position in the candidates of the rule's choice, or -1 - (position whose start to wait for)."""
    if horizon > 0:
        ranked = np.arange(m)
        for x in range(1, m):  # stable insertion sort by start
            y = x
            while y > 0 and cs[ranked[y - 1]] > cs[ranked[y]]:
                ranked[y - 1], ranked[y] = ranked[y], ranked[y - 1]
                y -= 1
        h = min(horizon, m)
        pool = np.empty(h, dtype=np.int64)
        for x in range(h):
            pool[x] = cand[ranked[x]]
        p = best_first(t, pool, k, group[k], t0, speed, U, RA, RC, EX)
        c = ranked[0] if p < 0 else ranked[p]
        return c if cs[c] <= t + EPS else -1 - c
    best = -1
    bk, bt = 0.0, 0.0
    for x in range(m):
        if cs[x] <= t + EPS:
            i = cand[x]
            key = _key(order, t, i, k, t0, w, speed, rest, cf[x])
            if best < 0 or key < bk or (key == bk and t0[i] < bt):
                best, bk, bt = x, key, t0[i]
    if best >= 0:
        return best
    low = 0
    for x in range(1, m):
        if cs[x] < cs[low]:
            low = x
    return -1 - low


@jit
def run_events(t0, w, speed, width, group, RA, RC, EX, U, u_min, u_max, max_tA, rest, order, share, horizon,
               picked_by, meet, u_meet, start, finish):
    """Run the line (module doc); fills the item columns (``picked_by``: the arm's position upstream
    first, -1 missed), returns the number of decisions."""
    n, A = t0.size, u_min.size
    taken = np.zeros(n, dtype=np.bool_)
    next_t = np.zeros(A)
    active = np.ones(A, dtype=np.bool_)
    cand = np.empty(16, dtype=np.int64)
    cs, cm, cf, cu = np.empty(16), np.empty(16), np.empty(16), np.empty(16)
    out = np.empty(4)
    decisions = 0
    while True:
        k = -1
        for a in range(A):
            if active[a] and (k < 0 or next_t[a] < next_t[k]):
                k = a
        if k < 0:
            break
        t = next_t[k]
        active[k] = False
        decisions += 1
        slack = EPS + 4.0 * spacing(abs(t))
        lo = _left(t0, t - u_max[k] / speed - slack)
        hi = _right(t0, t - u_min[k] / speed + max_tA[k] + slack)
        if horizon > 0:
            hi = max(hi, min(n, lo + horizon))
        j = hi
        for i in range(hi, min(hi + 64, n)):
            if not taken[i] and _takes(share, k, A, i, w[i], width):
                j = i
                break
        wake = max(t + 1e-6, t0[j] + u_min[k] / speed - max_tA[k]) if j < n else np.inf
        m = 0
        for i in range(lo, hi):
            if taken[i] or not _takes(share, k, A, i, w[i], width):
                continue
            if not intercept(t, i, k, group[k], t0, speed, U, RA, RC, EX, out):
                continue
            if m == cand.size:
                cand, cs, cm, cf, cu = (np.concatenate((cand, cand)), np.concatenate((cs, cs)),
                                        np.concatenate((cm, cm)), np.concatenate((cf, cf)), np.concatenate((cu, cu)))
            cand[m], cs[m], cm[m], cf[m], cu[m] = i, out[0], out[1], out[2], out[3]
            m += 1
        if m == 0:
            if j < n:
                next_t[k], active[k] = wake, True
            continue
        c = _choose(t, k, m, cand, cs, cf, order, horizon, t0, w, speed, rest, group, U, RA, RC, EX)
        if c < 0:
            next_t[k], active[k] = cs[-1 - c], True
            continue
        i = cand[c]
        taken[i] = True
        picked_by[i], meet[i], u_meet[i], start[i], finish[i] = k, cm[c], cu[c], t, cf[c]
        next_t[k], active[k] = cf[c], True
    return decisions


@jit
def cell_rows(w, sel, g, ends, layer, weight, tA, tC):
    """Rows ``sel`` of ``tA``, ``tC`` (n, K) for items at ``w[sel]``: :meth:`~pinarms.optim.line.map_rows.CellRows.rows`
    item by item (the cell ``j`` and place ``f`` of numpy's ``searchsorted`` and division, then
    ``T_j · (1 − f) + T_j+1 · f`` per node on yaw layer ``layer[i]``, blended with the next layer
    as ``(1 − f_y) · lower + f_y · upper`` where ``weight[i]`` (f_y) > 0; NaN off the grid)."""
    nc, K, ny = ends.shape[2], ends.shape[3], ends.shape[0]
    for x in range(sel.size):
        i = sel[x]
        wi = w[i]
        j = min(max(_right(g, wi) - 1, 0), nc - 1)
        f = (wi - g[j]) / (g[j + 1] - g[j])
        if wi < g[0] or wi > g[g.size - 1]:
            f = np.nan
        y = layer[i]
        fy = weight[i]
        y1 = min(y + 1, ny - 1)
        for k in range(K):
            a = ends[y, 0, j, k] * (1 - f) + ends[y, 1, j, k] * f
            c = ends[y, 2, j, k] * (1 - f) + ends[y, 3, j, k] * f
            if fy > 0.0:
                a = (1.0 - fy) * a + fy * (ends[y1, 0, j, k] * (1 - f) + ends[y1, 1, j, k] * f)
                c = (1.0 - fy) * c + fy * (ends[y1, 2, j, k] * (1 - f) + ends[y1, 3, j, k] * f)
            tA[i, k] = a
            tC[i, k] = c
