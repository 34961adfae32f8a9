"""Per-link travel bounds of the compiled edge proof: how far a pair's distance can change along an edge.

**The Lipschitz argument.** Along the straight joint-space edge ``x(s) = x_a + s (x_b − x_a)``,
``s ∈ [0, 1]``, a point ``P`` of link ``L`` (fixed in ``L``'s joint frame) moves with velocity
``Σ_i ṡ·scale_i·Δq_{c(i)} · (u_i × (P − o_i))`` for a revolute joint ``i`` upstream of ``L``
(axis ``u_i`` through its origin ``o_i``, configuration column ``c(i)``, mimic ``scale_i``),
and ``scale_i Δq_{c(i)} u_i`` for a prismatic one. ``|u_i × (P − o_i)| ≤ |P − o_i|`` and
``|P − o_i| ≤ ρ_{i,L}``: the largest ``|centre| + radius`` of ``L``'s cover spheres (they
contain its geometry, :mod:`pinarms.robots.cell.cover`) plus, up the chain from ``L`` to the child
of ``i``, every joint's offset ``|M_p|`` and, for a prismatic joint, its largest stroke
``max |scale·q + offset|`` over its limits — whatever the other joints are. So ``P`` moves
at most ``(s₁ − s₀) Σ_i |Δq_{c(i)}| λ_{i,L}`` between ``s₀`` and ``s₁``, with
``λ_{i,L} = |scale_i| ρ_{i,L}`` (revolute) or ``|scale_i|`` (prismatic).

The distance ``d`` between two links ``A`` and ``B`` depends only on their relative placement:
a joint upstream of both moves them as one rigid body and leaves ``d`` unchanged. Seen from
their common ancestor, ``A``'s points move by the joints upstream of ``A`` and not of ``B``,
``B``'s by those upstream of ``B`` and not of ``A``, so ``d`` (and the pair's excess
``d − t``) changes by at most ``(s₁ − s₀) w`` with
``w = Σ_{i ∈ up(A)∖up(B)} |Δq| λ_{i,A} + Σ_{i ∈ up(B)∖up(A)} |Δq| λ_{i,B}`` (a static fixture:
``up = ∅``). The whole-arm bound ``T = Σ_j |Δq_j| ℓ_j`` (:func:`pinarms.robots.cell.motion.joint_levers`)
holds for every pair too; each group's weight is ``min(w, T)``.

With ``e_k(s)`` the excess of pair ``k`` (of group ``g``, weight ``w_g``) and ``ê_k ≤ e_k`` the
cover's lower bound at the ends of ``[s₀, s₁]``: for ``s`` inside,
``2 e_k(s) ≥ e_k(s₀) + e_k(s₁) − (s₁ − s₀) w_g``. Writing ``Ẽ(x) = min_k ê_k(x) / w_{g(k)}`` (the
*scaled* excess), ``Ẽ(s₀) + Ẽ(s₁) ≥ s₁ − s₀`` gives ``ê_k(s₀) + ê_k(s₁) ≥ (s₁ − s₀) w_g`` for every
``k``, so every ``e_k(s) ≥ 0`` on the interval: the interval is proven. A pair left out of the
check (proven more than ``reach`` above its threshold, weight at most ``T``) has
``e_k / w ≥ reach / T``: ``Ẽ`` is capped there. A smaller weight only scales a pair's excess
up; the pairs of the base links (few joints upstream, short levers) and the links far from
the moving joints then cost far fewer states than under one lever for the whole arm.
"""

from __future__ import annotations

from typing import Any, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    from pinarms.robots.cell.cover import Cover

__all__ = ["link_levers", "group_levers"]


def _chains(parent: np.ndarray) -> np.ndarray:
    """``(nj, nj)`` bool: ``C[L, i]`` when joint ``i ≥ 1`` is ``L`` or upstream of it."""
    nj = parent.size
    C = np.zeros((nj, nj), dtype=bool)
    for L in range(1, nj):
        i = L
        while i > 0:
            C[L, i] = True
            i = int(parent[i])
    return C


def _joint_levers(cover: Any, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """``(nj, nj)``: ``λ_{i,L}`` of joint ``i`` for the points of link ``L`` (module docstring); 0 off the chain."""
    parent, index, scale, offset, revolute = (np.asarray(a) for a in cover.fk[:5])
    Mp = np.asarray(cover.fk[7], dtype=float)
    nj = parent.size
    own = np.zeros(nj)
    np.maximum.at(own, np.asarray(cover.joint, dtype=np.int64),
                  np.linalg.norm(cover.center, axis=1) + np.asarray(cover.radius, dtype=float))
    stroke = np.zeros(nj)
    for i in range(1, nj):
        if not revolute[i]:
            ends = scale[i] * np.array([lower[index[i]], upper[index[i]]]) + offset[i]
            stroke[i] = float(np.abs(ends).max())
    hop = np.linalg.norm(Mp, axis=1) + stroke  # bound of |o_i − o_parent(i)|
    J = np.zeros((nj, nj))
    for L in range(1, nj):
        acc, i = float(own[L]), L
        while i > 0:
            J[L, i] = abs(float(scale[i])) * (acc if revolute[i] else 1.0)
            acc += float(hop[i])
            i = int(parent[i])
    return J * (1.0 + 1e-9)  # a hair over the rounding of the sums


def link_levers(cover: Cover, lower: ArrayLike, upper: ArrayLike) -> np.ndarray:
    """``(nj, nq)``: row ``L`` bounds how far any point of link ``L``'s cover moves per unit change of each
    configuration column (``Σ_c |Δq_c| · row[c]``), for a cell with limits ``lower``, ``upper (nq,)``."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    J = _joint_levers(cover, lower, upper)
    index = np.asarray(cover.fk[1], dtype=np.int64)
    out = np.zeros((J.shape[0], lower.size))
    for i in range(1, J.shape[0]):
        out[:, index[i]] += J[:, i]
    return out


def group_levers(cover: Cover, pairs: tuple, lower: ArrayLike, upper: ArrayLike, cols: ArrayLike) -> np.ndarray:
    """``(G, n)``: for each pair group of ``pairs`` (:meth:`Cover.prepare`: two links, or a link and a
    fixture), how much its distance can change per unit change of each planned column ``cols``
    (module docstring: the joints upstream of one link and not of the other)."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    J = _joint_levers(cover, lower, upper)
    C = _chains(np.asarray(cover.fk[0], dtype=np.int64))
    ja = np.asarray(pairs.hjoint, dtype=np.int64)[np.asarray(pairs.group_a, dtype=np.int64)]
    jb = np.asarray(pairs.hjoint, dtype=np.int64)[np.asarray(pairs.group_b, dtype=np.int64)]
    W = J[ja] * ~C[jb] + J[jb] * ~C[ja]
    index = np.asarray(cover.fk[1], dtype=np.int64)
    out = np.zeros((W.shape[0], lower.size))
    for i in range(1, J.shape[0]):
        out[:, index[i]] += W[:, i]
    return np.ascontiguousarray(out[:, np.asarray(cols, dtype=np.int64)])
