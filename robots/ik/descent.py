"""The interpreted Levenberg–Marquardt descent of the numerical IK solver, step by step through Pinocchio.

Error of a configuration ``q`` for a target pose ``T_target`` (frame → base)::

    D(q) = T(q)⁻¹ · T_target,    e(q) = log6(D(q))    (6,) twist in the frame's own axes [m, rad]

Moving the joints by ``Δq`` moves the frame by ``J_local Δq`` (a twist in its own axes, on
the left of ``D``), and ``log6(exp(−ξ) D) ≈ log6(D) − Jlog6(D⁻¹) ξ``: the Gauss–Newton system is
``A Δq = e`` with ``A = Jlog6(D⁻¹) · J_local``, damped (Levenberg–Marquardt)::

    Δq = Aᵀ (A Aᵀ + λ I)⁻¹ e           (nq ≥ 6; (AᵀA + λI)⁻¹ Aᵀ e when nq < 6)
    λ  = μ ‖e‖² + λ_min                 (Sugihara's damping, μ adapted by Nielsen's rule)

``position_only`` uses ``p_target − p(q)`` and the 3 linear rows of the world-aligned frame
Jacobian. Per trial step one ``computeJointJacobians`` (forward kinematics and every joint
Jacobian at once), ``updateFramePlacement`` and ``log6``; the frame Jacobian of an accepted step
is then read with ``getFrameJacobian`` without recomputing anything; the damped system is solved
by LAPACK's Cholesky (``posv``). The compiled solver (:mod:`._kernel`) runs the same rules; this
descent serves failure diagnosis, the closed-form refinement and :meth:`LMDescent.attempt`.

:class:`LMDescent` is a base class of :class:`.numerical.NumericalIK` (which sets ``model``,
``frame_id``, the settings and, from :class:`.limit_rules.JointLimitRules`, the limit rules).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

__all__ = ["LMDescent", "FREE", "WINDOW", "CLIP"]

_TWO_PI = 2.0 * np.pi
_MU_MAX = 1e8  # an attempt gives up when no step with μ below this lowers the error
FREE, WINDOW, CLIP = 0, 1, 2  # free descent; free then wrapped to the ranges' windows; projected descent


#: LAPACK's ``posv`` (scipy), imported at the first step: scipy.linalg takes about a second to import, which every
#: command line call paid (robots.Robot imports this module).
_POSV: list = []


def _posv(a: np.ndarray, b: np.ndarray, overwrite_a: int = 0):
    if not _POSV:
        from scipy.linalg.lapack import dposv

        _POSV.append(dposv)
    return _POSV[0](a, b, overwrite_a=overwrite_a)


def _nielsen(mu: float, E: float, E_t: float, e: np.ndarray, A: np.ndarray, dq: np.ndarray) -> float:
    """Nielsen's update of ``μ`` from the gain ratio ρ (actual over predicted decrease of ‖e‖²)."""
    r = e - A.dot(dq)
    predicted = E - r.dot(r)
    rho = (E - E_t) / predicted if predicted > 0.0 else 1.0
    return max(mu * max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3), 1e-12)


class LMDescent:
    """The interpreted descent (see the module docstring)."""

    @property
    def data(self) -> pin.Data:
        """This thread's Pinocchio data (each thread gets its own on first use)."""
        data = getattr(self._local, "data", None)
        if data is None:
            data = self._local.data = self.model.createData()
        return data

    def _pin_q(self, q: np.ndarray) -> np.ndarray:
        return q if self._identity_coords else self._coords.to_pin(q)

    def errors(self, q: np.ndarray, target: np.ndarray, position_only: bool) -> tuple[float, float]:
        """``(position error [m], rotation error [rad])`` of ``q`` for ``target`` (4,4)."""
        pin.forwardKinematics(self.model, self.data, self._pin_q(q))
        M = pin.updateFramePlacement(self.model, self.data, self.frame_id)
        dp = float(np.linalg.norm(M.translation - target[:3, 3]))
        if position_only:
            return dp, 0.0
        return dp, float(np.linalg.norm(pin.log3(M.rotation.T @ target[:3, :3])))

    def _target(self, target: np.ndarray, position_only: bool):
        target = np.asarray(target, dtype=float)
        target_in_base = np.array(target[:3, 3])
        target_to_base = None if position_only else pin.SE3(np.array(target[:3, :3]), target_in_base)
        return target_to_base, target_in_base

    def attempt(
        self, q0: np.ndarray, target: np.ndarray, position_only: bool, tol: float, limits: bool = True
    ) -> tuple[np.ndarray, float, float, int]:
        """One Levenberg–Marquardt descent from ``q0`` to ``target`` (4, 4): ``(q, pos_err, rot_err, iterations)``.

        With ``limits`` every iterate is projected into the joint limits; without, joints
        move freely (continuous joints wrapped), for diagnostics.
        """
        target_to_base, target_in_base = self._target(target, position_only)
        mode = CLIP if limits else FREE
        return self._descend(np.array(q0, dtype=float), target_to_base, target_in_base, position_only, float(tol), mode)

    def _attempt_within_limits(self, q0, target_to_base, target_in_base, position_only: bool, tol: float):
        """Free descent (angles wrapped to their range's window), then, if it met the target
        outside the limits, a projected descent from there: ``(q, pos_err, rot_err, its, ok)``.

        A returned ``q`` is always within the limits (projected if the descent ended outside).
        """
        q, pe, re, it = self._descend(q0, target_to_base, target_in_base, position_only, tol, WINDOW)
        met = pe <= tol and re <= tol
        if met and self.in_limits(q):
            return q, pe, re, it, True
        if not met:  # no pose reached from this start: report its projection, restart elsewhere
            self._clip(q)
            pe, re = self._errors_to(q, target_to_base, target_in_base, position_only)
            return q, pe, re, it, False
        self._clip(q)  # a solution outside the limits: slide back along the limits
        q, pe, re, it2 = self._descend(q, target_to_base, target_in_base, position_only, tol, CLIP)
        return q, pe, re, it + it2, pe <= tol and re <= tol

    def _errors_to(self, q, target_to_base, target_in_base, position_only: bool) -> tuple[float, float]:
        pin.forwardKinematics(self.model, self.data, self._pin_q(q))
        M = pin.updateFramePlacement(self.model, self.data, self.frame_id)
        d = M.translation - target_in_base
        pe = float(np.sqrt(d.dot(d)))
        if position_only:
            return pe, 0.0
        w = pin.log3(M.rotation.T.dot(target_to_base.rotation))
        return pe, float(np.sqrt(w.dot(w)))

    def _evaluator(self, target_to_base, target_in_base, position_only: bool):
        """``evaluate(q) → (e, D, ‖e‖²)``; it leaves the joint Jacobians of ``q`` in this thread's data."""
        model, data, fid = self.model, self.data, self.frame_id
        jacobians, placement, log6 = pin.computeJointJacobians, pin.updateFramePlacement, pin.log6
        pin_q = self._pin_q
        same_q = self._identity_coords

        def evaluate(x):
            jacobians(model, data, x if same_q else pin_q(x))
            M = placement(model, data, fid)
            if position_only:
                d = target_in_base - M.translation
                return d, None, float(d.dot(d))
            D = M.actInv(target_to_base)
            d = log6(D).vector
            return d, D, float(d.dot(d))

        return evaluate

    def _system(self, e, D, position_only: bool, wide: bool):
        """``(A, gram, rhs)`` of the Gauss–Newton system at the last accepted configuration."""
        ref = pin.LOCAL_WORLD_ALIGNED if position_only else pin.LOCAL
        J = pin.getFrameJacobian(self.model, self.data, self.frame_id, ref)  # data holds the joint Jacobians of q
        A = J[:3] if position_only else pin.Jlog6(D.inverse()).dot(J)
        gram = A.dot(A.T) if wide else A.T.dot(A)
        rhs = e if wide else A.T.dot(e)
        return A, gram, rhs

    def _damped(self, A, gram, rhs, e, lam: float, eye, wide: bool, q, at_limit: bool):
        """The damped step ``Δq`` of this ``λ``: the joints at a limit pushed outwards taken out, capped per joint."""
        _, x, info = _posv(gram + lam * eye, rhs, overwrite_a=1)
        if info != 0:  # not positive definite in floating point: least squares instead
            x = np.linalg.lstsq(gram + lam * np.eye(gram.shape[0]), rhs, rcond=None)[0]
        dq = A.T.dot(x) if wide else x
        if at_limit:  # joints at a limit pushed outwards: take them out and re-solve
            blocked = ((q <= self.lower) & (dq < 0.0)) | ((q >= self.upper) & (dq > 0.0))
            if blocked.any():
                A_free = A.copy()
                A_free[:, blocked] = 0.0
                dq = self._step(A_free, e, lam, wide)
                dq[blocked] = 0.0
        max_step = self.max_step
        if dq.dot(dq) > max_step * max_step:  # cheap test first: the 2-norm bounds every joint's step
            step = max(dq.max(), -dq.min())
            if step > max_step:
                dq *= max_step / step
        return dq

    def _finish(self, q, e, D, E: float, it: int, mode: int, position_only: bool):
        """``(q, position error, rotation error, iterations)`` of a descent's end, ``q`` wrapped by ``mode``."""
        if mode == WINDOW:
            self._wrap(q)
        elif self._any_unbounded:
            u = self.unbounded
            q[u] = np.pi - (np.pi - q[u]) % _TWO_PI
        if position_only:
            return q, float(np.sqrt(E)), 0.0, it
        t, w = D.translation, e[3:]
        return q, float(np.sqrt(t.dot(t))), float(np.sqrt(w.dot(w))), it

    def _descend(self, q, target_to_base, target_in_base, position_only: bool, tol: float, mode: int, patience: int = 1):
        """Levenberg–Marquardt from ``q`` (modified in place), projecting each iterate by ``mode``.

        ``patience`` multiplies ``max_iter`` and ``stall_steps`` (a final polish of a failed solve).
        """
        clip = mode == CLIP
        rows = 3 if position_only else 6  # task rows
        wide = self.nq >= rows  # solve the rows×rows system AAᵀ (else the nq×nq system AᵀA)
        eye = np.eye(rows if wide else self.nq)  # G + λI by one add (a strided in-place add costs 4x more)
        stall_steps, max_iter = self.stall_steps * patience, self.max_iter * patience
        tol2 = tol * tol
        evaluate = self._evaluator(target_to_base, target_in_base, position_only)
        at_limit = clip and (self._clip(q) or bool(((q <= self.lower) | (q >= self.upper)).any()))
        e, D, E = evaluate(q)
        mu, nu = self.damping, 2.0
        it = 0
        stall = 0
        done = _converged(e, D, E, tol2, position_only)
        while not done and it < max_iter:
            it += 1
            A, gram, rhs = self._system(e, D, position_only, wide)
            accepted = False
            while mu < _MU_MAX:
                dq = self._damped(A, gram, rhs, e, mu * E + self.min_damping, eye, wide, q, at_limit)
                q_try = q + dq
                clipped = clip and self._clip(q_try)
                e_t, D_t, E_t = evaluate(q_try)
                if E_t < E:  # accept; Nielsen's update of μ from the gain ratio ρ
                    mu, nu = _nielsen(mu, E, E_t, e, A, dq), 2.0
                    stall = stall + 1 if E_t > self.stall_ratio * E else 0
                    q, e, D, E, at_limit = q_try, e_t, D_t, E_t, clipped
                    accepted = True
                    break
                mu *= nu
                nu *= 2.0
            if not accepted:
                break
            done = _converged(e, D, E, tol2, position_only)
            if stall >= stall_steps:
                break
        return self._finish(q, e, D, E, it, mode, position_only)

    @staticmethod
    def _step(A: np.ndarray, e: np.ndarray, lam: float, wide: bool) -> np.ndarray:
        """Damped least-squares step (LAPACK ``posv`` on the symmetric positive definite system)."""
        if wide:
            G = A.dot(A.T)
            G.flat[:: G.shape[0] + 1] += lam
            _, x, info = _posv(G, e, overwrite_a=1)
            if info != 0:
                x = np.linalg.lstsq(A.dot(A.T) + lam * np.eye(A.shape[0]), e, rcond=None)[0]
            return A.T.dot(x)
        G = A.T.dot(A)
        G.flat[:: G.shape[0] + 1] += lam
        b = A.T.dot(e)
        _, dq, info = _posv(G, b, overwrite_a=1)
        if info != 0:
            dq = np.linalg.lstsq(A.T.dot(A) + lam * np.eye(A.shape[1]), b, rcond=None)[0]
        return dq



def _converged(d, D, E: float, tol2: float, position_only: bool) -> bool:
    """Position and rotation errors both within ``tol`` (``tol2 = tol²``)."""
    if E > 4.0 * tol2:  # ‖e‖² above this cannot meet tol (|e_lin| ≤ (1 + O(angle)) · position error)
        return False
    if position_only:
        return True  # E is the squared position error
    t, w = D.translation, d[3:]  # |D.translation| = ‖p − p_target‖, d[3:] = log3(Rᵀ R_target)
    return t.dot(t) <= tol2 and w.dot(w) <= tol2
