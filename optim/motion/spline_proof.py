"""The smoothed spline proven on the compiled cover check first, the exact proof only where it is inconclusive.

:func:`open_ranges` runs the compiled proof of :mod:`._spline_kernel` on a joint path with the
cumulative travel bound of :func:`.smoothing._travel_bound`: the same Lipschitz rule as the
exact proof (:meth:`MotionChecker.prove`), the excess of every state the cover's lower bound
(the planned arm placed alone, :func:`.fast.fast_check`), and returns the ranges of ``s`` it
did not prove. :func:`.smoothing.prove_path` then proves those ranges alone with the exact
proof (coal where the cover is inconclusive); the rest of the path is proven already. Nothing
closer than the margin is called clear: the cover contains the geometry, so its excess is a
lower bound of the exact one.

The joint limits are checked exactly: a piece whose exact joint extrema leave the limits is
left open (the exact proof checks its samples against them, as before); :func:`joint_extrema` /
:func:`outside_joints` give those extrema per joint, with which :func:`.smoothing.prove_path`
refuses such a piece before any sample is proven (a spline may leave a limit between samples).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms.optim.motion.proof import MAX_SPLITS
from pinarms.planning.extrema import normalised_pieces, piece_extrema

__all__ = ["CoverProof", "cover_proof", "open_ranges", "merged", "joint_extrema", "outside_joints", "MAX_STATES",
           "FIRST_STEP", "LIMIT_TOL"]

#: Most states one compiled spline proof evaluates (about 5 µs each); the intervals left then go to
#: the exact proof.
MAX_STATES = 20_000
#: The compiled proof's first samples are at most this much travel apart [m] (the cap of its excess,
#: :data:`.fast.REACH`, is the most an end can contribute).
FIRST_STEP = 0.25
#: First intervals that share one set of group weights (:func:`_group_weights`).
BLOCK = 4
#: Parts of the travel bound taken together for the group weights (:func:`_group_weights`).
CHUNK = 16
_HUGE = 1e300
#: Most ranges the compiled proof hands to the exact one (more: the whole path goes to it).
MAX_OPEN = 4096
#: Tolerance [rad or m] of the joint limits on a path's exact extrema (that of :meth:`MotionChecker.within_limits`).
LIMIT_TOL = 1e-12


def _outside_limits(checker: Any, path: Any) -> np.ndarray:
    """The pieces of ``path`` whose exact joint extrema leave the checker's joint limits (bool per piece)."""
    if path.coefficients.shape[1] <= 4:  # compiled: the ends and the roots of the quadratic q'
        from pinarms.optim.motion._spline_kernel import outside_limits

        out = np.empty(path.coefficients.shape[0], dtype=np.bool_)
        outside_limits(np.ascontiguousarray(path.breaks, dtype=float),
                       np.ascontiguousarray(path.coefficients, dtype=float),
                       np.ascontiguousarray(checker.lower, dtype=float), np.ascontiguousarray(checker.upper, dtype=float),
                       out)
        return out
    return _outside_limits_arrays(checker, path)


def _outside_limits_arrays(checker: Any, path: Any) -> np.ndarray:
    """:func:`_outside_limits` from :func:`pinarms.planning.extrema.piece_extrema` (any degree)."""
    h = np.diff(np.asarray(path.breaks, dtype=float))
    values, _ = piece_extrema(normalised_pieces(path.coefficients, h), h, (0,))
    lo = np.nanmin(values[0], axis=-1)
    hi = np.nanmax(values[0], axis=-1)
    return np.any((lo < checker.lower) | (hi > checker.upper), axis=1)


def _merged(ranges: np.ndarray) -> np.ndarray:
    """``ranges (M, 2)`` sorted and the overlapping or touching ones joined."""
    if ranges.shape[0] == 0:
        return ranges.reshape(0, 2)
    r = ranges[np.argsort(ranges[:, 0], kind="stable")]
    out = [r[0].copy()]
    for a, b in r[1:]:
        if a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append(np.array([a, b]))
    return np.array(out)


def _group_weights(levers: np.ndarray, lam: np.ndarray, nodes: np.ndarray, V: np.ndarray,
                   s0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The block of each first interval ``[s0_i, s0_i+1]`` (:data:`BLOCK` of them a block) and each block's
    inverse group weights ``(B, G)``.

    On a part of the travel bound (joint speeds at most ``V_p``) ``T`` grows ``V_p · ℓ`` per unit of s
    (the arm's levers) and the distance of the pairs of group ``g`` changes at most ``V_p · λ_g``
    (:mod:`.link_levers`: the group's levers). Over :data:`CHUNK` consecutive parts, with ``V̂`` the
    largest joint speeds and ``D̂`` the smallest ``V_p · ℓ`` there, the group moves at most
    ``κ_g = (V̂ · λ_g) / D̂`` times as fast as ``T`` grows; a block takes the largest over the chunks
    it meets, at most 1 (``T`` bounds every pair's change too)."""
    M = V.shape[0]
    starts = np.arange(0, M, CHUNK)
    top = np.maximum.reduceat(V, starts, axis=0)  # (C, n)
    low = np.minimum.reduceat(V @ levers, starts)  # (C,)
    # an unbounded lever (inf) counts as a huge one: a joint that stays still then adds nothing (not nan)
    finite = np.where(np.isfinite(lam), lam, _HUGE)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ratio = np.minimum((top @ finite.T) / low[:, None], 1.0)  # (C, G)
    ratio[~(low > 0.0)] = 1.0  # a chunk with a part at rest: the whole-arm bound
    ratio[np.isnan(ratio)] = 1.0
    n0 = s0.size - 1
    block = np.arange(n0) // BLOCK
    edges = s0[np.append(np.arange(0, n0, BLOCK), n0)]
    part_first = np.clip(np.searchsorted(nodes, edges[:-1], side="right") - 1, 0, M - 1)
    part_last = np.clip(np.searchsorted(nodes, edges[1:], side="left") - 1, part_first, M - 1)
    first, last = part_first // CHUNK, part_last // CHUNK + 1
    kappa = np.array([ratio[a:b].max(axis=0) for a, b in zip(first.tolist(), last.tolist())])
    return block, 1.0 / np.maximum(kappa, 1e-12)


class CoverProof:
    """The compiled cover proof of one path, run in steps (:meth:`advance`): the ranges it leaves open
    are handed out as they are found, so that the exact proof can refuse a path at its first one.

    ``limits``: the ranges of the pieces whose exact joint extrema leave the joint limits (left to
    the exact proof from the start)."""

    def __init__(self, fc: Any, checker: Any, path: Any, nodes: np.ndarray, T: np.ndarray, V: np.ndarray) -> None:
        from pinarms.optim.motion import _spline_kernel as kernel

        self._kernel = kernel
        # own writable copies: numba types a read-only array apart (a path's frozen arrays would compile the
        # kernels once more)
        breaks = np.array(path.breaks, dtype=float)
        n0 = max(1, int(np.ceil(T[-1] / FIRST_STEP)))
        s0 = np.interp(T[-1] * np.arange(n0 + 1) / n0, T, nodes)
        s0[0], s0[-1] = breaks[0], breaks[-1]
        s0 = np.maximum.accumulate(s0)
        block, inv = _group_weights(fc.levers, fc.lam, nodes, V, s0)
        self._args = (breaks, np.array(path.coefficients, dtype=float),
                      np.array(nodes, dtype=float), np.array(T, dtype=float), s0, block, inv,
                      np.array(checker.lower, dtype=float), np.array(checker.upper, dtype=float),
                      float(checker.step / 2.0 ** MAX_SPLITS), MAX_STATES, fc.hold, fc.cols, fc.fk, fc.cov, fc.grp,
                      fc.cap, fc.work)
        self._opened = np.empty((MAX_OPEN, 2))
        self._queue = np.empty((kernel.QUEUE, 5))
        self._st = np.zeros(6, dtype=np.int64)
        self._given = 0
        outside = np.flatnonzero(_outside_limits(checker, path))
        self.limits = np.column_stack([breaks[outside], breaks[outside + 1]])

    @property
    def done(self) -> bool:
        """Every interval decided (proven or handed out)."""
        return bool(self._st[self._kernel.STARTED] == 1 and self._st[self._kernel.SIZE] == 0)

    @property
    def states(self) -> int:
        """The states evaluated so far."""
        return int(self._st[self._kernel.STATES])

    def advance(self, stop: int = MAX_OPEN) -> np.ndarray | None:
        """Go on until ``stop`` ranges in all are open or the proof is done; the ranges found since the last
        call ``(k, 2)``, or ``None`` when they did not fit (nothing is proven by this proof then)."""
        count = self._kernel.spline_open(*self._args, self._opened, self._queue, self._st, int(stop))
        if count < 0:
            return None
        new = self._opened[self._given:count].copy()
        self._given = count
        return new


def cover_proof(checker: Any, path: Any, nodes: np.ndarray, T: np.ndarray, V: np.ndarray) -> CoverProof | None:
    """The :class:`CoverProof` of ``path``, or ``None`` when the checker has no compiled check (no cover,
    moving arms) or the path is not one of its planned joints. ``nodes``, ``T``, ``V``: the path's
    cumulative travel bound and the joint speed bounds of its parts (:func:`.smoothing._travel_parts`)."""
    from pinarms.optim.motion.fast import fast_check

    fc = fast_check(checker)
    if fc is None or path.coefficients.shape[2] != checker.n:
        return None
    return CoverProof(fc, checker, path, nodes, T, V)


def merged(ranges: Any) -> np.ndarray:
    """``ranges`` (a list of (k, 2) arrays) sorted and the overlapping or touching ones joined: (M, 2)."""
    parts = [np.asarray(r, dtype=float).reshape(-1, 2) for r in ranges]
    return _merged(np.concatenate(parts) if parts else np.empty((0, 2)))


def open_ranges(checker: Any, path: Any, nodes: np.ndarray, T: np.ndarray, V: np.ndarray) -> np.ndarray | None:
    """The ranges ``[s_a, s_b]`` (M, 2) of ``path`` the compiled cover proof leaves to the exact proof, the
    joint limits' included (sorted, disjoint; empty: the whole path is proven), or ``None`` when there is
    no compiled check or the ranges did not fit: then the exact proof takes the whole path."""
    proof = cover_proof(checker, path, nodes, T, V)
    got = None if proof is None else proof.advance()
    return None if got is None else merged([got, proof.limits])


def joint_extrema(breaks: np.ndarray, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact smallest and largest value of every joint on every piece of a path of degree ≤ 3: ``(K, n)`` each
    (the piece's ends and the real roots of the quadratic ``q'`` inside it)."""
    h = np.diff(breaks)[:, None]
    W = C.shape[1]
    c = [C[:, d] if d < W else np.zeros_like(C[:, 0]) for d in range(4)]

    def at(t: np.ndarray) -> np.ndarray:
        return c[0] + t * (c[1] + t * (c[2] + t * c[3]))

    end = at(np.broadcast_to(h, c[0].shape))
    lo, hi = np.minimum(c[0], end), np.maximum(c[0], end)
    a, b = 3.0 * c[3], 2.0 * c[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.sqrt(np.maximum(b * b - 4.0 * a * c[1], 0.0))
        real = b * b - 4.0 * a * c[1] >= 0.0
        roots = [np.where(a != 0.0, (-b - r) / (2.0 * a), np.where(b != 0.0, -c[1] / b, np.nan)),
                 np.where(a != 0.0, (-b + r) / (2.0 * a), np.nan)]
    for t in roots:
        inside = real & (t > 0.0) & (t < h)
        v = at(np.where(inside, t, 0.0))
        lo, hi = np.where(inside, np.minimum(lo, v), lo), np.where(inside, np.maximum(hi, v), hi)
    return lo, hi


def outside_joints(path: Any, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """``(K, n)``: whether piece k of ``path`` leaves joint j's limits (exact extrema, :data:`LIMIT_TOL`)."""
    lo, hi = joint_extrema(np.asarray(path.breaks, dtype=float), path.coefficients)
    return (lo < lower - LIMIT_TOL) | (hi > upper + LIMIT_TOL)
