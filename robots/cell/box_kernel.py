"""Compiled lower bounds of distances to the static boxes, cylinders and spheres of a cell, for :mod:`.cover_kernel`
(numba): a point's distance, and a moving cylinder's (one, or a mesh's slice cylinders beside their spheres,
:func:`.mesh_cover.mesh_parts`) through the gaps of its projections on a few lines (a projection shortens every
distance). Cached on disk like the other kernels. Lengths in m, the world frame.
"""

from __future__ import annotations

import math

import numpy as np

from pinarms.compiled import jit, jit_inline


@jit_inline
def fixture_distance(x0, x1, x2, kind, FR, Fp, size, o):
    """Distance [m] from point ``x`` to the static box (1), cylinder (2, axis z) or sphere (3) ``o``
    (world rotation ``FR[o]``, centre ``Fp[o]``, ``size[o]``); 0 inside."""
    d0, d1, d2 = x0 - Fp[o, 0], x1 - Fp[o, 1], x2 - Fp[o, 2]
    l0 = FR[o, 0, 0] * d0 + FR[o, 1, 0] * d1 + FR[o, 2, 0] * d2
    l1 = FR[o, 0, 1] * d0 + FR[o, 1, 1] * d1 + FR[o, 2, 1] * d2
    l2 = FR[o, 0, 2] * d0 + FR[o, 1, 2] * d1 + FR[o, 2, 2] * d2
    if kind == 1:
        o0 = max(abs(l0) - size[o, 0], 0.0)
        o1 = max(abs(l1) - size[o, 1], 0.0)
        o2 = max(abs(l2) - size[o, 2], 0.0)
        return math.sqrt(o0 * o0 + o1 * o1 + o2 * o2)
    if kind == 2:
        dr = max(math.sqrt(l0 * l0 + l1 * l1) - size[o, 0], 0.0)
        dz = max(abs(l2) - size[o, 1], 0.0)
        return math.sqrt(dr * dr + dz * dz)
    return max(math.sqrt(l0 * l0 + l1 * l1 + l2 * l2) - size[o, 0], 0.0)


@jit
def cylinder_box_gap(a, b, r, FR, Fp, half):
    """A lower bound [m] of the distance between the solid cylinder of axis ``a b`` and radius ``r`` and a
    static box (world rotation ``FR``, centre ``Fp``, half sides ``half``): the widest gap between their
    projections on the box's three axes (a projection shortens every distance). Exact for a cylinder
    standing upright over a box's face, where its spheres overshoot by nearly its radius."""
    return _box_gap(a.reshape((1, 3)), b.reshape((1, 3)), 0, r, FR.reshape((1, 3, 3)), Fp.reshape((1, 3)),
                    half.reshape((1, 3)), 0)


@jit_inline
def _box_gap(SA, SB, k, r, FR, Fp, half, o):
    """:func:`cylinder_box_gap` of the cylinder ``SA[k] SB[k]`` and the box ``o`` (``FR[o]``, ``Fp[o]``, ``half[o]``)."""
    u0, u1, u2 = SB[k, 0] - SA[k, 0], SB[k, 1] - SA[k, 1], SB[k, 2] - SA[k, 2]
    L = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    if L > 0.0:
        u0, u1, u2 = u0 / L, u1 / L, u2 / L
    gap = -np.inf
    for i in range(3):
        n0, n1, n2 = FR[o, 0, i], FR[o, 1, i], FR[o, 2, i]
        ca = (SA[k, 0] - Fp[o, 0]) * n0 + (SA[k, 1] - Fp[o, 1]) * n1 + (SA[k, 2] - Fp[o, 2]) * n2
        cb = (SB[k, 0] - Fp[o, 0]) * n0 + (SB[k, 1] - Fp[o, 1]) * n1 + (SB[k, 2] - Fp[o, 2]) * n2
        un = u0 * n0 + u1 * n1 + u2 * n2
        rad = r * math.sqrt(max(1.0 - un * un, 0.0))
        g = max(min(ca, cb) - rad - half[o, i], -half[o, i] - max(ca, cb) - rad)
        gap = max(gap, g)
    return gap


@jit_inline
def held_low(held, g, boxes, o, t, cut):
    """A lower bound [m] of the distance from moving geometry ``g`` held by its cylinders (:mod:`.cover`) to the static
    box ``o``: the least over cylinders ``k`` of the larger of its gaps (:func:`_box_gap`, :func:`_toward_gap`) and
    the distances of the spheres ``spart[k]`` holding its pieces. Only a bound at most ``cut`` is meant: a cylinder
    whose spheres are farther is passed over (so ``inf`` where none is nearer), and at one at most ``t`` (with
    ``t ≥ cut``: whether the bound exceeds ``t`` is meant) it returns early.

    ``held``: the cover's ``(W, radius, SA, SB, srad, sstart, spart)`` (sphere world centres and radii, cylinder
    axis ends and radii, each geometry's first cylinder, each cylinder's spheres); ``boxes``: the static shapes'
    ``(FR, Fp, half)`` (world rotations, centres, half sides)."""
    W, radius, SA, SB, srad, sstart, spart = held
    FR, Fp, half = boxes
    low = np.inf
    near = np.inf
    held = -1
    for k in range(sstart[g], sstart[g + 1]):
        many = spart[k, 1] - spart[k, 0] > 1  # a whole cylinder's spheres: its cheap gap first
        gap = _box_gap(SA, SB, k, srad[k], FR, Fp, half, o) if many else -np.inf
        if gap >= low or gap > cut:
            continue
        if spart[k, 0] != held or k == sstart[g]:
            held = spart[k, 0]  # a new sphere (a slice's cylinders follow each other, sharing their sphere)
            near = np.inf
            for s in range(spart[k, 0], spart[k, 1]):
                near = min(near, fixture_distance(W[s, 0], W[s, 1], W[s, 2], 1, FR, Fp, half, o) - radius[s])
        if near >= low or near > cut:
            continue
        if not many:
            gap = _box_gap(SA, SB, k, srad[k], FR, Fp, half, o)
        low = min(low, max(near, gap, _toward_gap(SA, SB, k, srad[k], FR, Fp, half, o)))
        if low <= t and t >= cut:
            return low
    return low


@jit_inline
def _toward_gap(SA, SB, k, r, FR, Fp, half, o):
    """The gap [m] between the projections of the cylinder ``SA[k] SB[k]`` (radius ``r``) and the box ``o`` on the line
    from the box's point ``c`` nearest the axis' middle ``m`` to ``m`` (the box lies behind ``c`` on it: ``c`` is
    nearest), ``|m − c|`` less the cylinder's half extent on it; −inf for ``m`` inside. Tight at a box's edge or corner."""
    m0, m1, m2 = 0.5 * (SA[k, 0] + SB[k, 0]), 0.5 * (SA[k, 1] + SB[k, 1]), 0.5 * (SA[k, 2] + SB[k, 2])
    n0, n1, n2 = m0 - Fp[o, 0], m1 - Fp[o, 1], m2 - Fp[o, 2]
    for i in range(3):  # m − c: the local coordinates' overshoot over each half side
        lc = (m0 - Fp[o, 0]) * FR[o, 0, i] + (m1 - Fp[o, 1]) * FR[o, 1, i] + (m2 - Fp[o, 2]) * FR[o, 2, i]
        inner = min(max(lc, -half[o, i]), half[o, i])
        n0, n1, n2 = n0 - inner * FR[o, 0, i], n1 - inner * FR[o, 1, i], n2 - inner * FR[o, 2, i]
    L = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    if L <= 1e-12:
        return -np.inf
    u0, u1, u2 = SB[k, 0] - SA[k, 0], SB[k, 1] - SA[k, 1], SB[k, 2] - SA[k, 2]
    un = abs(u0 * n0 + u1 * n1 + u2 * n2) / L  # |u·n̂|, u the whole axis
    ul = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    c = un / ul if ul > 0.0 else 0.0
    return L - 0.5 * un - r * math.sqrt(max(1.0 - c * c, 0.0))
