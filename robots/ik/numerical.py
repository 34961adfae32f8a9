"""Numerical IK for any URDF: damped least squares (Levenberg–Marquardt) on the SE(3) log error.

Error of a configuration ``q`` for a target pose ``T_target`` (frame → base)::

    e(q) = log6( T(q)⁻¹ · T_target )        (6,) twist in the frame's own axes [m, rad]

Newton's step solves ``Jlog6(D⁻¹) · J_local(q) · Δq = e`` with ``D = T(q)⁻¹ T_target``;
pinarms damps it, ``Δq = Aᵀ (A Aᵀ + λ I)⁻¹ e`` (or ``(AᵀA + λI)⁻¹ Aᵀ e`` when the arm has
fewer joints than task rows) with ``λ = λ₀ ‖e‖² + λ_min`` (large steps far away, Newton's
quadratic convergence near the solution), caps each joint's step, and *projects* the new
configuration into the joint limits (bounded joints clipped, continuous joints wrapped):
the iterate never leaves the limits. ``position_only`` uses the 3 linear rows of the
world-aligned Jacobian and the position error instead.

An attempt stops when the error is within ``tol`` (success), after ``max_iter`` steps, or
when the error has stagnated. The first attempt starts from ``q_seed``; the next ones from
configurations drawn uniformly within the limits by a seeded generator, taken in
order of their pose distance to the target (one batched FK over 32 draws).

The inner loop calls Pinocchio directly (``framesForwardKinematics`` and
``computeFrameJacobian``): one configuration at a time is what IK needs, and the batched
numpy path of :class:`robots.kinematic_tree.KinematicTree` would only add overhead.
Pinocchio's model is built with ``mimic=True``, so mimic joints (the koji arm's
parallelogram) are followed and the Jacobian is w.r.t. the independent joints.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.linalg.lapack import dposv as _posv

__all__ = ["NumericalIK", "IKResult"]

_POOL = 32  # random starts drawn at once and ranked by their distance to the target
_ROT_WEIGHT = 0.1  # [m/rad] weight of the rotation distance when ranking starts


@dataclass(frozen=True)
class IKResult:
    """Outcome of a numerical IK run.

    Attributes:
        q: best configuration found ``(nq,)`` [rad or m]; meets the target only if ``success``.
        success: position and rotation errors within the tolerance.
        position_error: ``‖p(q) − p_target‖`` [m].
        rotation_error: angle of ``R(q)ᵀ R_target`` [rad] (0 in position-only mode).
        attempts: starts tried (1 + restarts used).
        iterations: total iterations over all attempts.
    """

    q: np.ndarray
    success: bool
    position_error: float
    rotation_error: float
    attempts: int
    iterations: int


class NumericalIK:
    """Damped-least-squares IK of one robot frame, joint limits respected, seeded random restarts.

    Args:
        robot: a :class:`robots.Robot`.
        frame: target frame (default the tcp).
        max_iter: iterations per attempt.
        damping: ``λ₀`` of ``λ = λ₀‖e‖² + λ_min``.
        max_step: largest change of one joint per iteration [rad or m].
    """

    def __init__(
        self,
        robot,
        frame: str = "tcp",
        *,
        max_iter: int = 30,
        damping: float = 1e-3,
        min_damping: float = 1e-12,
        max_step: float = 0.5,
        stall_ratio: float = 0.9,
        stall_steps: int = 4,
    ) -> None:
        self.robot = robot
        self.model = robot.model
        self.data = robot.model.createData()
        self.frame_id = robot.frame_id(frame)
        self._frame = frame
        self.nq = robot.nq
        coords = robot._tree.coordinates
        self.unbounded = np.array(coords.is_unbounded, dtype=bool)
        self._identity_coords = (not self.unbounded.any()) and self.model.nq == self.nq
        self._coords = coords
        self.lower = np.where(self.unbounded, -np.pi, robot.lower)
        self.upper = np.where(self.unbounded, np.pi, robot.upper)
        self.max_iter = int(max_iter)
        self.damping = float(damping)
        self.min_damping = float(min_damping)
        self.max_step = float(max_step)
        self.stall_ratio = float(stall_ratio)
        self.stall_steps = int(stall_steps)

    # ------------------------------------------------------------------ pieces
    def _pin_q(self, q: np.ndarray) -> np.ndarray:
        return q if self._identity_coords else self._coords.to_pin(q)

    def errors(self, q: np.ndarray, target: np.ndarray, position_only: bool) -> tuple[float, float]:
        """``(position error [m], rotation error [rad])`` of ``q`` for ``target`` (4,4) or (3,)."""
        pin.framesForwardKinematics(self.model, self.data, self._pin_q(q))
        M = self.data.oMf[self.frame_id]
        if position_only:
            return float(np.linalg.norm(M.translation - target[:3, 3])), 0.0
        dp = float(np.linalg.norm(M.translation - target[:3, 3]))
        dR = M.rotation.T @ target[:3, :3]
        return dp, float(np.linalg.norm(pin.log3(dR)))

    def _project(self, q: np.ndarray, limits: bool) -> np.ndarray:
        if self.unbounded.any():
            u = self.unbounded
            q[u] = np.pi - (np.pi - q[u]) % (2.0 * np.pi)
        if limits:
            np.clip(q, self.lower, self.upper, out=q)
        return q

    def _residual(self, q: np.ndarray, T_des, p_des: np.ndarray, position_only: bool):
        """``(e, D, pos_err, rot_err)`` at ``q`` (FK evaluated into ``self.data``)."""
        qp = self._pin_q(q)
        pin.framesForwardKinematics(self.model, self.data, qp)
        M = self.data.oMf[self.frame_id]
        if position_only:
            e = p_des - M.translation
            return e, None, float(np.sqrt(e @ e)), 0.0
        D = M.actInv(T_des)
        e = pin.log6(D).vector
        dp = M.translation - p_des
        w = e[3:]
        return e, D, float(np.sqrt(dp @ dp)), float(np.sqrt(w @ w))

    def attempt(
        self, q0: np.ndarray, target: np.ndarray, position_only: bool, tol: float, limits: bool = True
    ) -> tuple[np.ndarray, float, float, int]:
        """One Levenberg–Marquardt descent from ``q0``: ``(q, pos_err, rot_err, iterations)``.

        A step is accepted only if it lowers ``‖e‖²``; otherwise the damping grows and the
        step is recomputed. Joints held at a limit by the projection and pushed beyond it
        are taken out of the step (their Jacobian columns removed) so the free joints move.
        """
        model, data, fid = self.model, self.data, self.frame_id
        q = self._project(np.array(q0, dtype=float), limits)
        T_des = None if position_only else pin.SE3(target[:3, :3], target[:3, 3])
        p_des = np.array(target[:3, 3])
        lower, upper = self.lower, self.upper
        e, D, pos_err, rot_err = self._residual(q, T_des, p_des, position_only)
        E = float(e @ e)
        mu = self.damping
        it = 0
        stall = 0
        while it < self.max_iter and not (pos_err <= tol and rot_err <= tol):
            it += 1
            qp = self._pin_q(q)
            if position_only:
                A = pin.computeFrameJacobian(model, data, qp, fid, pin.LOCAL_WORLD_ALIGNED)[:3]
            else:
                A = pin.Jlog6(D.inverse()) @ pin.computeFrameJacobian(model, data, qp, fid, pin.LOCAL)
            accepted = False
            while mu < 1e8:
                dq = self._step(A, e, mu * E + self.min_damping)
                if limits:  # joints at a limit pushed outwards: freeze them and re-solve
                    blocked = ((q <= lower) & (dq < 0.0)) | ((q >= upper) & (dq > 0.0))
                    if blocked.any():
                        A_free = A.copy()
                        A_free[:, blocked] = 0.0
                        dq = self._step(A_free, e, mu * E + self.min_damping)
                        dq[blocked] = 0.0
                q_try = self._project(q + dq, limits)
                e_t, D_t, pe_t, re_t = self._residual(q_try, T_des, p_des, position_only)
                E_t = float(e_t @ e_t)
                if E_t < E:
                    stall = stall + 1 if E_t > self.stall_ratio * E else 0
                    q, e, D, pos_err, rot_err, E = q_try, e_t, D_t, pe_t, re_t, E_t
                    mu = max(mu / 3.0, 1e-9)
                    accepted = True
                    break
                mu *= 5.0
            if not accepted or stall >= self.stall_steps:
                break
        if not position_only:  # exact rotation angle for the report
            pos_err, rot_err = self.errors(q, target, position_only)
        return q, pos_err, rot_err, it

    def _step(self, A: np.ndarray, e: np.ndarray, lam: float) -> np.ndarray:
        """Damped least-squares step, capped at :attr:`max_step` per joint (LAPACK ``posv`` on the SPD system)."""
        rows, cols = A.shape
        if rows <= cols:
            G = A @ A.T
            G.flat[:: rows + 1] += lam
            _, x, info = _posv(G, e)
            dq = A.T @ x if info == 0 else A.T @ np.linalg.lstsq(G, e, rcond=None)[0]
        else:
            G = A.T @ A
            G.flat[:: cols + 1] += lam
            _, dq, info = _posv(G, A.T @ e)
            if info != 0:
                dq = np.linalg.lstsq(G, A.T @ e, rcond=None)[0]
        step = float(np.abs(dq).max())
        if step > self.max_step:
            dq = dq * (self.max_step / step)
        return dq

    def _ranked_starts(self, rng: np.random.Generator, target: np.ndarray, position_only: bool) -> np.ndarray:
        """:data:`_POOL` uniform draws within the limits, closest to the target first (one batched FK)."""
        q = rng.uniform(self.lower, self.upper, size=(_POOL, self.nq))
        T = self.robot.fk(q, self._frame)
        cost = np.linalg.norm(T[:, :3, 3] - target[:3, 3], axis=1)
        if not position_only:
            cost = cost + _ROT_WEIGHT * np.linalg.norm((T[:, :3, :3] - target[:3, :3]).reshape(-1, 9), axis=1)
        return q[np.argsort(cost)]

    # ------------------------------------------------------------------ public
    def solve(
        self,
        target: np.ndarray,
        q_seed: np.ndarray | None = None,
        *,
        position_only: bool = False,
        tol: float = 1e-10,
        max_restarts: int = 40,
        seed: int | np.random.Generator | None = 0,
        limits: bool = True,
    ) -> IKResult:
        """Best of up to ``1 + max_restarts`` descents; stops at the first that meets ``tol``.

        Args:
            target: pose ``(4, 4)`` frame → base (only its translation is used when ``position_only``).
            q_seed: first start ``(nq,)`` (default: the middle of the joint ranges).
            tol: success when the position error [m] and the rotation error [rad] are both ≤ tol.
            seed: seed or ``numpy.random.Generator`` of the restarts.
            limits: keep the iterates within the joint limits (``False`` only for diagnostics).
        """
        rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        q0 = 0.5 * (self.lower + self.upper) if q_seed is None else np.asarray(q_seed, dtype=float)
        best = None
        iterations = 0
        pool = np.empty((0, self.nq))
        for attempt in range(int(max_restarts) + 1):
            if attempt > 0:
                if pool.shape[0] == 0:
                    pool = self._ranked_starts(rng, target, position_only)
                q0, pool = pool[0], pool[1:]
            q, pe, re, it = self.attempt(q0, target, position_only, tol, limits)
            iterations += it
            score = pe + re
            if best is None or score < best[1] + best[2]:
                best = (q, pe, re)
            if pe <= tol and re <= tol:
                return IKResult(q, True, pe, re, attempt + 1, iterations)
        q, pe, re = best
        return IKResult(q, False, pe, re, int(max_restarts) + 1, iterations)
