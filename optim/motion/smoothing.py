"""From a shortcut polyline to a smooth joint path, proven clear again after smoothing.

The planner's path is a polyline in joint space: timed as it is, the arm would stop at
every corner. :func:`smooth_path` replaces it by the C² cubic spline through its vertices
(:func:`planning.joint_spline`, parameter = joint-space chord length), which the time
scaling passes without stopping. A spline is not the polyline that was proven: it is
**proven again** (:func:`prove_path`) with the same continuous rule as the edges, its travel
bound taken from the exact peaks of ``|q'(s)|`` on every piece. Where the proof fails the
polyline edges around the failing piece get vertices at their quarter points, which pulls
the spline towards the proven polyline, and the spline is proven again
(:data:`REFINE_ROUNDS` rounds at most). If that does not succeed, the polyline itself is
the path, with stops at its corners: slower, but proven by the search.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms.planning import JointPath, joint_spline
from pinarms.planning.extrema import normalised_pieces, piece_extrema

__all__ = ["REFINE_ROUNDS", "prove_path", "polyline_path", "smooth_path", "path_speed_bounds"]

#: Rounds of vertex insertion before falling back to the polyline with stops.
REFINE_ROUNDS = 4


def path_speed_bounds(path: JointPath) -> np.ndarray:
    """Exact ``max |dq_j/ds|`` on every piece of ``path``: ``(pieces, n_joints)``."""
    h = np.diff(path.breaks)
    values, _ = piece_extrema(normalised_pieces(path.coefficients, h), h, (1,))
    return np.nanmax(np.abs(values[0]), axis=-1)


def prove_path(checker: Any, path: JointPath, extra: np.ndarray | None = None) -> Any:
    """Prove that every configuration of ``path`` keeps the checker's margins (module docstring).

    ``extra``: per-path-joint lever additions (unused for a planned arm's own path).
    """
    D = path_speed_bounds(path)
    levers = checker.levers
    breaks = path.breaks
    s_parts, budgets, piece_of = [np.array([0.0])], [], []
    for k in range(breaks.size - 1):
        a, b = breaks[k], breaks[k + 1]
        travel = float(D[k] @ levers) * (b - a)
        n = max(1, int(np.ceil(travel / checker.step * (1.0 + 1e-12))))
        s_parts.append(a + (b - a) * np.arange(1, n + 1) / n)
        budgets.extend([travel / n] * n)
        piece_of.extend([k] * n)
    s = np.concatenate(s_parts)
    s[-1] = breaks[-1]
    X = path(s)
    budgets = np.asarray(budgets)

    def midpoint(i: int, fa: float, fb: float, B: float):
        sm = s[i] + 0.5 * (fa + fb) * (s[i + 1] - s[i])
        return path(np.array([sm]))[0], 0.5 * B, 0.5 * B

    verdict = checker.prove(X, budgets, midpoint)
    if verdict.ok:
        return verdict, None
    i = max(0, min(int(verdict.first_bad), len(piece_of) - 1))
    return verdict, int(piece_of[i])


def polyline_path(waypoints: np.ndarray, robot: Any = None) -> JointPath:
    """The polyline through ``waypoints (K, n)`` as a :class:`JointPath` (s = chord length) with stops at its corners."""
    W = np.asarray(waypoints, dtype=float)
    step = np.linalg.norm(np.diff(W, axis=0), axis=1)
    keep = np.concatenate([[True], step > 1e-12])
    W = W[keep]
    step = np.linalg.norm(np.diff(W, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(step)])
    coefs = np.stack([W[:-1], np.diff(W, axis=0) / step[:, None]], axis=1)
    return JointPath(s, coefs, stops=s[1:-1], robot=robot)


def smooth_path(checker: Any, waypoints: np.ndarray, robot: Any = None) -> tuple[JointPath, str, int]:
    """A proven joint path through the polyline ``waypoints``: ``(path, method, rounds)``.

    ``method`` is ``"straight line"`` (two waypoints), ``"cubic spline"`` (proven, after
    ``rounds`` vertex insertions) or ``"polyline with stops"`` (the fallback).
    """
    W = np.asarray(waypoints, dtype=float)
    step = np.linalg.norm(np.diff(W, axis=0), axis=1)
    W = W[np.concatenate([[True], step > 1e-12])]
    if W.shape[0] <= 2:
        return polyline_path(W, robot), "straight line", 0
    for rounds in range(REFINE_ROUNDS + 1):
        path = joint_spline(W, robot=robot)
        verdict, piece = prove_path(checker, path)
        if verdict.ok:
            return path, "cubic spline", rounds
        # pull the spline towards the proven polyline around the failing piece
        lo, hi = max(0, piece - 1), min(W.shape[0] - 2, piece + 1)
        rows = [W[: lo + 1]]
        for k in range(lo, hi + 1):
            a, b = W[k], W[k + 1]
            rows.append(np.stack([a + 0.25 * (b - a), a + 0.75 * (b - a), b]))
        rows.append(W[hi + 2:])
        W = np.concatenate(rows)
    return polyline_path(waypoints, robot), "polyline with stops", REFINE_ROUNDS
