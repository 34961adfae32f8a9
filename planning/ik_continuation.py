"""IK followed along a tool path on one branch: Newton on the pose, path derivatives, continuation.

:class:`PathSolver` holds one robot and one :class:`pinarms.planning.ToolPath` and solves, batched,
the pose error by chord Newton and the path derivatives ``q' = J⁺ X'`` and
``q'' = J⁺ (X'' − J̇ q')`` (weighted Jacobian). :func:`continue_to` walks from a knot to a
later arc length by predictor (Taylor step) and corrector (Newton), halving the step where
it is refused, so that the solution never jumps to another IK branch; where it cannot go on
it raises :class:`Stop` with the arc length and the reason (:mod:`pinarms.planning.cartesian_path`
turns that into a named error). Units: m, rad; s in m of the tool path's arc length.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pinarms.robots import so3 as _so3
from pinarms.planning.joint_path import jacobian_rate
from pinarms.planning.tool_path import ToolPath

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot

__all__ = ["PathSolver", "Knot", "Stop", "solve_knots", "continue_to", "MAX_CORRECTION", "MAX_JOINT_STEP"]

#: Newton's method stops when the position error [m] and the weighted rotation error [m] are below this.
NEWTON_TOL = 1e-11
NEWTON_ITERATIONS = 8
#: A continuation step is refused when Newton corrects the prediction by more than this [rad or m] ...
MAX_CORRECTION = 0.05
#: ... or when a joint moves more than this in one step [rad or m].
MAX_JOINT_STEP = 0.3


class PathSolver:
    """IK along one tool path for one robot: Newton, derivatives, conditioning (batched)."""

    def __init__(self, robot: Robot, tool: ToolPath, frame: str, singular_tolerance: float) -> None:
        self.robot, self.tool, self.frame = robot, tool, frame
        self.w = tool.weight
        self.scale = np.array([1.0, 1.0, 1.0, self.w, self.w, self.w])
        self.singular = singular_tolerance
        self.lower = np.asarray(robot.lower, dtype=float)
        self.upper = np.asarray(robot.upper, dtype=float)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        return np.asarray(self.robot.jacobian(q, frame=self.frame)) * self.scale[:, None]

    def errors(self, q: np.ndarray, T: np.ndarray) -> np.ndarray:
        """Weighted pose errors (N, 6) [m]: position, w × rotation vector of T R(q)ᵀ (base axes)."""
        F = np.asarray(self.robot.fk(q, frame=self.frame))
        e = np.empty((q.shape[0], 6))
        e[:, :3] = T[:, :3, 3] - F[:, :3, 3]
        e[:, 3:] = self.w * _so3.log(T[:, :3, :3] @ np.swapaxes(F[:, :3, :3], 1, 2))
        return e

    def newton(self, q0: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Solutions near q0 (N, nq) for targets T (N, 4, 4) and a converged flag (N,).

        Chord Newton: the Jacobian's pseudo-inverse is evaluated at the start and refreshed every
        4 iterations (the predictions start close, so each iteration costs one batched FK).
        """
        q = q0.copy()
        active = np.ones(q.shape[0], dtype=bool)
        ok = np.zeros(q.shape[0], dtype=bool)
        pinv = np.zeros((q.shape[0], q.shape[1], 6))
        for it in range(NEWTON_ITERATIONS):
            idx = np.flatnonzero(active)
            if idx.size == 0:
                break
            e = self.errors(q[idx], T[idx])
            done = np.abs(e).max(axis=1) <= NEWTON_TOL
            ok[idx[done]] = True
            active[idx[done]] = False
            idx, e = idx[~done], e[~done]
            if idx.size == 0:
                break
            if it % 4 == 0:
                pinv[idx] = np.linalg.pinv(self.jacobian(q[idx]), rcond=1e-12)
            q[idx] += (pinv[idx] @ e[:, :, None])[:, :, 0]
        if active.any():
            idx = np.flatnonzero(active)
            ok[idx] = np.abs(self.errors(q[idx], T[idx])).max(axis=1) <= NEWTON_TOL * 10.0
        return q, ok

    def derivatives(self, q: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q' (N, nq), q'' (N, nq) from the tool path's d1, d2 (N, 6), and σ_min (N,) of the weighted Jacobian."""
        J = self.jacobian(q)
        U, S, Vt = np.linalg.svd(J, full_matrices=False)
        inv = np.where(S > 1e-14 * S[:, :1], 1.0 / np.where(S > 0.0, S, 1.0), 0.0)
        pinv = np.einsum("nji,nj,nkj->nik", Vt, inv, U)
        x1 = d1 * self.scale
        x2 = d2 * self.scale
        dq = np.einsum("nij,nj->ni", pinv, x1)
        rate = jacobian_rate(self.robot, q, dq, self.frame) * self.scale
        ddq = np.einsum("nij,nj->ni", pinv, x2 - rate)
        return dq, ddq, S[:, -1]

    def outside(self, q: np.ndarray) -> np.ndarray:
        """Largest excess of each row beyond the joint limits (N,) [rad or m]."""
        return np.maximum(self.lower - q, q - self.upper).max(axis=1)


class Knot:
    """A knot of the joint path: arc length s, the IK solution q, q' and q'' on the right of s and on its
    left (they differ at a corner of the tool path), and σ_min of the weighted Jacobian."""

    __slots__ = ("s", "q", "dq", "ddq", "dq_l", "ddq_l", "sigma")

    def __init__(self, s: float, q: np.ndarray, right: tuple, left: tuple, sigma: float) -> None:
        self.s, self.q, self.sigma = s, q, sigma
        self.dq, self.ddq = right
        self.dq_l, self.ddq_l = left


def solve_knots(sv: PathSolver, s: np.ndarray, q: np.ndarray) -> list[Knot]:
    """Knots at s (N,) for configurations q (N, nq) already on the path (derivatives on both sides)."""
    tool = sv.tool
    T, r1, r2 = tool.evaluate(s, "right")
    _, l1, l2 = tool.evaluate(s, "left")
    dq_r, ddq_r, sig = sv.derivatives(q, r1, r2)
    differ = np.abs(l1 - r1).max(axis=1) + np.abs(l2 - r2).max(axis=1) > 0.0
    dq_l, ddq_l = dq_r.copy(), ddq_r.copy()
    if differ.any():
        dq_l[differ], ddq_l[differ], _ = sv.derivatives(q[differ], l1[differ], l2[differ])
    return [Knot(float(s[i]), q[i], (dq_r[i], ddq_r[i]), (dq_l[i], ddq_l[i]), float(sig[i])) for i in range(s.size)]


class Stop(Exception):
    """Internal: the continuation of one start cannot pass arc length ``s`` (diagnosed once, by
    :func:`pinarms.planning.cartesian_path.joint_image`, which names the error)."""

    def __init__(self, s: float, q_last: np.ndarray, kind: str, detail: str) -> None:
        super().__init__(detail)
        self.s, self.q_last, self.kind, self.detail = s, q_last, kind, detail


def continue_to(sv: PathSolver, start: Knot, s_end: float, locate: float) -> list[Knot]:
    """Knots from ``start`` to ``s_end`` by predictor–corrector continuation (adaptive step), start excluded."""
    out: list[Knot] = []
    cur = start
    h = s_end - cur.s
    while s_end - cur.s > 1e-15 * max(1.0, s_end):
        h = min(h, s_end - cur.s)
        s_new = cur.s + h if s_end - (cur.s + h) > 1e-12 * max(1.0, s_end) else s_end
        hh = s_new - cur.s
        pred = cur.q + cur.dq * hh + 0.5 * cur.ddq * hh * hh
        T = sv.tool.pose(s_new)[None]
        q, ok = sv.newton(pred[None], T)
        q = q[0]
        kind, detail = "", ""
        if not ok[0]:
            kind, detail = "newton", "Newton's method does not converge on the pose"
        elif np.abs(q - pred).max() > MAX_CORRECTION or np.abs(q - cur.q).max() > MAX_JOINT_STEP:
            kind, detail = "jump", "the IK solution jumps"
        elif sv.outside(q[None])[0] > 1e-9:
            j = int(np.argmax(np.maximum(sv.lower - q, q - sv.upper)))
            side = "upper" if q[j] > sv.upper[j] else "lower"
            kind = "limit"
            detail = (f"joint {sv.robot.joint_names[j]} would pass its {side} limit "
                      f"{(sv.upper if side == 'upper' else sv.lower)[j]:.6g}")
        if not kind:
            knot = solve_knots(sv, np.array([s_new]), q[None])[0]
            if knot.sigma < sv.singular:
                kind, detail = "singular", (f"smallest singular value of the weighted Jacobian {knot.sigma:.4g} m/rad "
                                            f"< singular_tolerance {sv.singular:g}")
            else:
                out.append(knot)
                cur = knot
                h = 2.0 * hh
                continue
        if hh <= locate:
            raise Stop(s_new, cur.q, kind, detail)
        h = 0.5 * hh
    return out
