"""Compiled parts of :mod:`.cover` (numba): batched forward kinematics to the cover's spheres and the screen.

Joints as in :class:`.placements.BatchedPlacements` (the same arrays): joint ``i`` sits at
``(M_R[i], M_p[i])`` after its parent and rotates about (revolute) or moves along its unit
``axis[i]`` by ``scale[i]·q[index[i]] + offset[i]``; joint 0 is the world. Cached on disk
like :mod:`pinarms.robots.ik._kernel` (compiled per process where no cache location is writable).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pinarms.compiled import drop_stale_caches, jit, jit_inline

from pinarms.robots.cell import box_kernel
from pinarms.robots.cell.box_kernel import fixture_distance, held_low

# these kernels inline the bounds of box_kernel: its changes must compile them again (pinarms.compiled)
drop_stale_caches([Path(box_kernel.__file__), Path(__file__)],
                  "cover_kernels.sha256")


@jit
def _fk(q, parent, index, scale, offset, revolute, axis, MR, Mp, R, p):
    """World rotation ``R (nj, 3, 3)`` and position ``p (nj, 3)`` of every joint (in place)."""
    for a in range(3):
        p[0, a] = 0.0
        for b in range(3):
            R[0, a, b] = 1.0 if a == b else 0.0
    RM = np.empty((3, 3))
    for i in range(1, parent.shape[0]):
        _fk_joint(i, q, parent, index, scale, offset, revolute, axis, MR, Mp, R, p, RM)


@jit_inline
def _fk_joint(i, q, parent, index, scale, offset, revolute, axis, MR, Mp, R, p, RM):
    """Joint ``i``'s world placement from its parent's (``RM (3, 3)``: scratch)."""
    par = parent[i]
    v = scale[i] * q[index[i]] + offset[i]
    for a in range(3):
        s = p[par, a]
        for b in range(3):
            s += R[par, a, b] * Mp[i, b]
            t = 0.0
            for c in range(3):
                t += R[par, a, c] * MR[i, c, b]
            RM[a, b] = t
        p[i, a] = s
    ux, uy, uz = axis[i, 0], axis[i, 1], axis[i, 2]
    if revolute[i]:
        c = math.cos(v)
        s = math.sin(v)
        t = 1.0 - c
        L00, L01, L02 = t * ux * ux + c, t * ux * uy - s * uz, t * ux * uz + s * uy
        L10, L11, L12 = t * ux * uy + s * uz, t * uy * uy + c, t * uy * uz - s * ux
        L20, L21, L22 = t * ux * uz - s * uy, t * uy * uz + s * ux, t * uz * uz + c
        for a in range(3):
            x, y, z = RM[a, 0], RM[a, 1], RM[a, 2]
            R[i, a, 0] = x * L00 + y * L10 + z * L20
            R[i, a, 1] = x * L01 + y * L11 + z * L21
            R[i, a, 2] = x * L02 + y * L12 + z * L22
    else:
        for a in range(3):
            for b in range(3):
                R[i, a, b] = RM[a, b]
            p[i, a] += v * (RM[a, 0] * ux + RM[a, 1] * uy + RM[a, 2] * uz)


@jit
def _centers(R, p, joint, center, W):
    for s in range(joint.shape[0]):
        j = joint[s]
        for a in range(3):
            W[s, a] = p[j, a] + R[j, a, 0] * center[s, 0] + R[j, a, 1] * center[s, 1] + R[j, a, 2] * center[s, 2]


@jit
def centers_kernel(Q, fk, joint, center, out):
    """Sphere centres ``out (N, S, 3)`` in the world for the cell configurations ``Q (N, nq)`` (``fk``: the joints'
    arrays, :meth:`Cover.fk`; ``joint``, ``center``: each sphere's joint and centre in its frame)."""
    parent, index, scale, offset, revolute, axis, MR, Mp = fk
    nj = parent.shape[0]
    R = np.empty((nj, 3, 3))
    p = np.empty((nj, 3))
    for i in range(Q.shape[0]):
        _fk(Q[i], parent, index, scale, offset, revolute, axis, MR, Mp, R, p)
        _centers(R, p, joint, center, out[i])


@jit_inline
def _cylinder_distance(x0, x1, x2, SA, SB, k, r):
    """Distance [m] from point ``x`` to the solid cylinder of axis ``SA[k] SB[k]`` and radius ``r``; 0 inside."""
    u0, u1, u2 = SB[k, 0] - SA[k, 0], SB[k, 1] - SA[k, 1], SB[k, 2] - SA[k, 2]
    L = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    w0, w1, w2 = x0 - SA[k, 0], x1 - SA[k, 1], x2 - SA[k, 2]
    ww = w0 * w0 + w1 * w1 + w2 * w2
    if L <= 1e-15:
        return max(math.sqrt(ww) - r, 0.0)
    t = (w0 * u0 + w1 * u1 + w2 * u2) / L
    radial = math.sqrt(max(ww - t * t, 0.0))
    dr = max(radial - r, 0.0)
    dz = max(abs(t - 0.5 * L) - 0.5 * L, 0.0)
    return math.sqrt(dr * dr + dz * dz)


@jit_inline
def _exact_distance(x0, x1, x2, other, exact, FR, Fp, size, SA, SB, srad, sstart):
    """Distance [m] from point ``x`` to geometry ``other`` taken exactly (a static shape, or a moving cylinder)."""
    if exact[other] != 0:
        return fixture_distance(x0, x1, x2, exact[other], FR, Fp, size, other)
    k = sstart[other]
    return _cylinder_distance(x0, x1, x2, SA, SB, k, srad[k])


@jit_inline
def _spheres_clear(W, radius, start, g, other, exact, FR, Fp, size, SA, SB, srad, sstart, cyl, spart, t, HW, hrad):
    """Cover spheres of geometry ``g`` against geometry ``other`` taken exactly (a static box,
    cylinder or sphere, or a moving cylinder): all more than ``t`` away. The bounding sphere of
    ``g`` (``HW[g]``, ``hrad[g]``) first."""
    if _exact_distance(HW[g, 0], HW[g, 1], HW[g, 2], other, exact, FR, Fp, size, SA, SB, srad, sstart) - hrad[g] > t:
        return True
    if cyl[g] != 0 and exact[other] == 1:
        return held_low((W, radius, SA, SB, srad, sstart, spart), g, (FR, Fp, size), other, t, t) > t
    for s in range(start[g], start[g + 1]):
        d = _exact_distance(W[s, 0], W[s, 1], W[s, 2], other, exact, FR, Fp, size, SA, SB, srad, sstart)
        if d - radius[s] <= t:
            return False
    return True


@jit_inline
def _pair_clear(W, radius, start, exact, FR, Fp, size, SA, SB, srad, sstart, cyl, spart, ga, gb, t, HW, hrad):
    """Whether the cover proves geometries ``ga`` and ``gb`` more than ``t`` apart."""
    if exact[gb] != 0 or (cyl[gb] == 1 and exact[ga] == 0):
        return _spheres_clear(W, radius, start, ga, gb, exact, FR, Fp, size, SA, SB, srad, sstart, cyl, spart, t, HW,
                              hrad)
    if exact[ga] != 0 or cyl[ga] == 1:
        return _spheres_clear(W, radius, start, gb, ga, exact, FR, Fp, size, SA, SB, srad, sstart, cyl, spart, t, HW,
                              hrad)
    for sa in range(start[ga], start[ga + 1]):
        for sb in range(start[gb], start[gb + 1]):
            reach = radius[sa] + radius[sb] + t
            e0 = W[sa, 0] - W[sb, 0]
            e1 = W[sa, 1] - W[sb, 1]
            e2 = W[sa, 2] - W[sb, 2]
            if reach > 0.0 and e0 * e0 + e1 * e1 + e2 * e2 <= reach * reach:
                return False
    return True


@jit
def screen_kernel(Q, fk, cov, grp, work, stop, out):
    """``out[i]``: every pair proven more than its threshold apart at ``Q[i]`` (module docstring of :mod:`.cover`;
    the arrays as :func:`excess_one`'s).

    The pairs come in groups (the geometries of one link against those of another); a group
    is first tested on the two bounding spheres at its largest threshold, then pair by pair on
    the geometries' bounding spheres, their distance table (:mod:`.pair_tables`) where they have
    one, then their covers. ``stop``: return at the first inconclusive row (its index; else −1)."""
    exact, FR, Fp, size = cov[4], cov[5], cov[6], cov[7]
    hrad, group_start, group_a, group_b, group_fixed, group_t = grp[2], grp[3], grp[4], grp[5], grp[6], grp[7]
    HW = work[5]
    for i in range(Q.shape[0]):
        place_world(Q[i], fk, cov, grp[0], grp[1], work)
        ok = True
        for g in range(group_t.shape[0]):
            if spheres_apart(HW, hrad, group_a[g], group_b[g], group_t[g]):
                continue
            fixed = group_fixed[g]
            ha = group_a[g]
            if fixed >= 0 and fixture_distance(HW[ha, 0], HW[ha, 1], HW[ha, 2], exact[fixed], FR, Fp, size, fixed) \
                    - hrad[ha] > group_t[g]:
                continue
            for k in range(group_start[g], group_start[g + 1]):
                if not pair_proven(cov, grp, work, k):
                    ok = False
                    break
            if not ok:
                break
        out[i] = ok
        if stop and not ok:
            return i
    return -1


@jit_inline
def pair_proven(cov, grp, work, k):
    """Whether pair ``k`` (the groups' order) is proven more than its threshold apart on ``work`` placed:
    its bounding spheres, its table (:func:`table_low`), its covers (:func:`_pair_clear`)."""
    ga, gb, t = grp[8][k], grp[9][k], grp[10][k]
    if spheres_apart(work[5], grp[2], ga, gb, t):
        return True
    tab = grp[11][k]
    if tab >= 0 and table_low(work[0], cov[14], tab) > t:
        return True
    return _pair_clear(work[2], cov[2], cov[3], cov[4], cov[5], cov[6], cov[7], work[3], work[4], cov[11], cov[12],
                       cov[13], cov[15], ga, gb, t, work[5], grp[2])


@jit_inline
def _angle(R, tabs, t, i):
    """Angle [rad] of axis ``i`` of table ``t`` from the placed joint frames ``R`` (:mod:`.pair_tables`)."""
    j, par, ea, eb, e = tabs[0][t, i], tabs[1][t, i], tabs[2], tabs[3], tabs[4]
    c = 0.0
    s = 0.0
    for a in range(3):
        w = R[j, a, 0] * e[t, i, 0] + R[j, a, 1] * e[t, i, 1] + R[j, a, 2] * e[t, i, 2]
        c += w * (R[par, a, 0] * ea[t, i, 0] + R[par, a, 1] * ea[t, i, 1] + R[par, a, 2] * ea[t, i, 2])
        s += w * (R[par, a, 0] * eb[t, i, 0] + R[par, a, 1] * eb[t, i, 1] + R[par, a, 2] * eb[t, i, 2])
    return math.atan2(s, c)


@jit_inline
def table_low(R, tabs, t):
    """Table ``t``'s proven lower bound [m] of its pair's distance at the joint frames ``R`` (its k-d tree over the
    angles of its joints, :mod:`.pair_tables`)."""
    v0 = _angle(R, tabs, t, 0) if tabs[0][t, 0] >= 0 else 0.0
    v1 = _angle(R, tabs, t, 1) if tabs[0][t, 1] >= 0 else 0.0
    child, split = tabs[6], tabs[7]
    lo0 = -math.pi
    lo1 = -math.pi
    w0 = 2.0 * math.pi
    w1 = 2.0 * math.pi
    n = tabs[5][t]
    while child[n] >= 0:
        if split[n] == 0:
            w0 *= 0.5
            up = v0 >= lo0 + w0
            if up:
                lo0 += w0
        else:
            w1 *= 0.5
            up = v1 >= lo1 + w1
            if up:
                lo1 += w1
        n = child[n] + (1 if up else 0)
    return tabs[8][n]


@jit
def spheres_apart(HW, hrad, a, b, t):
    """Whether the bounding spheres ``a`` and ``b`` (world centres ``HW``, radii ``hrad`` [m]) are more than ``t`` apart."""
    reach = hrad[a] + hrad[b] + t
    e0 = HW[a, 0] - HW[b, 0]
    e1 = HW[a, 1] - HW[b, 1]
    e2 = HW[a, 2] - HW[b, 2]
    return reach < 0.0 or e0 * e0 + e1 * e1 + e2 * e2 > reach * reach


@jit_inline
def _spheres_excess(W, radius, start, g, other, exact, FR, Fp, size, SA, SB, srad, sstart, cyl, spart, t, HW,
                               hrad,                     best):
    """``min(best, lower bound of distance(g, other) − t)``: the cover spheres of ``g`` against ``other``
    taken exactly (a static box, cylinder or sphere, or a moving cylinder); its bounding sphere first."""
    if _exact_distance(HW[g, 0], HW[g, 1], HW[g, 2], other, exact, FR, Fp, size, SA, SB, srad, sstart) - hrad[g] \
            - t >= best:
        return best
    if cyl[g] != 0 and exact[other] == 1:
        return min(best, held_low((W, radius, SA, SB, srad, sstart, spart), g, (FR, Fp, size), other, -np.inf,
                                   t + best) - t)
    low = np.inf
    if exact[other] != 0:
        for s in range(start[g], start[g + 1]):
            d = fixture_distance(W[s, 0], W[s, 1], W[s, 2], exact[other], FR, Fp, size, other)
            low = min(low, d - radius[s] - t)
        return min(best, low)
    # a moving cylinder: its axis once for all the spheres (the same arithmetic as _cylinder_distance)
    k = sstart[other]
    a0, a1, a2, r = SA[k, 0], SA[k, 1], SA[k, 2], srad[k]
    u0, u1, u2 = SB[k, 0] - a0, SB[k, 1] - a1, SB[k, 2] - a2
    L = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    for s in range(start[g], start[g + 1]):
        w0, w1, w2 = W[s, 0] - a0, W[s, 1] - a1, W[s, 2] - a2
        ww = w0 * w0 + w1 * w1 + w2 * w2
        if L <= 1e-15:
            d = max(math.sqrt(ww) - r, 0.0)
        else:
            h = (w0 * u0 + w1 * u1 + w2 * u2) / L
            dr = max(math.sqrt(max(ww - h * h, 0.0)) - r, 0.0)
            dz = max(abs(h - 0.5 * L) - 0.5 * L, 0.0)
            d = math.sqrt(dr * dr + dz * dz)
        low = min(low, d - radius[s] - t)
    return min(best, low)


@jit_inline
def _pair_excess(W, radius, start, exact, FR, Fp, size, SA, SB, srad, sstart, cyl, spart, ga, gb, t, HW, hrad,
                 best):
    """``min(best, lower bound of distance(ga, gb) − t)`` from the covers (:func:`_pair_clear`'s cases)."""
    if exact[gb] != 0 or (cyl[gb] == 1 and exact[ga] == 0):
        return _spheres_excess(W, radius, start, ga, gb, exact, FR, Fp, size, SA, SB, srad, sstart, cyl, spart, t, HW,
                               hrad, best)
    if exact[ga] != 0 or cyl[ga] == 1:
        return _spheres_excess(W, radius, start, gb, ga, exact, FR, Fp, size, SA, SB, srad, sstart, cyl, spart, t, HW,
                               hrad, best)
    for sa in range(start[ga], start[ga + 1]):
        for sb in range(start[gb], start[gb + 1]):
            rr = radius[sa] + radius[sb] + t
            reach = best + rr
            if reach <= 0.0:
                continue
            e0 = W[sa, 0] - W[sb, 0]
            e1 = W[sa, 1] - W[sb, 1]
            e2 = W[sa, 2] - W[sb, 2]
            e = e0 * e0 + e1 * e1 + e2 * e2
            if e < reach * reach:
                best = math.sqrt(e) - rr
    return best


@jit
def _hd(HW, hrad, a, b):
    e0 = HW[a, 0] - HW[b, 0]
    e1 = HW[a, 1] - HW[b, 1]
    e2 = HW[a, 2] - HW[b, 2]
    return math.sqrt(e0 * e0 + e1 * e1 + e2 * e2) - hrad[a] - hrad[b]


@jit
def place_world(q, fk, cov, hjoint, hcenter, work):
    """Forward kinematics of cell configuration ``q`` and the world centres of the cover's spheres,
    its cylinders' axis ends and the bounding spheres (joints ``hjoint``, centres ``hcenter``), into ``work``
    (:meth:`Cover.work`'s arrays); ``cov``: :meth:`Cover.kernel_arrays`."""
    parent, index, scale, offset, revolute, axis, MR, Mp = fk
    joint, center, sjoint, sa_local, sb_local = cov[0], cov[1], cov[8], cov[9], cov[10]
    R, p, W, SA, SB, HW = work
    _fk(q, parent, index, scale, offset, revolute, axis, MR, Mp, R, p)
    _centers(R, p, joint, center, W)
    _centers(R, p, sjoint, sa_local, SA)
    _centers(R, p, sjoint, sb_local, SB)
    _centers(R, p, hjoint, hcenter, HW)


#: No group weights: :func:`excess_scaled` then bounds the excess itself (every weight 1). Inside a kernel, write
#: ``np.empty(0)``: numba passes a module's array as a read-only constant, another type than the weights'
#: array, and compiles every kernel it reaches once more for it.
UNWEIGHTED = np.empty(0)


@jit
def excess_one(q, fk, cov, grp, cap, floor, work):
    """A lower bound [m] of ``min_k (d_k − t_k)`` over the pairs of ``grp`` at cell configuration ``q``,
    at most ``cap``; it returns early (some value below ``floor``) once the bound falls below ``floor``.

    ``fk``: :meth:`Cover.fk`'s arrays; ``cov``: the cover's arrays (:meth:`Cover.kernel_arrays`);
    ``grp``: the pair groups (:meth:`Cover.group_arrays`) with the thresholds ``t`` in their order;
    ``work``: scratch arrays (:meth:`Cover.work`). The covers' distances and the distance tables'
    bounds (:mod:`.pair_tables`, ``cov[14]``, ``grp[11]``) are lower bounds of the geometries'
    distances, so the result is a lower bound of the exact excess.
    :func:`excess_scaled` without weights."""
    return excess_scaled(q, fk, cov, grp, np.empty(0), cap, floor, work)  # not UNWEIGHTED (above)


@jit
def excess_kernel(Q, fk, cov, grp, cap, floor, work, out):
    """:func:`excess_one` for every row of ``Q (N, nq)`` into ``out (N,)``."""
    for i in range(Q.shape[0]):
        out[i] = excess_one(Q[i], fk, cov, grp, cap, floor, work)


@jit
def excess_scaled(q, fk, cov, grp, inv, cap, floor, work):
    """:func:`excess_one` with the pairs of group ``g`` weighed by ``inv[g] > 0``: a lower bound of
    ``min_k inv[g(k)] · (d_k − t_k)``, at most ``cap`` (early out below ``floor``). The compiled edge
    proof's scaled excess (``inv``: one over each group's travel weight, :mod:`pinarms.optim.motion.link_levers`);
    ``inv`` empty (:data:`UNWEIGHTED`): every weight 1, the excess itself (:func:`excess_one`)."""
    place_world(q, fk, cov, grp[0], grp[1], work)
    return excess_placed(cov, grp, inv, cap, floor, work)


@jit
def place_moving(q, fk, cov, grp, work, moving):
    """Place cell configuration ``q`` into ``work`` (:meth:`Cover.work`'s arrays) already placed at a
    configuration that differs from ``q`` only in the joints ``moving[0]`` (ascending; the joints
    below them included): their frames, then the bounding spheres ``moving[1]``, the cover spheres
    ``moving[2]`` and the cylinder axes ``moving[3]`` on them (``moving[4] (3, 3)``: scratch). The
    compiled search's states: the held arms and the fixtures are placed once, not at every state."""
    parent, index, scale, offset, revolute, axis, MR, Mp = fk
    R, p, W, SA, SB, HW = work[0], work[1], work[2], work[3], work[4], work[5]
    mjoint, mbound, msphere, mseg, RM = moving
    for k in range(mjoint.shape[0]):
        _fk_joint(mjoint[k], q, parent, index, scale, offset, revolute, axis, MR, Mp, R, p, RM)
    hjoint, hcenter = grp[0], grp[1]
    joint, center, sjoint, sa_local, sb_local = cov[0], cov[1], cov[8], cov[9], cov[10]
    # one loop per kind of point, written out (a call per point costs more than the point)
    for k in range(mbound.shape[0]):
        s = mbound[k]
        j = hjoint[s]
        for a in range(3):
            HW[s, a] = p[j, a] + R[j, a, 0] * hcenter[s, 0] + R[j, a, 1] * hcenter[s, 1] + R[j, a, 2] * hcenter[s, 2]
    for k in range(msphere.shape[0]):
        s = msphere[k]
        j = joint[s]
        for a in range(3):
            W[s, a] = p[j, a] + R[j, a, 0] * center[s, 0] + R[j, a, 1] * center[s, 1] + R[j, a, 2] * center[s, 2]
    for k in range(mseg.shape[0]):
        s = mseg[k]
        j = sjoint[s]
        for a in range(3):
            SA[s, a] = p[j, a] + R[j, a, 0] * sa_local[s, 0] + R[j, a, 1] * sa_local[s, 1] + R[j, a, 2] * sa_local[s, 2]
            SB[s, a] = p[j, a] + R[j, a, 0] * sb_local[s, 0] + R[j, a, 1] * sb_local[s, 1] + R[j, a, 2] * sb_local[s, 2]


@jit
def excess_placed(cov, grp, inv, cap, floor, work):
    """:func:`excess_scaled` on ``work`` already placed (:func:`place_world` or :func:`place_moving`).

    The group and pair tests run on the bounding spheres; a pair with a distance table takes the
    larger of its table's bound and its cover's (the table first: a pair it keeps above the
    running bound costs no cover test); the others are computed inline (:func:`_pair_excess`).
    Any lower bound keeps the edge proofs valid: they need ``d ≥ bound`` at their samples only."""
    radius, start, exact, FR, Fp, size = cov[2], cov[3], cov[4], cov[5], cov[6], cov[7]
    srad, sstart, cyl = cov[11], cov[12], cov[13]
    hrad, group_start, group_a, group_b, group_fixed, group_t = grp[2], grp[3], grp[4], grp[5], grp[6], grp[7]
    pair_a, pair_b, t, table = grp[8], grp[9], grp[10], grp[11]
    W, SA, SB, HW = work[2], work[3], work[4], work[5]
    weighted = inv.shape[0] > 0
    best = cap
    for g in range(group_t.shape[0]):
        a = group_a[g]
        s = inv[g] if weighted else 1.0
        if (_hd(HW, hrad, a, group_b[g]) - group_t[g]) * s >= best:
            continue
        fixed = group_fixed[g]
        if fixed >= 0 and (fixture_distance(HW[a, 0], HW[a, 1], HW[a, 2], exact[fixed], FR, Fp, size, fixed)
                           - hrad[a] - group_t[g]) * s >= best:
            continue
        for k in range(group_start[g], group_start[g + 1]):
            ga = pair_a[k]
            gb = pair_b[k]
            if (_hd(HW, hrad, ga, gb) - t[k]) * s >= best:
                continue
            tab = table[k]
            low = table_low(work[0], cov[14], tab) - t[k] if tab >= 0 else -np.inf
            if low * s >= best:
                continue
            raw = best / s
            r = _pair_excess(W, radius, start, exact, FR, Fp, size, SA, SB, srad, sstart, cyl, cov[15], ga, gb, t[k],
                             HW, hrad, raw)
            if r < raw:
                best = min(best, max(r, low) * s)
            if best < floor:
                return best
    return best
