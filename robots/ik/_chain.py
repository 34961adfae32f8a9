"""Compiled kinematics of one serial chain (numba): pose, frame Jacobian, SE(3) error, start look-up.

The chain is the path from the base to a frame's joint, in :class:`~..kinematic_tree.KinematicTree`'s
rewritten form, passed as the tuple ``C = (qi, sc, of, rev, LR, Lp, fR, fp)``: joint ``k`` has the
constant placement ``(LR[k], Lp[k])`` after its parent and moves about (revolute, ``rev[k]``) or
along (prismatic) its own z axis by ``v = sc[k]·q[qi[k]] + of[k]`` (mimic joints: their master's
coordinate, scaled and offset); the frame sits at ``(fR, fp)`` after the last joint.

Error of ``q`` for the target ``(R_t, p_t)`` in base axes::

    e = [p_t − p(q);  log3(R_t R(q)ᵀ)]      (6,) [m, rad]  (position only: the first 3)

with the frame Jacobian in base axes at the frame origin (linear rows first), so that
``e(q + Δq) ≈ e − J Δq``. Units: m, rad. Used by the solver in :mod:`._kernel`.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pinarms import compiled
from pinarms.compiled import jit, jit_inline

#: the compiled solver's modules: their functions call (and inline) each other across files
KERNEL_MODULES = ("_chain.py", "_limits_kernel.py", "_kernel.py")


def drop_stale_caches(here: Path | None = None) -> bool:
    """Drop the compiled caches of :data:`KERNEL_MODULES` (in ``here``, default this folder) when
    any of their sources changed (:func:`pinarms.compiled.drop_stale_caches`)."""
    here = Path(__file__).resolve().parent if here is None else Path(here)
    return compiled.drop_stale_caches([here / name for name in KERNEL_MODULES], "ik_kernels.sha256")


drop_stale_caches()

ROT_WEIGHT = 0.1  # [m/rad] weight of the rotation distance when ranking starts


@jit_inline
def fk(q, qi, sc, of, rev, LR, Lp, fR, fp, R, p, Z, O):
    """Frame rotation ``R`` and origin ``p`` (written in place); joint axes ``Z`` and origins ``O`` ``(m, 3)``.

    The cosines and sines of the joint angles are taken first (held in ``Z[k, 0]``, ``Z[k, 1]``
    until the chain's pass writes joint ``k``'s axis), so that the pass itself calls no function
    and keeps the running rotation and position in registers.
    """
    m = qi.shape[0]
    for k in range(m):
        if rev[k]:
            v = sc[k] * q[qi[k]] + of[k]
            Z[k, 0] = math.cos(v)
            Z[k, 1] = math.sin(v)
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
    p0 = p1 = p2 = 0.0
    for k in range(m):
        a0, a1, a2 = Lp[k, 0], Lp[k, 1], Lp[k, 2]
        p0 = p0 + r00 * a0 + r01 * a1 + r02 * a2
        p1 = p1 + r10 * a0 + r11 * a1 + r12 * a2
        p2 = p2 + r20 * a0 + r21 * a1 + r22 * a2
        M = LR[k]
        n00 = r00 * M[0, 0] + r01 * M[1, 0] + r02 * M[2, 0]
        n01 = r00 * M[0, 1] + r01 * M[1, 1] + r02 * M[2, 1]
        n02 = r00 * M[0, 2] + r01 * M[1, 2] + r02 * M[2, 2]
        n10 = r10 * M[0, 0] + r11 * M[1, 0] + r12 * M[2, 0]
        n11 = r10 * M[0, 1] + r11 * M[1, 1] + r12 * M[2, 1]
        n12 = r10 * M[0, 2] + r11 * M[1, 2] + r12 * M[2, 2]
        n20 = r20 * M[0, 0] + r21 * M[1, 0] + r22 * M[2, 0]
        n21 = r20 * M[0, 1] + r21 * M[1, 1] + r22 * M[2, 1]
        n22 = r20 * M[0, 2] + r21 * M[1, 2] + r22 * M[2, 2]
        if rev[k]:
            c = Z[k, 0]
            s = Z[k, 1]
            r00, r01 = c * n00 + s * n01, c * n01 - s * n00
            r10, r11 = c * n10 + s * n11, c * n11 - s * n10
            r20, r21 = c * n20 + s * n21, c * n21 - s * n20
        else:
            v = sc[k] * q[qi[k]] + of[k]
            r00, r01, r10, r11, r20, r21 = n00, n01, n10, n11, n20, n21
            p0 += v * n02
            p1 += v * n12
            p2 += v * n22
        r02, r12, r22 = n02, n12, n22
        Z[k, 0], Z[k, 1], Z[k, 2] = r02, r12, r22
        O[k, 0], O[k, 1], O[k, 2] = p0, p1, p2
    a0, a1, a2 = fp[0], fp[1], fp[2]
    p[0] = p0 + r00 * a0 + r01 * a1 + r02 * a2
    p[1] = p1 + r10 * a0 + r11 * a1 + r12 * a2
    p[2] = p2 + r20 * a0 + r21 * a1 + r22 * a2
    for b in range(3):
        R[0, b] = r00 * fR[0, b] + r01 * fR[1, b] + r02 * fR[2, b]
        R[1, b] = r10 * fR[0, b] + r11 * fR[1, b] + r12 * fR[2, b]
        R[2, b] = r20 * fR[0, b] + r21 * fR[1, b] + r22 * fR[2, b]


@jit_inline
def jacobian(qi, sc, rev, Z, O, p, J):
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


@jit_inline
def log3_of(Rt, R, w):
    """``w = log3(Rt Rᵀ)`` (3,) in place; returns the angle [rad] (atan2 form; axis from the symmetric part near π)."""
    m00 = Rt[0, 0] * R[0, 0] + Rt[0, 1] * R[0, 1] + Rt[0, 2] * R[0, 2]
    m01 = Rt[0, 0] * R[1, 0] + Rt[0, 1] * R[1, 1] + Rt[0, 2] * R[1, 2]
    m02 = Rt[0, 0] * R[2, 0] + Rt[0, 1] * R[2, 1] + Rt[0, 2] * R[2, 2]
    m10 = Rt[1, 0] * R[0, 0] + Rt[1, 1] * R[0, 1] + Rt[1, 2] * R[0, 2]
    m11 = Rt[1, 0] * R[1, 0] + Rt[1, 1] * R[1, 1] + Rt[1, 2] * R[1, 2]
    m12 = Rt[1, 0] * R[2, 0] + Rt[1, 1] * R[2, 1] + Rt[1, 2] * R[2, 2]
    m20 = Rt[2, 0] * R[0, 0] + Rt[2, 1] * R[0, 1] + Rt[2, 2] * R[0, 2]
    m21 = Rt[2, 0] * R[1, 0] + Rt[2, 1] * R[1, 1] + Rt[2, 2] * R[1, 2]
    m22 = Rt[2, 0] * R[2, 0] + Rt[2, 1] * R[2, 1] + Rt[2, 2] * R[2, 2]
    w0 = 0.5 * (m21 - m12)
    w1 = 0.5 * (m02 - m20)
    w2 = 0.5 * (m10 - m01)
    c = 0.5 * (m00 + m11 + m22 - 1.0)
    s = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    theta = math.atan2(s, c)
    if c >= -0.9:
        k = theta / s if s > 1e-300 else 1.0
        w[0], w[1], w[2] = k * w0, k * w1, k * w2
        return theta
    # θ > 2.69 rad: (M + Mᵀ)/2 − c I = (1 − c) a aᵀ; the column of the largest diagonal entry
    d0, d1, d2 = m00 - c, m11 - c, m22 - c
    if d0 >= d1 and d0 >= d2:
        col0, col1, col2 = d0, 0.5 * (m10 + m01), 0.5 * (m20 + m02)
    elif d1 >= d2:
        col0, col1, col2 = 0.5 * (m01 + m10), d1, 0.5 * (m21 + m12)
    else:
        col0, col1, col2 = 0.5 * (m02 + m20), 0.5 * (m12 + m21), d2
    n = math.sqrt(max(col0 * col0 + col1 * col1 + col2 * col2, 1e-300))
    sign = -1.0 if (col0 * w0 + col1 * w1 + col2 * w2) < 0.0 else 1.0
    k = sign * theta / n
    w[0], w[1], w[2] = k * col0, k * col1, k * col2
    return theta


@jit_inline
def pose_error(q, C, Rt, pt, posonly, R, p, Z, O, e):
    """Error ``e`` of ``q`` (its pose, axes ``Z`` and origins ``O`` written too): ``(‖e‖², position error², angle)``."""
    qi, sc, of, rev, LR, Lp, fR, fp = C
    fk(q, qi, sc, of, rev, LR, Lp, fR, fp, R, p, Z, O)
    pe2 = 0.0
    for a in range(3):
        e[a] = pt[a] - p[a]
        pe2 += e[a] * e[a]
    if posonly:
        return pe2, pe2, 0.0
    theta = log3_of(Rt, R, e[3:])
    return pe2 + e[3] * e[3] + e[4] * e[4] + e[5] * e[5], pe2, theta


@jit
def errors(q, C, Rt, pt, posonly):
    """``(position error [m], rotation error [rad])`` of ``q``."""
    m = C[0].shape[0]
    _, pe2, th = pose_error(q, C, Rt, pt, posonly, np.empty((3, 3)), np.empty(3), np.empty((m, 3)),
                            np.empty((m, 3)), np.empty(6))
    return math.sqrt(pe2), th


@jit
def pose_cost(C, q, Rt, pt, posonly, R, p, Z, O):
    """Distance of ``q``'s pose to the target: ``‖Δp‖ + 0.1 m/rad · ‖ΔR‖_F`` (position only: the first term)."""
    qi, sc, of, rev, LR, Lp, fR, fp = C
    fk(q, qi, sc, of, rev, LR, Lp, fR, fp, R, p, Z, O)
    d = math.sqrt((p[0] - pt[0]) ** 2 + (p[1] - pt[1]) ** 2 + (p[2] - pt[2]) ** 2)
    if posonly:
        return d
    f = 0.0
    for a in range(3):
        for b in range(3):
            f += (R[a, b] - Rt[a, b]) ** 2
    return d + ROT_WEIGHT * math.sqrt(f)


@jit_inline
def _quaternion(Rt):
    """A unit quaternion ``(w, x, y, z)`` of the rotation ``Rt`` (Shepperd: from its largest diagonal term; either sign)."""
    t = Rt[0, 0] + Rt[1, 1] + Rt[2, 2]
    if t >= Rt[0, 0] and t >= Rt[1, 1] and t >= Rt[2, 2]:
        r = math.sqrt(1.0 + t)
        f = 0.5 / r
        return 0.5 * r, (Rt[2, 1] - Rt[1, 2]) * f, (Rt[0, 2] - Rt[2, 0]) * f, (Rt[1, 0] - Rt[0, 1]) * f
    if Rt[0, 0] >= Rt[1, 1] and Rt[0, 0] >= Rt[2, 2]:
        r = math.sqrt(max(1.0 + Rt[0, 0] - Rt[1, 1] - Rt[2, 2], 1e-300))
        f = 0.5 / r
        return (Rt[2, 1] - Rt[1, 2]) * f, 0.5 * r, (Rt[0, 1] + Rt[1, 0]) * f, (Rt[0, 2] + Rt[2, 0]) * f
    if Rt[1, 1] >= Rt[2, 2]:
        r = math.sqrt(max(1.0 - Rt[0, 0] + Rt[1, 1] - Rt[2, 2], 1e-300))
        f = 0.5 / r
        return (Rt[0, 2] - Rt[2, 0]) * f, (Rt[0, 1] + Rt[1, 0]) * f, 0.5 * r, (Rt[1, 2] + Rt[2, 1]) * f
    r = math.sqrt(max(1.0 - Rt[0, 0] - Rt[1, 1] + Rt[2, 2], 1e-300))
    f = 0.5 / r
    return (Rt[1, 0] - Rt[0, 1]) * f, (Rt[0, 2] + Rt[2, 0]) * f, (Rt[1, 2] + Rt[2, 1]) * f, 0.5 * r


@jit_inline
def _row_rotation(tQ, k, w, x, y, z):
    """The rotation term of a start-table row's cost, ``0.1 m/rad · ‖R_k − R_t‖_F``, from the rows' unit quaternions
    ``tQ (n, 4)`` and the target's ``(w, x, y, z)``: ``‖A − B‖_F² = 6 − 2 tr(AᵀB) = 8 (1 − (q_A·q_B)²)``."""
    dot = tQ[k, 0] * w + tQ[k, 1] * x + tQ[k, 2] * y + tQ[k, 3] * z
    return ROT_WEIGHT * math.sqrt(max(8.0 * (1.0 - dot * dot), 0.0))


@jit
def table_index(tq, tp, tpp, tQ, pen, Rt, pt, posonly):
    """Row of the start table whose pose is nearest ``(Rt, pt)`` (``‖Δp‖ + 0.1 m/rad · ‖ΔR‖_F + pen[k]``).

    A row whose position distance alone is no better than the best so far is passed over
    without its other terms (the cost only grows with them): the row of the full scan (up to rounding ties).
    """
    best, best2, k_best = np.inf, np.inf, 0
    w, x, y, z = _quaternion(Rt)
    ptp = pt[0] * pt[0] + pt[1] * pt[1] + pt[2] * pt[2]
    for k in range(tq.shape[0]):
        d2 = tpp[k] - 2.0 * (tp[k, 0] * pt[0] + tp[k, 1] * pt[1] + tp[k, 2] * pt[2]) + ptp
        if d2 >= best2:  # sqrt(d2) >= best: the position term alone rules the row out
            continue
        c = math.sqrt(max(d2, 0.0)) + pen[k]
        if not posonly:
            c += _row_rotation(tQ, k, w, x, y, z)
        if c < best:
            best, k_best = c, k
            best2 = c * c
    return k_best


@jit
def _cell_of(grid, pt):
    """``(cx, cy, cz, nx, ny, nz)``: the grid cell of the point ``pt`` (clamped to the grid) and the grid's size."""
    nx, ny, nz = int(grid[4]), int(grid[5]), int(grid[6])
    cx = min(max(int(math.floor((pt[0] - grid[0]) * grid[3])), 0), nx - 1)
    cy = min(max(int(math.floor((pt[1] - grid[1]) * grid[3])), 0), ny - 1)
    cz = min(max(int(math.floor((pt[2] - grid[2]) * grid[3])), 0), nz - 1)
    return cx, cy, cz, nx, ny, nz


@jit
def grid_index(table, Rt, pt, posonly):
    """Row of the gridded start table nearest ``(Rt, pt)`` among the rows in the target's cell and its 26 neighbours.

    ``table = (q, p, |p|², unit quaternions (n, 4), cell_start, grid, penalty)``, rows sorted by cell; ``grid = (x0,
    y0, z0, 1/size, nx, ny, nz)``; a target outside the grid looks in the nearest border cells. Cost as
    :func:`table_index` (the row's limit penalty included); when those cells are all empty, every row is scanned.
    """
    tq, tp, tpp, tQ, cell_start, grid, pen = table
    cx, cy, cz, nx, ny, nz = _cell_of(grid, pt)
    w, x, y, z = _quaternion(Rt)
    best, best2, k_best = np.inf, np.inf, -1
    for ix in range(max(cx - 1, 0), min(cx + 2, nx)):
        for iy in range(max(cy - 1, 0), min(cy + 2, ny)):
            for iz in range(max(cz - 1, 0), min(cz + 2, nz)):
                cell = (ix * ny + iy) * nz + iz
                for k in range(cell_start[cell], cell_start[cell + 1]):
                    d2 = (tp[k, 0] - pt[0]) ** 2 + (tp[k, 1] - pt[1]) ** 2 + (tp[k, 2] - pt[2]) ** 2
                    if d2 >= best2:  # the position term alone rules the row out
                        continue
                    c = math.sqrt(d2) + pen[k]
                    if not posonly:
                        c += _row_rotation(tQ, k, w, x, y, z)
                    if c < best:
                        best, best2, k_best = c, c * c, k
    if k_best < 0:
        return table_index(tq, tp, tpp, tQ, pen, Rt, pt, posonly)
    return k_best


@jit
def grid_neighbours(table, Rt, pt, posonly, count):
    """Up to ``count`` rows of the gridded start table in the target's cell and its 26 neighbours,
    nearest pose first (cost as :func:`grid_index`; equal costs in scan order); ``int64`` array.

    A bounded selection: once ``count`` rows are held, a row whose position term alone is no
    better than the worst of them is passed over (the former full sort of the 100-1 000 rows of
    the 27 cells cost ≈ 10 µs).
    """
    tq, tp, tpp, tQ, cell_start, grid, pen = table
    count = max(count, 1)
    cx, cy, cz, nx, ny, nz = _cell_of(grid, pt)
    w, x, y, z = _quaternion(Rt)
    rows = np.empty(count, dtype=np.int64)
    cost = np.empty(count)
    n = 0
    worst = np.inf
    for ix in range(max(cx - 1, 0), min(cx + 2, nx)):
        for iy in range(max(cy - 1, 0), min(cy + 2, ny)):
            for iz in range(max(cz - 1, 0), min(cz + 2, nz)):
                cell = (ix * ny + iy) * nz + iz
                for k in range(cell_start[cell], cell_start[cell + 1]):
                    d2 = (tp[k, 0] - pt[0]) ** 2 + (tp[k, 1] - pt[1]) ** 2 + (tp[k, 2] - pt[2]) ** 2
                    if n == count and d2 >= worst * worst:
                        continue
                    c = math.sqrt(d2) + pen[k]
                    if not posonly:
                        c += _row_rotation(tQ, k, w, x, y, z)
                    if n == count and c >= worst:
                        continue
                    i = min(n, count - 1)  # insert after the held rows of equal or lower cost
                    while i > 0 and cost[i - 1] > c:
                        if i < count:
                            rows[i], cost[i] = rows[i - 1], cost[i - 1]
                        i -= 1
                    rows[i], cost[i] = k, c
                    n = min(n + 1, count)
                    if n == count:
                        worst = cost[count - 1]
    return rows[:n]
