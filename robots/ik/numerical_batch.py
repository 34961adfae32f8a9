"""The batched numerical IK solver (:meth:`pinarms.robots.ik.NumericalIK.solve_batch`) and its result.

Functions of a :class:`pinarms.robots.ik.numerical.NumericalIK` (``self``), attached to the class by
:mod:`pinarms.robots.ik.numerical`; this module imports nothing of it. Units: m, rad.
"""

from __future__ import annotations

import itertools
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from pinarms.robots._checks import check_restarts


__all__ = ["BatchIKResult", "solve_batch", "batch_errors", "seed_int32"]

_WORKERS = max(1, min(4, os.cpu_count() or 1))  # threads of a batched solve (the compiled solver releases the GIL)
_PARALLEL_MIN = 64  # targets per thread below which a batch runs in one thread
_CHUNK = 64  # targets per block of a threaded batch (blocks are taken in turn: the threads stay balanced)


def seed_int32(seed: int | np.random.Generator | None) -> int:
    """A 32-bit seed for the compiled solver's generator from ``seed`` (int, ``Generator`` or None)."""
    if isinstance(seed, np.random.Generator):
        return int(seed.integers(2**32))
    if seed is None:
        return int(np.random.default_rng().integers(2**32))
    return int(seed) & 0xFFFFFFFF


# ------------------------------------------------------------------ batched solver
@dataclass(frozen=True)
class BatchIKResult:
    """Outcome of :meth:`NumericalIK.solve_batch`.

    Attributes:
        q: ``(N, nq)`` configurations within the limits [rad or m]; a row meets its target
            only where ``success``.
        success: ``(N,)`` position and rotation errors within the tolerance, within the limits.
        position_error: ``(N,)`` [m]; rotation_error: ``(N,)`` [rad] (0 in position-only mode).
        iterations: Levenberg–Marquardt iterations over all targets.
    """

    q: np.ndarray
    success: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    iterations: int


def _log3(R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation vectors ``(n, 3)`` [rad] of rotation matrices ``(n, 3, 3)`` and their angles ``(n,)``.

    The angle is ``atan2(|w|, (tr R − 1)/2)`` with ``w = vee(R − Rᵀ)/2`` (accurate near 0, where
    an arccos loses half the digits); within 0.45 rad of π the axis comes from the symmetric part.
    """
    w = 0.5 * np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], axis=1)
    c = 0.5 * (R[:, 0, 0] + R[:, 1, 1] + R[:, 2, 2] - 1.0)
    s = np.sqrt(np.einsum("ij,ij->i", w, w))
    theta = np.arctan2(s, c)
    k = np.ones_like(theta)
    np.divide(theta, s, out=k, where=s > 1e-300)
    out = w * k[:, None]
    near = c < -0.9  # θ > 2.69 rad: |w| = sin θ is small, take the axis from (R + Rᵀ)/2 − c I = (1 − c) a aᵀ
    if near.any():
        Rn, cn, wn, tn = R[near], c[near], w[near], theta[near]
        B = 0.5 * (Rn + np.swapaxes(Rn, 1, 2)) - cn[:, None, None] * np.eye(3)
        i = np.argmax(np.diagonal(B, axis1=1, axis2=2), axis=1)
        col = B[np.arange(i.size), :, i]
        axis = col / np.sqrt(np.maximum(np.einsum("ij,ij->i", col, col), 1e-300))[:, None]
        sign = np.where(np.einsum("ij,ij->i", axis, wn) < 0.0, -1.0, 1.0)
        out[near] = axis * (sign * tn)[:, None]
    return out, theta


def batch_errors(self, q: np.ndarray, targets: np.ndarray, position_only: bool) -> tuple[np.ndarray, np.ndarray]:
    """Position [m] and rotation [rad] errors of ``q (N, nq)`` for ``targets (N, 4, 4)`` by a fresh batched FK."""
    T = self.robot.fk(q, self._frame)
    pe = np.linalg.norm(T[:, :3, 3] - targets[:, :3, 3], axis=1)
    if position_only:
        return pe, np.zeros(q.shape[0])
    _, theta = _log3(targets[:, :3, :3] @ np.swapaxes(T[:, :3, :3], 1, 2))
    return pe, theta


def solve_batch(
    self,
    targets: np.ndarray,
    q_seed: np.ndarray | None = None,
    *,
    position_only: bool = False,
    tol: float = 1e-10,
    max_restarts: int = 40,
    seed: int | np.random.Generator | None = 0,
) -> BatchIKResult:
    """Many targets at once: the compiled solver over the batch (in threads), then :meth:`solve` for any left.

    Each target gets the attempts of :meth:`solve` (free descent, projected descent when it
    meets the target outside the limits) from its start, then up to ``max_restarts`` more (the
    stored poses next nearest the target, then uniform starts within the limits nearest pose
    first), the whole loop compiled; target ``k``'s
    restarts are seeded by ``seed + k`` (for an integer ``seed``: row ``k`` is ``Robot.ik(targets[k],
    seed=seed + k)``, bit for bit; the thread blocks change nothing).

    Args:
        targets: checked poses ``(N, 4, 4)`` frame → base [m].
        q_seed: starts ``(nq,)`` or ``(N, nq)`` (default, and for rows holding NaN: the stored
            configuration whose pose is nearest each target, as :meth:`solve` without a seed).
        tol: success when the position error [m] and the rotation error [rad] are both ≤ tol.
        max_restarts, seed: restarts per target, and the seed of all random starts.

    Every success is confirmed by a fresh batched forward kinematics and an exact limit check.
    """
    targets = np.asarray(targets, dtype=float)
    N = targets.shape[0]
    nq = self.nq
    max_restarts = check_restarts(max_restarts)
    tol = float(tol)
    if q_seed is None:  # no seed (or a NaN row): the compiled solver starts from the table's nearest pose
        starts = np.full((N, nq), np.nan)
    else:
        starts = np.array(np.broadcast_to(np.asarray(q_seed, dtype=float), (N, nq)))
    kernel, C, L, P, table = self._compiled()
    Rts = np.ascontiguousarray(targets[:, :3, :3])
    pts = np.ascontiguousarray(targets[:, :3, 3])
    starts = np.ascontiguousarray(starts)
    q = np.empty((N, nq))
    success = np.zeros(N, dtype=bool)
    pe, re = np.empty(N), np.empty(N)
    base = seed_int32(seed)  # target k's restarts: seed + k, as solve(targets[k], seed=seed + k); any blocks
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(base)
    iterations = [0]

    def block(s: int, e: int) -> None:  # compiled and nogil: the blocks run in parallel
        iterations.append(kernel.solve_many(Rts[s:e], pts[s:e], starts[s:e], table, C, L, P, bool(position_only), tol,
                                            int(max_restarts), base + s, q[s:e], success[s:e], pe[s:e], re[s:e]))

    workers = min(_WORKERS, max(1, N // _PARALLEL_MIN))
    if workers == 1:
        block(0, N)
    else:  # blocks of _CHUNK targets taken in turn by each thread: a thread the machine holds back takes fewer
        chunks = itertools.count()
        n_chunks = -(-N // _CHUNK)

        def worker() -> None:
            for c in iter(chunks.__next__, None):  # itertools.count's next is atomic under the GIL
                if c >= n_chunks:
                    return
                block(c * _CHUNK, min(N, (c + 1) * _CHUNK))

        with ThreadPoolExecutor(workers) as pool:
            for f in [pool.submit(worker) for _ in range(workers)]:
                f.result()
    iterations = int(sum(iterations))
    # confirm by a fresh batched FK (independent of the compiled chain) and an exact limit check
    pos_err, rot_err = batch_errors(self, q, targets, position_only)
    inside = np.all((q >= self.lower) & (q <= self.upper), axis=1)
    success &= (pos_err <= tol) & (rot_err <= tol) & inside
    left = np.flatnonzero(~success)
    for k in left:  # the few the batch left: per-target solver with restarts
        res = self.solve_checked(targets[k], None, position_only=position_only, tol=tol, max_restarts=max_restarts,
                          seed=rng, limits=True)
        q[k] = res.q
        success[k] = res.success
    if left.size:
        pos_err[left], rot_err[left] = batch_errors(self, q[left], targets[left], position_only)
    return BatchIKResult(q, success, pos_err, rot_err, iterations)
