"""Compiled Levenberg–Marquardt IK of one serial chain (numba): the whole solve in one native call.

A Python step of the solver in :mod:`.numerical` costs ≈ 10 µs (about 15 Pinocchio and numpy
calls), where the work itself is a few hundred floating-point operations. Here the chain's
kinematics (:mod:`._chain`), the damped 6×6 (or nq×nq) Cholesky solve, step control, limit
handling and restarts run compiled (``nogil``: threads sharing a robot run in parallel; every
buffer belongs to one call, nothing is shared).

The step control is the one of :meth:`.numerical.NumericalIK._descend`: Sugihara's damping
``λ = μ‖e‖² + λ_min``, Nielsen's update of ``μ`` from the gain ratio, a rejected step
multiplying ``μ`` by 2, 4, 8, …, a per-joint step cap, stall detection, and the two phases
for joint limits (a free descent wrapped to the ranges' 2π windows, then a projected descent
with an active set; see :mod:`._limits_kernel`).

Starts: the first from ``q0`` (a seed, or the stored pose nearest the target, :func:`._chain.grid_index`,
stored poses near a joint limit ranked lower), then up to :data:`_NEAR` stored poses next nearest the
target (for an arm with isolated solutions only those :data:`_DIVERSE` away from every start tried),
then uniform draws within the limits (numba's generator, seeded per target), 32 at a time, nearest
pose first.

Costs kept out of the loop: the Gram matrix ``J Jᵀ`` is formed once per iteration (a rejected
step only adds another ``λ`` to its diagonal); a trial step evaluates the pose and error only,
the Jacobian is formed once the step is accepted; the scratch buffers are made once per batch;
the per-iteration helpers with many array arguments are inlined by numba (a call with a dozen array
arguments costs as much as the 6×6 solve).
"""

from __future__ import annotations

import math

import numpy as np

from pinarms.robots.ik._chain import errors, grid_index, grid_neighbours, jacobian, jit, jit_inline, pose_cost, pose_error, table_index
from pinarms.robots.ik._limits_kernel import CLIP, FREE, WINDOW, clip, in_limits, wrap, wrap_unbounded

__all__ = ["FREE", "WINDOW", "CLIP", "descend", "errors", "attempt_within_limits", "table_index", "solve",
           "solve_many", "workspace", "grid_index"]

_MU_MAX = 1e8
_POOL = 32
_NEAR = 8  # restarts from the stored poses nearest the target (after the first start) before random draws
#: [rad] an arm with isolated solutions (no more joints than task rows) restarts only from stored poses
#: this far from every start tried, in some revolute joint (modulo 2π): a nearby start descends to
#: the same solution (outside the limits) or the same local minimum; among the :data:`_CANDIDATES`
#: stored poses nearest the target
_DIVERSE = 1.5
_CANDIDATES = 32
_TWO_PI = 2.0 * math.pi

# P (float64 array) holds the settings: μ0, λ_min, max_step, stall_ratio, stall_steps, max_iter
_P_MU0, _P_LAMMIN, _P_STEP, _P_STALLR, _P_STALLN, _P_ITER = 0, 1, 2, 3, 4, 5
#: a free descent that met the pose this far [rad or m] beyond a limit, on an arm with no more joints
#: than task rows (no self-motion to slide back along), goes to the next start instead of phase 2
_FAR_OUTSIDE = 0.01


@jit
def workspace(nq, m):
    """Scratch buffers of :func:`descend` for ``nq`` coordinates and a chain of ``m`` joints."""
    n = max(6, nq)
    return (np.empty((3, 3)), np.empty(3), np.empty((m, 3)), np.empty((m, 3)), np.empty((m, 3)), np.empty((m, 3)),
            np.empty(6), np.empty(6), np.empty((6, nq)), np.empty(nq), np.empty(nq), np.ones(nq, dtype=np.bool_),
            np.empty((n, n)), np.empty((n, n)), np.empty(n), np.empty(n), np.empty((n, n)), np.empty(n),
            np.ones(nq, dtype=np.bool_))


# indices into the workspace tuple
_R, _P, _Z, _O, _ZT, _OT, _E, _ET, _J, _QT, _DQ, _FREE, _G0, _G, _X, _B, _GM, _BM, _ALL = range(19)


@jit
def _cholesky_solve(G, b, x):
    """Solve ``G x = b`` (G symmetric positive definite, overwritten by its factor); False if not SPD.

    The factor's diagonal is kept inverted (multiplications instead of divisions).
    """
    n = G.shape[0]
    for j in range(n):
        d = G[j, j]
        for k in range(j):
            d -= G[j, k] * G[j, k]
        if not d > 0.0:
            return False
        inv = 1.0 / math.sqrt(d)
        G[j, j] = inv
        for i in range(j + 1, n):
            s = G[i, j]
            for k in range(j):
                s -= G[i, k] * G[j, k]
            G[i, j] = s * inv
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= G[i, k] * x[k]
        x[i] = s * G[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= G[k, i] * x[k]
        x[i] = s * G[i, i]
    return True


@jit_inline
def _gram(J, rows, e, free, G0, b):
    """``G0 = A Aᵀ`` (rows × rows; ``AᵀA`` and ``b = Aᵀe`` when nq < rows), A = J[:rows] with columns not ``free`` zeroed."""
    nq = J.shape[1]
    if nq >= rows:
        for a in range(rows):
            for c in range(a + 1):
                s = 0.0
                for j in range(nq):
                    if free[j]:
                        s += J[a, j] * J[c, j]
                G0[a, c] = s
                G0[c, a] = s
        return
    for i in range(nq):
        s = 0.0
        for a in range(rows):
            s += J[a, i] * e[a]
        b[i] = s if free[i] else 0.0
        for j in range(i + 1):
            s = 0.0
            if free[i] and free[j]:
                for a in range(rows):
                    s += J[a, i] * J[a, j]
            G0[i, j] = s
            G0[j, i] = s


@jit_inline
def _damped_solve(J, rows, e, lam, free, G0, b, G, x, dq):
    """``dq = Aᵀ(G0 + λI)⁻¹e`` (``(G0 + λI)⁻¹b`` when nq < rows) from :func:`_gram`'s ``G0, b``; False if not SPD."""
    nq = J.shape[1]
    n = rows if nq >= rows else nq
    Gn = G[:n, :n]
    for a in range(n):
        for c in range(n):
            Gn[a, c] = G0[a, c]
        Gn[a, a] += lam
    if nq < rows:
        return _cholesky_solve(Gn, b, dq)
    if not _cholesky_solve(Gn, e, x):
        return False
    for j in range(nq):
        s = 0.0
        if free[j]:
            for a in range(rows):
                s += J[a, j] * x[a]
        dq[j] = s
    return True


@jit_inline
def _step(J, rows, e, lam, q, lo, hi, at_limit, max_step, dq, free, all_free, G0, b, G, x, Gm, bm):
    """The damped step ``dq`` of this ``λ``, with the active set at the limits and the step cap; False if not SPD.

    ``G0, b``: :func:`_gram` of all joints; ``free``, ``Gm``, ``bm``, ``G``, ``x``: scratch.
    """
    if not _damped_solve(J, rows, e, lam, all_free, G0, b, G, x, dq):
        return False
    if at_limit:  # joints at a limit pushed outwards: out of the step, solved again
        nb = 0
        for j in range(q.shape[0]):
            blocked = (q[j] <= lo[j] and dq[j] < 0.0) or (q[j] >= hi[j] and dq[j] > 0.0)
            free[j] = not blocked
            nb += blocked
        if nb:
            _gram(J, rows, e, free, Gm, bm)
            if not _damped_solve(J, rows, e, lam, free, Gm, bm, G, x, dq):
                return False
            for j in range(q.shape[0]):
                if not free[j]:
                    dq[j] = 0.0
    step = 0.0
    for j in range(q.shape[0]):
        step = max(step, abs(dq[j]))
    if step > max_step:
        scale = max_step / step
        for j in range(q.shape[0]):
            dq[j] *= scale
    return True


@jit_inline
def _nielsen(mu, E, E_t, e, J, dq, rows):
    """Nielsen's update of ``μ`` from the gain ratio ρ (actual over predicted decrease of ‖e‖²)."""
    predicted = E
    for a in range(rows):
        r = e[a]
        for j in range(dq.shape[0]):
            r -= J[a, j] * dq[j]
        predicted -= r * r
    rho = (E - E_t) / predicted if predicted > 0.0 else 1.0
    return max(mu * max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3), 1e-12)


@jit
def _start_at_limit(q, L):
    """Project ``q`` for a projected descent; True if a joint is at a limit."""
    if clip(q, L):
        return True
    lo, hi = L[0], L[1]
    for j in range(q.shape[0]):
        if q[j] <= lo[j] or q[j] >= hi[j]:
            return True
    return False


@jit
def descend(q, C, L, P, Rt, pt, posonly, tol, mode, patience, W):
    """Levenberg–Marquardt from ``q`` (modified in place): ``(position error [m], rotation error [rad], iterations)``."""
    rows = 3 if posonly else 6
    stall_ratio, max_step = P[_P_STALLR], P[_P_STEP]
    stall_steps, max_iter = int(P[_P_STALLN]) * patience, int(P[_P_ITER]) * patience
    qi, sc, rev = C[0], C[1], C[3]
    R, p, Z, O, Z_t, O_t = W[_R], W[_P], W[_Z], W[_O], W[_ZT], W[_OT]
    e, e_t, J, q_t, dq, free, G0, G, x, b, Gm, bm, all_free = (W[_E], W[_ET], W[_J], W[_QT], W[_DQ], W[_FREE], W[_G0],
                                                               W[_G], W[_X], W[_B], W[_GM], W[_BM], W[_ALL])
    lo, hi, lam_min = L[0], L[1], P[_P_LAMMIN]
    at_limit = _start_at_limit(q, L) if mode == CLIP else False
    E, pe2, th = pose_error(q, C, Rt, pt, posonly, R, p, Z, O, e)
    jacobian(qi, sc, rev, Z, O, p, J)
    mu, nu, it, stall = P[_P_MU0], 2.0, 0, 0
    done = pe2 <= tol * tol and th <= tol
    while not done and it < max_iter:
        it += 1
        _gram(J, rows, e, all_free, G0, b)  # all joints free: the step's Gram matrix, reused for every λ tried
        accepted = False
        while mu < _MU_MAX:
            if not _step(J, rows, e, mu * E + lam_min, q, lo, hi, at_limit, max_step, dq, free, all_free, G0, b, G, x,
                         Gm, bm):
                mu, nu = mu * nu, 2.0 * nu
                continue
            for j in range(q.shape[0]):
                q_t[j] = q[j] + dq[j]
            clipped = clip(q_t, L) if mode == CLIP else False
            E_t, pe2_t, th_t = pose_error(q_t, C, Rt, pt, posonly, R, p, Z_t, O_t, e_t)
            if E_t < E:  # accept
                mu, nu = _nielsen(mu, E, E_t, e, J, dq, rows), 2.0
                stall = stall + 1 if E_t > stall_ratio * E else 0
                q[:] = q_t
                e, e_t, Z, Z_t, O, O_t = e_t, e, Z_t, Z, O_t, O
                jacobian(qi, sc, rev, Z, O, p, J)
                E, pe2, th, at_limit, accepted = E_t, pe2_t, th_t, clipped, True
                break
            mu, nu = mu * nu, 2.0 * nu
        if not accepted or stall >= stall_steps:
            break
        done = pe2 <= tol * tol and th <= tol
    if mode == WINDOW:
        wrap(q, L)
    else:
        wrap_unbounded(q, L)
    return math.sqrt(pe2), th, it


@jit
def _excess(q, L):
    """Largest distance of ``q`` beyond a limit [rad or m]."""
    lo, hi = L[0], L[1]
    out = 0.0
    for j in range(q.shape[0]):
        out = max(out, lo[j] - q[j], q[j] - hi[j])
    return out


@jit
def attempt_within_limits(q, C, L, P, Rt, pt, posonly, tol, W):
    """Free descent (wrapped), then, met outside the limits, a projected one: ``(pe, re, iterations, ok)``; q in place, within the limits.

    An arm with no more joints than task rows has isolated solutions: a projected descent from
    a solution more than :data:`_FAR_OUTSIDE` beyond a limit almost never meets the pose (AUBO-i3: 1 of
    265 attempts), so the next start is tried at once; a solution just past a limit is still
    slid back.
    """
    # the modes as int64, not as numba's literals of the module's constants: one compile of the descent, not one
    # per mode (the same code either way)
    pe, re, it = descend(q, C, L, P, Rt, pt, posonly, tol, np.int64(WINDOW), 1, W)
    met = pe <= tol and re <= tol
    if met and in_limits(q, L):
        return pe, re, it, True
    far = not met or (q.shape[0] <= (3 if posonly else 6) and _excess(q, L) > _FAR_OUTSIDE)
    clip(q, L)
    if far:  # no pose reached, or an isolated solution well outside: report the projection, restart elsewhere
        pe, re = errors(q, C, Rt, pt, posonly)
        return pe, re, it, False
    pe, re, it2 = descend(q, C, L, P, Rt, pt, posonly, tol, np.int64(CLIP), 1, W)
    return pe, re, it + it2, pe <= tol and re <= tol


@jit
def _ranked_pool(C, L, Rt, pt, posonly, pool, cost, W):
    """Fill ``pool`` with uniform draws within the limits (numba's seeded generator); their order, nearest pose first."""
    lo, hi = L[0], L[1]
    for i in range(pool.shape[0]):
        for j in range(pool.shape[1]):
            pool[i, j] = lo[j] + (hi[j] - lo[j]) * np.random.random()
        cost[i] = pose_cost(C, pool[i], Rt, pt, posonly, W[_R], W[_P], W[_ZT], W[_OT])
    return np.argsort(cost, kind="mergesort")


@jit
def _same(a, b):
    """``a == b`` entry by entry."""
    for j in range(a.shape[0]):
        if a[j] != b[j]:
            return False
    return True


@jit
def _apart(a, tried, n, L, d_min):
    """True if ``a`` differs from each of ``tried[:n]`` by at least ``d_min`` [rad] in some revolute joint (modulo 2π)."""
    unbounded, turns = L[3], L[5]
    for i in range(n):
        far = False
        for j in range(a.shape[0]):
            if unbounded[j] or turns[j] > 0.0:
                d = abs(a[j] - tried[i, j]) % _TWO_PI
                if min(d, _TWO_PI - d) >= d_min:
                    far = True
                    break
        if not far:
            return False
    return True


@jit
def _diverse_restarts(L, nq, posonly):
    """The distance [rad] between restarts from stored poses: :data:`_DIVERSE` for an arm with isolated
    solutions and a revolute joint, else 0 (the next-nearest poses, whatever their distance)."""
    if nq > (3 if posonly else 6):
        return 0.0
    for j in range(nq):
        if L[3][j] or L[5][j] > 0.0:
            return _DIVERSE
    return 0.0


@jit
def solve_in(q0, table, C, L, P, Rt, pt, posonly, tol, restarts, seed, q_out, W):
    """:func:`solve` with the scratch buffers ``W`` of :func:`workspace`."""
    nq = q0.shape[0]
    q = q0.copy()
    pe, re, its, ok = attempt_within_limits(q, C, L, P, Rt, pt, posonly, tol, W)
    best = pe + re
    q_out[:] = q
    attempts = 1
    if ok:
        return True, pe, re, attempts, its
    pool = np.empty((0, nq))  # the random draws, made (and the generator seeded) only when needed
    cost = np.empty(0)
    order = np.empty(0, dtype=np.int64)
    k = _POOL
    best_pe, best_re = pe, re
    d_min = _diverse_restarts(L, nq, posonly)
    near = grid_neighbours(table, Rt, pt, posonly, _CANDIDATES if d_min > 0.0 else _NEAR + 1)
    tried = np.empty((_NEAR + 1, nq))  # the starts tried so far (the first, then stored poses)
    tried[0] = q0
    i_near, used = 0, 0
    while attempts <= restarts:
        while i_near < near.shape[0] and (_same(table[0][near[i_near]], q0) or (
                d_min > 0.0 and not _apart(table[0][near[i_near]], tried, used + 1, L, d_min))):
            i_near += 1  # the first start itself, or (isolated solutions) a pose near a start tried
        if used < _NEAR and i_near < near.shape[0]:  # the stored poses nearest the target, then random draws
            q[:] = table[0][near[i_near]]
            i_near += 1
            used += 1
            tried[used] = q
        else:
            if k == _POOL:
                if pool.shape[0] == 0:
                    np.random.seed(seed)
                    pool, cost = np.empty((_POOL, nq)), np.empty(_POOL)
                order = _ranked_pool(C, L, Rt, pt, posonly, pool, cost, W)
                k = 0
            q[:] = pool[order[k]]
            k += 1
        attempts += 1
        pe, re, it, ok = attempt_within_limits(q, C, L, P, Rt, pt, posonly, tol, W)
        its += it
        if ok:
            q_out[:] = q
            return True, pe, re, attempts, its
        if pe + re < best:
            best = pe + re
            best_pe, best_re = pe, re
            q_out[:] = q
    return False, best_pe, best_re, attempts, its


@jit
def solve(q0, table, C, L, P, Rt, pt, posonly, tol, restarts, seed, q_out):
    """Attempt from ``q0``, then up to ``restarts`` more: the stored poses next nearest the target, then
    starts drawn within the limits (``seed`` < 2³²), nearest pose first.

    Writes the solution (or the best configuration within the limits) to ``q_out``;
    returns ``(ok, pe, re, attempts, iterations)``.
    """
    W = workspace(q0.shape[0], C[0].shape[0])
    return solve_in(q0, table, C, L, P, Rt, pt, posonly, tol, restarts, seed, q_out, W)


@jit
def solve_many(Rts, pts, starts, table, C, L, P, posonly, tol, restarts, seed, q_out, ok, pe, re):
    """:func:`solve` for every target ``k`` (restarts seeded by ``seed + k``); returns the total iterations.

    A row of ``starts`` holding a NaN starts from the ``table`` configuration nearest its target
    (:func:`._chain.grid_index`), as a single solve without a seed does.
    """
    W = workspace(starts.shape[1], C[0].shape[0])
    total = 0
    for k in range(Rts.shape[0]):
        q0 = starts[k]
        if not np.all(np.isfinite(q0)):
            q0 = table[0][grid_index(table, Rts[k], pts[k], posonly)]
        o, a, b, _, it = solve_in(q0, table, C, L, P, Rts[k], pts[k], posonly, tol, restarts, (seed + k) % 4294967296,
                                  q_out[k], W)
        ok[k], pe[k], re[k] = o, a, b
        total += it
    return total
