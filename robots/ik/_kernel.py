"""Compiled Levenberg–Marquardt IK of one serial chain (numba): the whole solve in one native call.

A Python step of the solver in :mod:`.numerical` costs ≈ 10 µs (about 15 Pinocchio and numpy
calls), where the work itself is a few hundred floating-point operations. Here the chain's
forward kinematics, frame Jacobian, error, damped 6×6 (or nq×nq) Cholesky solve, step
control, limit handling and restarts run compiled (``nogil``: threads sharing a robot run
in parallel; every buffer is local to the call, nothing is shared).

The chain is the path from the base to the frame's joint, in :class:`~..kinematic_tree.KinematicTree`'s
rewritten form: joint ``k`` has the constant placement ``(LR[k], Lp[k])`` after its parent
and moves about (revolute) or along (prismatic) its own z axis by ``v = sc[k]·q[qi[k]] + of[k]``
(mimic joints: their master's coordinate, scaled and offset); the frame sits at ``(fR, fp)``
after the last joint.

Error of ``q`` for the target ``(R_t, p_t)`` in base axes::

    e = [p_t − p(q);  log3(R_t R(q)ᵀ)]      (6,) [m, rad]  (position only: the first 3)

with the frame Jacobian in base axes at the frame origin (linear rows first), so that
``e(q + Δq) ≈ e − J Δq`` (to first order in the error; near the solution the rotation term's
Jacobian tends to the identity, and the steps become Newton's). The step control is the
one of :meth:`.numerical.NumericalIK._descend`: Sugihara's damping ``λ = μ‖e‖² + λ_min``,
Nielsen's update of ``μ`` from the gain ratio, a rejected step multiplying ``μ`` by 2, 4,
8, …, a per-joint step cap, stall detection, and the two phases for joint limits (a free
descent wrapped to the ranges' 2π windows, then a projected descent with an active set).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

FREE, WINDOW, CLIP = 0, 1, 2
_MU_MAX = 1e8
_POOL = 32
_ROT_WEIGHT = 0.1
_TWO_PI = 2.0 * math.pi



def _jit(function):
    """``numba.njit`` with ``nogil``, cached on disk (beside the source, or numba's user cache
    directory when that is read-only); without any writable cache location, compiled per process."""
    try:
        return njit(cache=True, nogil=True)(function)
    except RuntimeError:  # numba: "cannot cache function ...: no locator available"
        return njit(nogil=True)(function)


# P (float64 array) holds the settings: μ0, λ_min, max_step, stall_ratio, stall_steps, max_iter
_P_MU0, _P_LAMMIN, _P_STEP, _P_STALLR, _P_STALLN, _P_ITER = 0, 1, 2, 3, 4, 5


@_jit
def _fk(q, qi, sc, of, rev, LR, Lp, fR, fp, R, p, Z, O, S):
    """Frame rotation ``R`` and origin ``p`` (written in place); joint axes ``Z`` and origins ``O`` (m, 3); ``S`` (3, 7) scratch."""
    Rc, Rn, pc = S[:, 0:3], S[:, 3:6], S[:, 6]
    Rc[:, :] = 0.0
    Rc[0, 0] = Rc[1, 1] = Rc[2, 2] = 1.0
    pc[:] = 0.0
    for k in range(qi.shape[0]):
        for a in range(3):
            pa = pc[a]
            for b in range(3):
                pa += Rc[a, b] * Lp[k, b]
                s = 0.0
                for c in range(3):
                    s += Rc[a, c] * LR[k, c, b]
                Rn[a, b] = s
            pc[a] = pa
        v = sc[k] * q[qi[k]] + of[k]
        if rev[k]:
            c = math.cos(v)
            s = math.sin(v)
            for a in range(3):
                x = Rn[a, 0]
                y = Rn[a, 1]
                Rc[a, 0] = c * x + s * y
                Rc[a, 1] = c * y - s * x
                Rc[a, 2] = Rn[a, 2]
        else:
            for a in range(3):
                Rc[a, 0] = Rn[a, 0]
                Rc[a, 1] = Rn[a, 1]
                Rc[a, 2] = Rn[a, 2]
                pc[a] += v * Rn[a, 2]
        for a in range(3):
            Z[k, a] = Rc[a, 2]
            O[k, a] = pc[a]
    for a in range(3):
        pa = pc[a]
        for b in range(3):
            pa += Rc[a, b] * fp[b]
            s = 0.0
            for c in range(3):
                s += Rc[a, c] * fR[c, b]
            R[a, b] = s
        p[a] = pa


@_jit
def _jacobian(qi, sc, rev, Z, O, p, J):
    """Frame Jacobian ``J (6, nq)`` in base axes at the frame origin ``p``, linear rows first."""
    J[:, :] = 0.0
    for k in range(qi.shape[0]):
        j = qi[k]
        z0, z1, z2 = Z[k, 0], Z[k, 1], Z[k, 2]
        s = sc[k]
        if rev[k]:
            d0, d1, d2 = p[0] - O[k, 0], p[1] - O[k, 1], p[2] - O[k, 2]
            J[0, j] += s * (z1 * d2 - z2 * d1)
            J[1, j] += s * (z2 * d0 - z0 * d2)
            J[2, j] += s * (z0 * d1 - z1 * d0)
            J[3, j] += s * z0
            J[4, j] += s * z1
            J[5, j] += s * z2
        else:
            J[0, j] += s * z0
            J[1, j] += s * z1
            J[2, j] += s * z2


@_jit
def _log3_of(Rt, R, w, M):
    """``w = log3(Rt Rᵀ)`` (3,) in place; returns the angle [rad] (atan2 form; axis from the symmetric part near π)."""
    for a in range(3):
        for b in range(3):
            M[a, b] = Rt[a, 0] * R[b, 0] + Rt[a, 1] * R[b, 1] + Rt[a, 2] * R[b, 2]
    w0 = 0.5 * (M[2, 1] - M[1, 2])
    w1 = 0.5 * (M[0, 2] - M[2, 0])
    w2 = 0.5 * (M[1, 0] - M[0, 1])
    c = 0.5 * (M[0, 0] + M[1, 1] + M[2, 2] - 1.0)
    s = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    theta = math.atan2(s, c)
    if c >= -0.9:
        k = theta / s if s > 1e-300 else 1.0
        w[0], w[1], w[2] = k * w0, k * w1, k * w2
        return theta
    # θ > 2.69 rad: (M + Mᵀ)/2 − c I = (1 − c) a aᵀ
    best, i = -1.0, 0
    for a in range(3):
        d = M[a, a] - c
        if d > best:
            best, i = d, a
    col0 = 0.5 * (M[0, i] + M[i, 0]) - (c if i == 0 else 0.0)
    col1 = 0.5 * (M[1, i] + M[i, 1]) - (c if i == 1 else 0.0)
    col2 = 0.5 * (M[2, i] + M[i, 2]) - (c if i == 2 else 0.0)
    n = math.sqrt(max(col0 * col0 + col1 * col1 + col2 * col2, 1e-300))
    sign = -1.0 if (col0 * w0 + col1 * w1 + col2 * w2) < 0.0 else 1.0
    k = sign * theta / n
    w[0], w[1], w[2] = k * col0, k * col1, k * col2
    return theta


@_jit
def _evaluate(q, C, Rt, pt, posonly, R, p, Z, O, e, J, S):
    """Error ``e``, Jacobian ``J`` of ``q``; returns ``(‖e‖², position error², rotation angle)``; ``S`` (3, 10) scratch."""
    qi, sc, of, rev, LR, Lp, fR, fp = C
    _fk(q, qi, sc, of, rev, LR, Lp, fR, fp, R, p, Z, O, S[:, :7])
    _jacobian(qi, sc, rev, Z, O, p, J)
    pe2 = 0.0
    for a in range(3):
        e[a] = pt[a] - p[a]
        pe2 += e[a] * e[a]
    if posonly:
        return pe2, pe2, 0.0
    theta = _log3_of(Rt, R, e[3:], S[:, 7:10])
    return pe2 + e[3] * e[3] + e[4] * e[4] + e[5] * e[5], pe2, theta


@_jit
def _cholesky_solve(G, b, x):
    """Solve ``G x = b`` (G symmetric positive definite, overwritten by its factor); False if not SPD."""
    n = G.shape[0]
    for j in range(n):
        d = G[j, j]
        for k in range(j):
            d -= G[j, k] * G[j, k]
        if not d > 0.0:
            return False
        d = math.sqrt(d)
        G[j, j] = d
        for i in range(j + 1, n):
            s = G[i, j]
            for k in range(j):
                s -= G[i, k] * G[j, k]
            G[i, j] = s / d
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= G[i, k] * x[k]
        x[i] = s / G[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= G[k, i] * x[k]
        x[i] = s / G[i, i]
    return True


@_jit
def _damped_step(J, rows, e, lam, free, dq, Gs, x):
    """``dq = Aᵀ(AAᵀ + λI)⁻¹e`` (``(AᵀA + λI)⁻¹Aᵀe`` when nq < rows), A = J[:rows] with columns not ``free`` zeroed.

    ``Gs`` (≥ n, ≥ n) and ``x`` (≥ n) are scratch.
    """
    nq = J.shape[1]
    if nq >= rows:
        G = Gs[:rows, :rows]
        for a in range(rows):
            for b in range(a + 1):
                s = 0.0
                for j in range(nq):
                    if free[j]:
                        s += J[a, j] * J[b, j]
                G[a, b] = s
                G[b, a] = s
            G[a, a] += lam
        if not _cholesky_solve(G, e[:rows], x):
            return False
        for j in range(nq):
            s = 0.0
            if free[j]:
                for a in range(rows):
                    s += J[a, j] * x[a]
            dq[j] = s
        return True
    G = Gs[:nq, :nq]
    bvec = x
    for i in range(nq):
        s = 0.0
        for a in range(rows):
            s += J[a, i] * e[a]
        bvec[i] = s if free[i] else 0.0
        for j in range(i + 1):
            s = 0.0
            if free[i] and free[j]:
                for a in range(rows):
                    s += J[a, i] * J[a, j]
            G[i, j] = s
            G[j, i] = s
        G[i, i] += lam
    return _cholesky_solve(G, bvec, dq)


@_jit
def _wrap(q, L):
    lo, hi, full_turn, unbounded, wlow, wturns = L
    for j in range(q.shape[0]):
        if unbounded[j]:
            q[j] = math.pi - (math.pi - q[j]) % _TWO_PI
        elif wturns[j] > 0.0:
            q[j] -= _TWO_PI * math.floor((q[j] - wlow[j]) * wturns[j])


@_jit
def _clip(q, L):
    """Project ``q`` into the limits in place (see ``NumericalIK._clip``); True if a joint was clipped."""
    lo, hi, full_turn, unbounded, wlow, wturns = L
    out = False
    for j in range(q.shape[0]):
        if unbounded[j]:
            q[j] = math.pi - (math.pi - q[j]) % _TWO_PI
    for j in range(q.shape[0]):
        if q[j] < lo[j] or q[j] > hi[j]:
            out = True
    if not out:
        return False
    at = False
    for j in range(q.shape[0]):
        if full_turn[j]:
            if q[j] > hi[j]:
                q[j] -= _TWO_PI
            elif q[j] < lo[j]:
                q[j] += _TWO_PI
        if q[j] <= lo[j]:
            q[j] = lo[j]
            at = True
        elif q[j] >= hi[j]:
            q[j] = hi[j]
            at = True
    return at


@_jit
def _in_limits(q, L):
    lo, hi = L[0], L[1]
    for j in range(q.shape[0]):
        if q[j] < lo[j] or q[j] > hi[j]:
            return False
    return True


@_jit
def descend(q, C, L, P, Rt, pt, posonly, tol, mode, patience):
    """Levenberg–Marquardt from ``q`` (modified in place): ``(position error [m], rotation error [rad], iterations)``."""
    lo, hi = L[0], L[1]
    nq = q.shape[0]
    rows = 3 if posonly else 6
    mu0, lam_min, max_step = P[_P_MU0], P[_P_LAMMIN], P[_P_STEP]
    stall_ratio = P[_P_STALLR]
    stall_steps = int(P[_P_STALLN]) * patience
    max_iter = int(P[_P_ITER]) * patience
    tol2 = tol * tol
    clip = mode == CLIP
    m = C[0].shape[0]
    R, p, Z, O = np.empty((3, 3)), np.empty(3), np.empty((m, 3)), np.empty((m, 3))
    e, J = np.empty(6), np.empty((6, nq))
    e_t, J_t = np.empty(6), np.empty((6, nq))
    q_t = np.empty(nq)
    dq = np.empty(nq)
    free = np.ones(nq, dtype=np.bool_)
    all_free = np.ones(nq, dtype=np.bool_)
    S = np.empty((3, 10))
    nb_ = max(rows, nq)
    Gs, xs = np.empty((nb_, nb_)), np.empty(nb_)
    at_limit = False
    if clip:
        at_limit = _clip(q, L)
        if not at_limit:
            for j in range(nq):
                if q[j] <= lo[j] or q[j] >= hi[j]:
                    at_limit = True
    E, pe2, th = _evaluate(q, C, Rt, pt, posonly, R, p, Z, O, e, J, S)
    mu, nu = mu0, 2.0
    it = 0
    stall = 0
    done = pe2 <= tol2 and th <= tol
    while not done and it < max_iter:
        it += 1
        accepted = False
        while mu < _MU_MAX:
            lam = mu * E + lam_min
            if not _damped_step(J, rows, e, lam, all_free, dq, Gs, xs):
                mu *= nu
                nu *= 2.0
                continue
            if at_limit:  # joints at a limit pushed outwards: out of the step, solved again
                nb = 0
                for j in range(nq):
                    blocked = (q[j] <= lo[j] and dq[j] < 0.0) or (q[j] >= hi[j] and dq[j] > 0.0)
                    free[j] = not blocked
                    nb += blocked
                if nb:
                    if not _damped_step(J, rows, e, lam, free, dq, Gs, xs):
                        mu *= nu
                        nu *= 2.0
                        continue
                    for j in range(nq):
                        if not free[j]:
                            dq[j] = 0.0
            step = 0.0
            for j in range(nq):
                step = max(step, abs(dq[j]))
            scale = max_step / step if step > max_step else 1.0
            for j in range(nq):
                dq[j] *= scale
                q_t[j] = q[j] + dq[j]
            clipped = _clip(q_t, L) if clip else False
            E_t, pe2_t, th_t = _evaluate(q_t, C, Rt, pt, posonly, R, p, Z, O, e_t, J_t, S)
            if E_t < E:  # accept; Nielsen's update of μ from the gain ratio
                predicted = E
                for a in range(rows):
                    r = e[a]
                    for j in range(nq):
                        r -= J[a, j] * dq[j]
                    predicted -= r * r
                rho = (E - E_t) / predicted if predicted > 0.0 else 1.0
                mu = max(mu * max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3), 1e-12)
                nu = 2.0
                stall = stall + 1 if E_t > stall_ratio * E else 0
                q[:] = q_t
                e, e_t = e_t, e
                J, J_t = J_t, J
                E, pe2, th = E_t, pe2_t, th_t
                at_limit = clipped
                accepted = True
                break
            mu *= nu
            nu *= 2.0
        if not accepted:
            break
        done = pe2 <= tol2 and th <= tol
        if stall >= stall_steps:
            break
    if mode == WINDOW:
        _wrap(q, L)
    else:
        unbounded = L[3]
        for j in range(nq):
            if unbounded[j]:
                q[j] = math.pi - (math.pi - q[j]) % _TWO_PI
    return math.sqrt(pe2), th, it


@_jit
def errors(q, C, Rt, pt, posonly):
    """``(position error [m], rotation error [rad])`` of ``q``."""
    m = C[0].shape[0]
    R, p, Z, O = np.empty((3, 3)), np.empty(3), np.empty((m, 3)), np.empty((m, 3))
    e, J = np.empty(6), np.empty((6, q.shape[0]))
    _, pe2, th = _evaluate(q, C, Rt, pt, posonly, R, p, Z, O, e, J, np.empty((3, 10)))
    return math.sqrt(pe2), th


@_jit
def attempt_within_limits(q, C, L, P, Rt, pt, posonly, tol):
    """Free descent (wrapped), then, met outside the limits, a projected one: ``(pe, re, iterations, ok)``; q in place, within the limits."""
    pe, re, it = descend(q, C, L, P, Rt, pt, posonly, tol, WINDOW, 1)
    met = pe <= tol and re <= tol
    if met and _in_limits(q, L):
        return pe, re, it, True
    _clip(q, L)
    if not met:
        pe, re = errors(q, C, Rt, pt, posonly)
        return pe, re, it, False
    pe, re, it2 = descend(q, C, L, P, Rt, pt, posonly, tol, CLIP, 1)
    return pe, re, it + it2, pe <= tol and re <= tol


@_jit
def _cost(C, q, Rt, pt, posonly, R, p, Z, O, S):
    qi, sc, of, rev, LR, Lp, fR, fp = C
    _fk(q, qi, sc, of, rev, LR, Lp, fR, fp, R, p, Z, O, S)
    d = math.sqrt((p[0] - pt[0]) ** 2 + (p[1] - pt[1]) ** 2 + (p[2] - pt[2]) ** 2)
    if posonly:
        return d
    f = 0.0
    for a in range(3):
        for b in range(3):
            f += (R[a, b] - Rt[a, b]) ** 2
    return d + _ROT_WEIGHT * math.sqrt(f)


@_jit
def table_index(tq, tp, tpp, tR, Rt, pt, posonly):
    """Row of the start table whose pose is nearest ``(Rt, pt)`` (``‖Δp‖ + 0.1 m/rad · ‖ΔR‖_F``)."""
    best, k_best = np.inf, 0
    ptp = pt[0] * pt[0] + pt[1] * pt[1] + pt[2] * pt[2]
    for k in range(tq.shape[0]):
        d2 = tpp[k] - 2.0 * (tp[k, 0] * pt[0] + tp[k, 1] * pt[1] + tp[k, 2] * pt[2]) + ptp
        c = math.sqrt(max(d2, 0.0))
        if not posonly:
            dot = 0.0
            for a in range(3):
                for b in range(3):
                    dot += tR[k, 3 * a + b] * Rt[a, b]
            c += _ROT_WEIGHT * math.sqrt(max(6.0 - 2.0 * dot, 0.0))
        if c < best:
            best, k_best = c, k
    return k_best


@_jit
def solve(q0, C, L, P, Rt, pt, posonly, tol, restarts, seed, q_out):
    """Attempt from ``q0``, then up to ``restarts`` starts drawn within the limits (``seed`` < 2³²), nearest pose first.

    Writes the solution (or the best configuration within the limits) to ``q_out``;
    returns ``(ok, pe, re, attempts, iterations)``.
    """
    lo, hi = L[0], L[1]
    nq = q0.shape[0]
    q = q0.copy()
    pe, re, its, ok = attempt_within_limits(q, C, L, P, Rt, pt, posonly, tol)
    best = pe + re
    q_out[:] = q
    attempts = 1
    if ok:
        return True, pe, re, attempts, its
    np.random.seed(seed)
    m = C[0].shape[0]
    R, p, Z, O = np.empty((3, 3)), np.empty(3), np.empty((m, 3)), np.empty((m, 3))
    S = np.empty((3, 7))
    pool = np.empty((_POOL, nq))
    cost = np.empty(_POOL)
    order = np.empty(0, dtype=np.int64)
    k = _POOL
    best_pe, best_re = pe, re
    while attempts <= restarts:
        if k == _POOL:
            for i in range(_POOL):
                for j in range(nq):
                    pool[i, j] = lo[j] + (hi[j] - lo[j]) * np.random.random()
                cost[i] = _cost(C, pool[i], Rt, pt, posonly, R, p, Z, O, S)
            order = np.argsort(cost, kind="mergesort")
            k = 0
        q[:] = pool[order[k]]
        k += 1
        attempts += 1
        pe, re, it, ok = attempt_within_limits(q, C, L, P, Rt, pt, posonly, tol)
        its += it
        if ok:
            q_out[:] = q
            return True, pe, re, attempts, its
        if pe + re < best:
            best = pe + re
            best_pe, best_re = pe, re
            q_out[:] = q
    return False, best_pe, best_re, attempts, its


@_jit
def solve_many(Rts, pts, starts, C, L, P, posonly, tol, restarts, seed, q_out, ok, pe, re):
    """:func:`solve` for every target ``k`` (restarts seeded by ``seed + k``); returns the total iterations."""
    total = 0
    for k in range(Rts.shape[0]):
        o, a, b, _, it = solve(starts[k], C, L, P, Rts[k], pts[k], posonly, tol, restarts,
                          (seed + k) % 4294967296, q_out[k])
        ok[k], pe[k], re[k] = o, a, b
        total += it
    return total
