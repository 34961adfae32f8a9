"""Dexterity of the tool's position: manipulability and inverse condition of the position Jacobian.

For joint vectors ``q (N, nq)`` and a frame, :func:`positions_and_dexterity` gives the frame's
origin and, from the *linear* rows ``J_v`` of its Jacobian:

- ``w = sqrt(det(J_v J_vᵀ))`` (``sqrt(det(J_vᵀ J_v))`` for arms with fewer than three joints),
  Yoshikawa's manipulability of the position Jacobian,
- ``c = σ_min / σ_max`` of ``J_v`` (0 = singular, 1 = isotropic), unit-free.

It runs one pass over the joints per chunk of samples (the robot's compiled kinematic tree)
on all cores; :func:`position_dexterity` takes the Jacobians themselves. Used by the sampled
and streamed workspaces (:mod:`pinarms.robots.reach.workspace`, :mod:`pinarms.robots.reach.workspace_stream`)
and the layout check (:mod:`pinarms.robots.reach.layout`).
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any, Callable

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.robot import Robot

__all__ = ["position_dexterity", "positions_and_dexterity", "CHUNK"]

#: Samples evaluated per block (bounds the working memory).
CHUNK = 16384
_WORKERS = max(1, min(4, os.cpu_count() or 1))


def position_dexterity(Jv: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Manipulability and inverse condition of position Jacobians ``J_v (N, 3, nq)``.

    Returns ``(w, c)``: ``w = sqrt(det(J_v J_vᵀ))`` (``sqrt(det(J_vᵀ J_v))`` when
    ``nq < 3``) and ``c = σ_min / σ_max`` of ``J_v``, each ``(N,)``.
    """
    Jv = np.asarray(Jv, dtype=float)
    if Jv.ndim != 3 or Jv.shape[1] != 3:
        raise InvalidInput(f"position Jacobians must have shape (N, 3, nq), got {Jv.shape}")
    nq = Jv.shape[2]
    if nq < 3:
        s = np.linalg.svd(Jv, compute_uv=False)
        w = np.prod(s, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            c = np.where(s[:, 0] > 0, s[:, -1] / s[:, 0], 0.0)
        return w, c
    cols = [[Jv[:, a, k] for a in range(3)] for k in range(nq)]
    return _dexterity_from_columns(cols, Jv.shape[0])


def _dexterity_from_columns(cols: list, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``(w, σ_min/σ_max)`` from the columns of ``J_v`` (list over joints of 3 ``(n,)`` arrays).

    ``G = J_v J_vᵀ`` (3×3 symmetric) is built entry by entry; its eigenvalues come from the
    closed form for symmetric 3×3 matrices (trigonometric solution of the characteristic
    cubic), the smallest one as ``det G / (λ1 λ2)`` for accuracy near singularities.
    """
    g = {}
    for a, b in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)):
        acc = np.zeros(n)
        for col in cols:
            acc += col[a] * col[b]
        g[a, b] = acc
    g00, g11, g22, g01, g02, g12 = g[0, 0], g[1, 1], g[2, 2], g[0, 1], g[0, 2], g[1, 2]
    det = g00 * (g11 * g22 - g12 * g12) - g01 * (g01 * g22 - g12 * g02) + g02 * (g01 * g12 - g11 * g02)
    det = np.maximum(det, 0.0)
    w = np.sqrt(det)
    qm = (g00 + g11 + g22) / 3.0
    off = g01 * g01 + g02 * g02 + g12 * g12
    p = np.sqrt(((g00 - qm) ** 2 + (g11 - qm) ** 2 + (g22 - qm) ** 2 + 2.0 * off) / 6.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        inv_p = np.where(p > 0, 1.0 / p, 0.0)
        b00, b11, b22 = (g00 - qm) * inv_p, (g11 - qm) * inv_p, (g22 - qm) * inv_p
        b01, b02, b12 = g01 * inv_p, g02 * inv_p, g12 * inv_p
        r = 0.5 * (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) + b02 * (b01 * b12 - b11 * b02))
        phi = np.arccos(np.clip(r, -1.0, 1.0)) / 3.0
        l1 = qm + 2.0 * p * np.cos(phi)
        l3 = qm + 2.0 * p * np.cos(phi + 2.0 * np.pi / 3.0)
        l2 = 3.0 * qm - l1 - l3
        lmin = np.where(l1 * l2 > 0, det / (l1 * l2), 0.0)
        c = np.where(l1 > 0, np.sqrt(np.clip(lmin / l1, 0.0, 1.0)), 0.0)
    return w, c


def positions_and_dexterity(
    robot: "Robot", q: np.ndarray, frame: str, chunk: int = CHUNK, progress: Callable[[int, int], None] | None = None, threads: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frame positions ``(N, 3)``, manipulability and inverse condition ``(N,)`` for ``q (N, nq)``.

    Uses the robot's compiled kinematic tree for one pass over the joints per chunk
    (positions and the linear Jacobian columns together), on all cores. ``progress(done, N)``
    is called after each chunk (from the worker threads, one call at a time).
    """
    fid = robot.frame_id(frame)
    N = q.shape[0]
    points = np.empty((N, 3))
    w = np.empty(N)
    c = np.empty(N)
    tree = getattr(robot, "kinematic_tree", None)
    fast = tree is not None and robot.nq >= 3 and hasattr(tree, "origin_and_columns")

    def block(start: int) -> None:
        qc = q[start : start + chunk]
        n = qc.shape[0]
        if fast:
            p, cols = _tree_position_and_columns(tree, qc, fid, robot.nq)
            wc, cc = _dexterity_from_columns(cols, n)
        else:
            p = robot.position(qc, frame)
            p = [p[:, 0], p[:, 1], p[:, 2]]
            wc, cc = position_dexterity(robot.jacobian(qc, frame)[:, :3, :])
        for a in range(3):
            points[start : start + n, a] = p[a]
        w[start : start + n] = wc
        c[start : start + n] = cc
        if progress is not None:
            with lock:
                done[0] += n
                progress(done[0], N)

    lock, done = threading.Lock(), [0]
    starts = range(0, N, chunk)
    threads = _WORKERS if threads is None else max(1, int(threads))
    if len(starts) < 2 or threads == 1:
        for s in starts:
            block(s)
    else:
        with ThreadPoolExecutor(max_workers=threads) as pool:
            list(pool.map(block, starts))
    return points, w, c


def _tree_position_and_columns(tree: Any, qc: np.ndarray, frame_id: int, nq: int) -> tuple[list, list]:
    """Frame origin (3 arrays) and linear Jacobian columns (nq × 3 arrays) of one chunk."""
    p, cols = tree.origin_and_columns(qc, frame_id)
    n = qc.shape[0]
    full = lambda v: np.broadcast_to(v, (n,)) if np.ndim(v) == 0 else v  # noqa: E731
    return [full(v) for v in p], [[full(v) for v in col[:3]] for col in cols]
