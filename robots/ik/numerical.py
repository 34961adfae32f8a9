"""Numerical IK for any URDF: Levenberg–Marquardt on the SE(3) log error, joint limits by projection.

Error of a configuration ``q`` for a target pose ``T_target`` (frame → base)::

    D(q) = T(q)⁻¹ · T_target,    e(q) = log6(D(q))    (6,) twist in the frame's own axes [m, rad]

Moving the joints by ``Δq`` moves the frame by ``J_local Δq`` (a twist in its own axes, on
the left of ``D``), and ``log6(exp(−ξ) D) ≈ log6(D) − Jlog6(D⁻¹) ξ`` (``Jlog6(D⁻¹)`` is the
inverse of the left Jacobian of ``SE(3)`` at ``log6(D)``): the Gauss–Newton system is
``A Δq = e`` with ``A = Jlog6(D⁻¹) · J_local``. pinarms damps it (Levenberg–Marquardt)::

    Δq = Aᵀ (A Aᵀ + λ I)⁻¹ e           (nq ≥ 6; (AᵀA + λI)⁻¹ Aᵀ e when nq < 6)
    λ  = μ ‖e‖² + λ_min                 (Sugihara's damping, μ adapted)

A step is kept only if it lowers ``‖e‖²``; ``μ`` then follows Nielsen's update from the
gain ratio ρ = (actual decrease of ‖e‖²) / (decrease predicted by the linear model):
``μ ← μ · max(1/3, 1 − (2ρ − 1)³)``; a rejected step multiplies ``μ`` by ν = 2, 4, 8, …
and is recomputed. Each joint's step is capped (``max_step``). Far from the target ``λ``
is large (short, gradient-like steps); near it ``λ → λ_min`` and the steps are Newton's
(quadratic convergence: 1e-10 is reached in one or two steps from 1e-5).

Joint limits. Clipping every iterate into the limits traps many descents at a limit
(the branch they head for lies beyond it), so an attempt runs in two phases:

1. a *free* descent (joints unconstrained). Its result is wrapped: each revolute angle
   to the ``2π`` window centred on its range (the pose is unchanged). If it meets the
   target and lies within the limits, that is the answer.
2. if it met the target *outside* the limits, a *projected* descent from its projection
   into the limits: every iterate is projected (continuous joints wrapped to ``(-π, π]``;
   a revolute joint whose range spans a full turn or more, e.g. the UR's ±2π, shifted by
   ∓2π when it leaves its range; other joints clipped), and joints held at a limit and
   pushed outwards are taken out of the step (their Jacobian columns zeroed) so the free
   joints move (an active set). Redundant arms often slide back into the limits this way.

A descent that did not meet the target ends the attempt (the next start is tried).
``attempt(limits=True)`` is the projected descent alone (used to refine closed-form
solutions); ``limits=False`` the free one, for diagnostics.

``position_only`` uses the position error ``p_target − p(q)`` and the 3 linear rows of the
world-aligned frame Jacobian instead.

A descent stops when the position error [m] and the rotation error [rad] are both within
``tol`` (success), after ``max_iter`` steps, when no step lowers the error, or when the
error has stagnated (``‖e‖²`` falls by less than ``1 − stall_ratio`` ``stall_steps``
times in a row). The first attempt starts from ``q_seed`` (default: of 256 configurations
drawn once within the limits, the one whose pose is nearest the target); the next ones from
configurations drawn uniformly within the limits by a seeded generator, taken in order
of their pose distance to the target. A success is confirmed on the returned ``q`` by a
fresh forward kinematics and a limit check.

Speed: one configuration at a time is what IK needs, so the loop calls Pinocchio
directly: per trial step one ``computeJointJacobians`` (forward kinematics and every
joint Jacobian at once), ``updateFramePlacement`` and ``log6``; the frame Jacobian of an
accepted step is then read with ``getFrameJacobian`` without recomputing anything. The
damped system is 6×6 (or nq×nq) and solved by LAPACK's Cholesky (``posv``). The exact
errors are computed only once ``‖e‖²`` is small enough for them to possibly meet ``tol``.
Pinocchio's model is built with ``mimic=True``, so mimic joints (the koji arm's
parallelogram) are followed and the Jacobian is w.r.t. the independent joints.

:meth:`NumericalIK.solve`, ``Robot.ik`` and :meth:`NumericalIK.solve_batch` run the same
attempts compiled (:mod:`._kernel`, the whole solve in one native call, ≈ 5× cheaper per
step); the interpreted descent above remains for failure diagnosis, the closed-form
refinement and :meth:`attempt`.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.linalg.lapack import dposv as _posv

from ..errors import InvalidInput
from ..kinematic_tree import _REVOLUTE
from .._checks import check_seed as _check_seed
from .._checks import check_tolerance as _check_tolerance
from .numerical_batch import _ROT_WEIGHT, BatchIKResult, _batch_errors, _seed_int, solve_batch

__all__ = ["NumericalIK", "IKResult", "BatchIKResult"]

_TABLE = 256  # configurations stored with their poses for the first start (table_start)
_POOL = 32  # random starts drawn at once and ranked by their distance to the target
_TWO_PI = 2.0 * np.pi
_MU_MAX = 1e8  # an attempt gives up when no step with μ below this lowers the error
_FREE, _WINDOW, _CLIP = 0, 1, 2  # free descent; free then wrapped to the ranges' windows; projected descent


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
    """Levenberg–Marquardt IK of one robot frame, joint limits respected, seeded random restarts.

    Args:
        robot: a :class:`robots.Robot`.
        frame: target frame (default the tcp).
        max_iter: iterations per attempt.
        damping: initial ``μ`` of ``λ = μ‖e‖² + λ_min``.
        min_damping: ``λ_min`` [1 / (m or rad)²].
        max_step: largest change of one joint per iteration [rad or m].
        stall_ratio, stall_steps: an attempt stops when ``‖e‖²`` falls by less than
            ``1 − stall_ratio`` for ``stall_steps`` accepted steps in a row.
    """

    def __init__(
        self,
        robot,
        frame: str = "tcp",
        *,
        max_iter: int = 30,
        damping: float = 1e-2,
        min_damping: float = 1e-12,
        max_step: float = 1.0,
        stall_ratio: float = 0.9,
        stall_steps: int = 4,
    ) -> None:
        self.robot = robot
        self.model = robot.model
        self._local = threading.local()  # per-thread Pinocchio data: one solver serves many threads
        self._table = None  # start table (see table_start), made on first use
        self._kernel_args = None  # the compiled solver's constant arrays (see _compiled), made on first use
        self.frame_id = robot.frame_id(frame)
        self._frame = frame
        self.nq = robot.nq
        tree = robot._tree
        coords = tree.coordinates
        self.unbounded = np.array(coords.is_unbounded, dtype=bool)
        self._any_unbounded = bool(self.unbounded.any())
        self._identity_coords = (not self._any_unbounded) and self.model.nq == self.nq
        self._coords = coords
        self.lower = np.where(self.unbounded, -np.pi, robot.lower)
        self.upper = np.where(self.unbounded, np.pi, robot.upper)
        revolute = np.zeros(self.nq, dtype=bool)
        for i in range(1, self.model.njoints):
            joint = self.model.joints[i]
            if "Mimic" not in joint.shortname() and tree.kind[i] == _REVOLUTE:
                revolute[joint.idx_v] = True
        #: bounded revolute joints whose range spans a full turn: leaving the range is undone by ∓2π
        self.full_turn = revolute & ~self.unbounded & (self.upper - self.lower >= _TWO_PI)
        self._any_full_turn = bool(self.full_turn.any())
        window = revolute & ~self.unbounded  # wrapped to the 2π window centred on their range
        self._any_revolute = bool(window.any())
        self._window_low = np.where(window, 0.5 * (self.lower + self.upper) - np.pi, 0.0)
        self._window_turns = np.where(window, 1.0 / _TWO_PI, 0.0)  # 0: the joint is never shifted
        self.max_iter = int(max_iter)
        self.damping = float(damping)
        self.min_damping = float(min_damping)
        self.max_step = float(max_step)
        self.stall_ratio = float(stall_ratio)
        self.stall_steps = int(stall_steps)

    @property
    def data(self) -> pin.Data:
        """This thread's Pinocchio data (each thread gets its own on first use)."""
        data = getattr(self._local, "data", None)
        if data is None:
            data = self._local.data = self.model.createData()
        return data

    # ------------------------------------------------------------------ pieces
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

    def in_limits(self, q: np.ndarray) -> bool:
        """``lower ≤ q ≤ upper`` exactly (no tolerance)."""
        return not ((q < self.lower).any() or (q > self.upper).any())

    def _wrap(self, q: np.ndarray) -> np.ndarray:
        """Revolute angles of ``q`` (in place) to the ``2π`` window centred on their range, continuous ones to ``(-π, π]``."""
        if self._any_unbounded:
            u = self.unbounded
            q[u] = np.pi - (np.pi - q[u]) % _TWO_PI
        if self._any_revolute:
            q -= _TWO_PI * np.floor((q - self._window_low) * self._window_turns)
        return q

    def _clip(self, q: np.ndarray) -> bool:
        """Project ``q`` into the limits in place; ``True`` if a joint was clipped to a limit.

        Continuous joints are wrapped to ``(-π, π]``; a revolute joint whose range spans a
        full turn is shifted by ∓2π when it leaves its range; the others are clipped.
        """
        if self._any_unbounded:
            u = self.unbounded
            q[u] = np.pi - (np.pi - q[u]) % _TWO_PI
        lo, hi = self.lower, self.upper
        if not ((q < lo).any() or (q > hi).any()):
            return False
        if self._any_full_turn:
            w = self.full_turn
            q[w & (q > hi)] -= _TWO_PI
            q[w & (q < lo)] += _TWO_PI
        np.minimum(np.maximum(q, lo, out=q), hi, out=q)
        return bool(((q <= lo) | (q >= hi)).any())

    def _target(self, target: np.ndarray, position_only: bool):
        target = np.asarray(target, dtype=float)
        p_des = np.array(target[:3, 3])
        T_des = None if position_only else pin.SE3(np.array(target[:3, :3]), p_des)
        return T_des, p_des

    def attempt(
        self, q0: np.ndarray, target: np.ndarray, position_only: bool, tol: float, limits: bool = True
    ) -> tuple[np.ndarray, float, float, int]:
        """One Levenberg–Marquardt descent from ``q0`` to ``target`` (4, 4): ``(q, pos_err, rot_err, iterations)``.

        With ``limits`` every iterate is projected into the joint limits; without, joints
        move freely (continuous joints wrapped), for diagnostics.
        """
        T_des, p_des = self._target(target, position_only)
        mode = _CLIP if limits else _FREE
        return self._descend(np.array(q0, dtype=float), T_des, p_des, position_only, float(tol), mode)

    def _attempt_within_limits(self, q0, T_des, p_des, position_only: bool, tol: float):
        """Free descent (angles wrapped to their range's window), then, if it met the target
        outside the limits, a projected descent from there: ``(q, pos_err, rot_err, its, ok)``.

        A returned ``q`` is always within the limits (projected if the descent ended outside).
        """
        q, pe, re, it = self._descend(q0, T_des, p_des, position_only, tol, _WINDOW)
        met = pe <= tol and re <= tol
        if met and self.in_limits(q):
            return q, pe, re, it, True
        if not met:  # no pose reached from this start: report its projection, restart elsewhere
            self._clip(q)
            pe, re = self._errors_to(q, T_des, p_des, position_only)
            return q, pe, re, it, False
        self._clip(q)  # a solution outside the limits: slide back along the limits
        q, pe, re, it2 = self._descend(q, T_des, p_des, position_only, tol, _CLIP)
        return q, pe, re, it + it2, pe <= tol and re <= tol

    def _errors_to(self, q, T_des, p_des, position_only: bool) -> tuple[float, float]:
        pin.forwardKinematics(self.model, self.data, self._pin_q(q))
        M = pin.updateFramePlacement(self.model, self.data, self.frame_id)
        d = M.translation - p_des
        pe = float(np.sqrt(d.dot(d)))
        if position_only:
            return pe, 0.0
        w = pin.log3(M.rotation.T.dot(T_des.rotation))
        return pe, float(np.sqrt(w.dot(w)))

    def _descend(self, q, T_des, p_des, position_only: bool, tol: float, mode: int, patience: int = 1):
        """Levenberg–Marquardt from ``q`` (modified in place), projecting each iterate by ``mode``.

        ``patience`` multiplies ``max_iter`` and ``stall_steps`` (a final polish of a failed solve).
        """
        model, data, fid = self.model, self.data, self.frame_id
        jacobians, placement, frame_jacobian = pin.computeJointJacobians, pin.updateFramePlacement, pin.getFrameJacobian
        log6, jlog6 = pin.log6, pin.Jlog6
        pin_q = self._pin_q
        lower, upper = self.lower, self.upper
        clip = mode == _CLIP
        rows = 3 if position_only else 6  # task rows
        wide = self.nq >= rows  # solve the rows×rows system AAᵀ (else the nq×nq system AᵀA)
        eye = np.eye(rows if wide else self.nq)  # G + λI by one add (a strided in-place add costs 4x more)
        min_damping, max_step = self.min_damping, self.max_step
        max_step2 = max_step * max_step
        stall_ratio, stall_steps = self.stall_ratio, self.stall_steps * patience
        max_iter = self.max_iter * patience
        ref = pin.LOCAL_WORLD_ALIGNED if position_only else pin.LOCAL
        tol2 = tol * tol
        gate = 4.0 * tol2  # ‖e‖² above this cannot meet tol (|e_lin| ≤ (1 + O(angle)) · position error)

        same_q = self._identity_coords

        def evaluate(x):
            jacobians(model, data, x if same_q else pin_q(x))
            M = placement(model, data, fid)
            if position_only:
                d = p_des - M.translation
                return d, None, float(d.dot(d))
            D = M.actInv(T_des)
            d = log6(D).vector
            return d, D, float(d.dot(d))

        def converged(d, D, E):
            if E > gate:
                return False
            if position_only:
                return True  # E is the squared position error
            t, w = D.translation, d[3:]  # |D.translation| = ‖p − p_target‖, d[3:] = log3(Rᵀ R_target)
            return t.dot(t) <= tol2 and w.dot(w) <= tol2

        at_limit = clip and (self._clip(q) or bool(((q <= lower) | (q >= upper)).any()))
        e, D, E = evaluate(q)
        mu, nu = self.damping, 2.0
        it = 0
        stall = 0
        done = converged(e, D, E)
        while not done and it < max_iter:
            it += 1
            J = frame_jacobian(model, data, fid, ref)  # data holds the joint Jacobians of q
            A = J[:3] if position_only else jlog6(D.inverse()).dot(J)
            gram = A.dot(A.T) if wide else A.T.dot(A)
            rhs = e if wide else A.T.dot(e)
            accepted = False
            while mu < _MU_MAX:
                lam = mu * E + min_damping
                _, x, info = _posv(gram + lam * eye, rhs, overwrite_a=1)
                if info != 0:  # not positive definite in floating point: least squares instead
                    x = np.linalg.lstsq(gram + lam * np.eye(gram.shape[0]), rhs, rcond=None)[0]
                dq = A.T.dot(x) if wide else x
                if at_limit:  # joints at a limit pushed outwards: take them out and re-solve
                    blocked = ((q <= lower) & (dq < 0.0)) | ((q >= upper) & (dq > 0.0))
                    if blocked.any():
                        A_free = A.copy()
                        A_free[:, blocked] = 0.0
                        dq = self._step(A_free, e, lam, wide)
                        dq[blocked] = 0.0
                if dq.dot(dq) > max_step2:  # cheap test first: the 2-norm bounds every joint's step
                    step = max(dq.max(), -dq.min())
                    if step > max_step:
                        dq *= max_step / step
                q_try = q + dq
                clipped = clip and self._clip(q_try)
                e_t, D_t, E_t = evaluate(q_try)
                if E_t < E:  # accept; Nielsen's update of μ from the gain ratio ρ
                    r = e - A.dot(dq)
                    predicted = E - r.dot(r)
                    rho = (E - E_t) / predicted if predicted > 0.0 else 1.0
                    mu = max(mu * max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3), 1e-12)
                    nu = 2.0
                    stall = stall + 1 if E_t > stall_ratio * E else 0
                    q, e, D, E, at_limit = q_try, e_t, D_t, E_t, clipped
                    accepted = True
                    break
                mu *= nu
                nu *= 2.0
            if not accepted:
                break
            done = converged(e, D, E)
            if stall >= stall_steps:
                break
        if mode == _WINDOW:
            self._wrap(q)
        elif self._any_unbounded:
            u = self.unbounded
            q[u] = np.pi - (np.pi - q[u]) % _TWO_PI
        if position_only:
            return q, float(np.sqrt(E)), 0.0, it
        t, w = D.translation, e[3:]
        return q, float(np.sqrt(t.dot(t))), float(np.sqrt(w.dot(w))), it

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

    def nearest_equivalent(self, q: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
        """``q`` ``(nq,)`` or ``(N, nq)`` with each bounded revolute angle at its 2π equivalent within the
        limits nearest ``q_ref`` (same shape, or ``(nq,)``): the same pose."""
        if not self._any_revolute:
            return q
        turns = self._window_turns > 0.0
        k = _TWO_PI * np.arange(-2.0, 3.0).reshape((5,) + (1,) * q.ndim)
        options = q + _TWO_PI * np.round((q_ref - q) / _TWO_PI) + k  # (5, ..., nq)
        inside = (options >= self.lower) & (options <= self.upper)
        cost = np.where(inside, np.abs(options - q_ref), np.inf)
        best = np.argmin(cost, axis=0)[None]
        pick = np.take_along_axis(options, best, 0)[0]
        ok = turns & np.isfinite(np.take_along_axis(cost, best, 0)[0])
        return np.where(ok, pick, q)

    def _start_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:data:`_TABLE` configurations drawn within the limits (seed 0) with their frame poses, made once."""
        table = self._table
        if table is None:
            q = np.random.default_rng(0).uniform(self.lower, self.upper, size=(_TABLE, self.nq))
            T = self.robot.fk(q, self._frame)
            p = np.ascontiguousarray(T[:, :3, 3])
            R = np.ascontiguousarray(T[:, :3, :3].reshape(-1, 9))
            table = self._table = (q, p, np.einsum("ij,ij->i", p, p), R)  # one assignment: safe across threads
        return table

    def table_start(self, target: np.ndarray, position_only: bool = False) -> np.ndarray:
        """The stored configuration whose frame pose is nearest ``target (4, 4)``: a copy ``(nq,)``.

        Distance ``‖p − p_target‖ + 0.1 m/rad · ‖R − R_target‖_F`` (position only: the first
        term) over :data:`_TABLE` configurations drawn once within the limits; starting there
        saves 2-4 iterations over the middle of the ranges.
        """
        q, p, pp, R = self._start_table()
        pt = target[:3, 3]
        d2 = pp - 2.0 * p.dot(pt) + pt.dot(pt)
        cost = np.sqrt(np.maximum(d2, 0.0))
        if not position_only:
            rt = target[:3, :3].reshape(9)
            cost += _ROT_WEIGHT * np.sqrt(np.maximum(6.0 - 2.0 * R.dot(rt), 0.0))
        return q[int(np.argmin(cost))].copy()

    def _ranked_starts(self, rng: np.random.Generator, target: np.ndarray, position_only: bool) -> np.ndarray:
        """:data:`_POOL` uniform draws within the limits, closest to the target first.

        Distance: ``‖p − p_target‖ + 0.1 m/rad · ‖R − R_target‖_F`` (position only: the first term).
        """
        q = rng.uniform(self.lower, self.upper, size=(_POOL, self.nq))
        model, data, fid = self.model, self.data, self.frame_id
        p = np.empty((_POOL, 3))
        R = np.empty((_POOL, 3, 3))
        for k in range(_POOL):  # one Pinocchio FK each: faster than the batched numpy FK for 32 rows
            pin.forwardKinematics(model, data, self._pin_q(q[k]))
            M = pin.updateFramePlacement(model, data, fid)
            p[k] = M.translation
            R[k] = M.rotation
        cost = np.linalg.norm(p - target[:3, 3], axis=1)
        if not position_only:
            cost = cost + _ROT_WEIGHT * np.linalg.norm((R - target[:3, :3]).reshape(-1, 9), axis=1)
        return q[np.argsort(cost, kind="stable")]

    # ------------------------------------------------------------------ compiled path
    def _compiled(self) -> tuple:
        """``(kernel module, C, L, P, table)``: the chain, limits and settings as arrays for :mod:`._kernel`, made once."""
        args = self._kernel_args
        if args is None:
            from . import _kernel  # numba: imported (and its functions loaded from the cache) on first use

            tree = self.robot._tree
            joint, fR, fp = tree.frame_of(self.frame_id)
            chain = np.array(tree.ancestors[joint], dtype=np.int64)
            C = (
                np.ascontiguousarray(tree.q_index[chain], dtype=np.int64),
                np.ascontiguousarray(tree.scale[chain], dtype=float),
                np.ascontiguousarray(tree.offset[chain], dtype=float),
                np.ascontiguousarray(tree.kind[chain] == _REVOLUTE),
                np.ascontiguousarray(tree.local_R[chain], dtype=float).reshape(-1, 3, 3),
                np.ascontiguousarray(tree.local_p[chain], dtype=float).reshape(-1, 3),
                np.ascontiguousarray(fR, dtype=float),
                np.ascontiguousarray(fp, dtype=float),
            )
            L = (
                np.ascontiguousarray(self.lower, dtype=float),
                np.ascontiguousarray(self.upper, dtype=float),
                np.ascontiguousarray(self.full_turn),
                np.ascontiguousarray(self.unbounded),
                np.ascontiguousarray(self._window_low, dtype=float),
                np.ascontiguousarray(self._window_turns, dtype=float),
            )
            P = np.array([self.damping, self.min_damping, self.max_step, self.stall_ratio, self.stall_steps,
                          self.max_iter], dtype=float)
            q_tab, p_tab, pp_tab, R_tab = self._start_table()
            args = self._kernel_args = (_kernel, C, L, P, (q_tab, p_tab, pp_tab, R_tab))  # one assignment: thread-safe
        return args

    def _solve_compiled(self, target: np.ndarray, q_seed, position_only: bool, tol: float, max_restarts: int,
                        seed) -> IKResult:
        """:meth:`_solve` (limits on, no final polish) compiled: the first start (``q_seed`` or the table's
        nearest pose), then up to ``max_restarts`` seeded uniform starts nearest pose first.

        A success is confirmed by Pinocchio's forward kinematics of the returned ``q`` and an exact
        limit check (independent of the compiled chain evaluation).
        """
        kernel, C, L, P, (tq, tp, tpp, tR) = self._compiled()
        Rt = np.ascontiguousarray(target[:3, :3], dtype=float)
        pt = np.ascontiguousarray(target[:3, 3], dtype=float)
        if q_seed is None:
            q0 = tq[kernel.table_index(tq, tp, tpp, tR, Rt, pt, position_only)]
        else:
            q0 = np.ascontiguousarray(q_seed, dtype=float)
        q = np.empty(self.nq)
        ok, pe, re, attempts, its = kernel.solve(q0, C, L, P, Rt, pt, position_only, tol, max_restarts,
                                                 _seed_int(seed), q)
        if ok:
            pe, re = self.errors(q, target, position_only)
            ok = pe <= tol and re <= tol and self.in_limits(q)
        return IKResult(q, bool(ok), float(pe), float(re), int(attempts), int(its))

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
            q_seed: first start ``(nq,)`` (default: :meth:`table_start`, the stored configuration nearest the target).
            tol: success when the position error [m] and the rotation error [rad] are both ≤ tol.
            seed: seed or ``numpy.random.Generator`` of the restarts.
            limits: return a configuration within the joint limits (``False``: joints move
                freely, only for diagnostics such as telling *out of reach* from *limits*).

        Each attempt: a free descent from the start (revolute angles then wrapped to the 2π
        window centred on their range); if it meets the target outside the limits, a
        projected descent from its projection. Success is confirmed on the returned ``q``
        with a fresh forward kinematics.

        Raises:
            InvalidInput: a target that is not one finite pose ``(4, 4)`` with a proper
                rotation (with ``position_only`` a position ``(3,)`` is accepted), a seed of
                the wrong shape or non-finite, ``tol`` not finite and positive,
                ``max_restarts`` not a non-negative integer, or a bad ``seed``.
        """
        robot = self.robot
        T, single = robot.check_target(target, position_only=position_only)
        if not single:
            raise InvalidInput("NumericalIK.solve takes one target: a pose (4, 4) (or a position (3,) with position_only)")
        if q_seed is not None:
            q_seed = robot.check_q(q_seed)[0][0]
        if isinstance(max_restarts, bool) or not isinstance(max_restarts, (int, np.integer)) or max_restarts < 0:
            raise InvalidInput(f"max_restarts must be a non-negative integer, got {max_restarts!r}")
        return self._solve(
            T[0], q_seed, position_only=position_only, tol=_check_tolerance(tol, "tol [m, rad]", positive=True),
            max_restarts=int(max_restarts), seed=_check_seed(seed), limits=bool(limits),
        )

    def _solve(
        self, target, q_seed, *, position_only, tol, max_restarts, seed, limits, first: bool = True, polish: bool = True,
        compiled: bool = True,
    ) -> IKResult:
        """:meth:`solve` on arguments already checked (``Robot.ik`` checks them once).

        ``first=False`` skips the attempt from the first start (already tried by the caller);
        ``polish=False`` skips the final projected descent of a failed solve; ``compiled=False``
        runs the attempts interpreted (step by step through Pinocchio) instead of :mod:`._kernel`.
        """
        target = np.asarray(target, dtype=float)
        T_des, p_des = self._target(target, position_only)
        tol = float(tol)
        if compiled and limits and first:
            res = self._solve_compiled(target, q_seed, bool(position_only), tol, int(max_restarts), seed)
            if res.success or not polish:
                return res
            # the closest configuration within the limits: a patient projected descent from the best end
            q, pe, re, it = self._descend(res.q.copy(), T_des, p_des, position_only, tol, _CLIP, patience=4)
            if pe + re > res.position_error + res.rotation_error:
                return res
            if pe <= tol and re <= tol:
                pe, re = self._errors_to(q, T_des, p_des, position_only)
            ok = pe <= tol and re <= tol and self.in_limits(q)
            return IKResult(q, bool(ok), pe, re, res.attempts, res.iterations + it)
        if not first:
            q0 = None
        elif q_seed is None:
            q0 = self.table_start(target, position_only)
        else:
            q0 = np.array(q_seed, dtype=float)
        rng = None
        best = None
        iterations = 0
        pool = np.empty((0, self.nq))
        for attempt in range(0 if first else 1, int(max_restarts) + 1):
            if attempt > 0:
                if pool.shape[0] == 0:
                    if rng is None:
                        rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
                    pool = self._ranked_starts(rng, target, position_only)
                q0, pool = pool[0].copy(), pool[1:]
            if limits:
                q, pe, re, it, ok = self._attempt_within_limits(q0, T_des, p_des, position_only, tol)
            else:
                q, pe, re, it = self._descend(q0, T_des, p_des, position_only, tol, _FREE)
                ok = pe <= tol and re <= tol
            iterations += it
            if ok:  # confirm on the returned q itself (after wrapping) with a fresh FK
                pe, re = self._errors_to(q, T_des, p_des, position_only)
                ok = pe <= tol and re <= tol and (not limits or self.in_limits(q))
            if ok:
                return IKResult(q, True, pe, re, attempt + 1, iterations)
            if best is None or pe + re < best[1] + best[2]:
                best = (q, pe, re)
        if best is None:
            return IKResult(np.clip(self.table_start(target, position_only), self.lower, self.upper), False,
                            np.inf, np.inf, 0, 0)
        q, pe, re = best
        if limits and polish:  # the closest configuration within the limits: a projected descent from the best end
            q, pe, re, it = self._descend(q.copy(), T_des, p_des, position_only, tol, _CLIP, patience=4)
            iterations += it
            if pe + re > best[1] + best[2]:
                q, pe, re = best
            elif pe <= tol and re <= tol:
                pe, re = self._errors_to(q, T_des, p_des, position_only)
                if pe <= tol and re <= tol:
                    return IKResult(q, True, pe, re, int(max_restarts) + 1, iterations)
        return IKResult(q, False, pe, re, int(max_restarts) + 1, iterations)


NumericalIK.solve_batch = solve_batch
NumericalIK.batch_errors = _batch_errors
