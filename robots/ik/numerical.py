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

:meth:`NumericalIK.solve`, ``Robot.ik`` and :meth:`NumericalIK.solve_batch` run the same
attempts compiled (:mod:`._kernel`, the whole solve in one native call, ≈ 5× cheaper per
step); the interpreted descent (:mod:`.descent`, step by step through Pinocchio) remains for
failure diagnosis, the closed-form refinement and :meth:`attempt`. The limit rules live in
:mod:`.limit_rules`, the starts in :mod:`.starts`.
"""

from __future__ import annotations

import hashlib
import threading
from dataclasses import dataclass

import numpy as np

from pinarms.errors import InvalidInput
from pinarms.robots.kinematic_tree import REVOLUTE
from pinarms.robots._checks import check_restarts as _check_restarts
from pinarms.robots._checks import check_seed as _check_seed
from pinarms.robots._checks import check_tolerance as _check_tolerance
from pinarms.robots.ik.descent import CLIP as _CLIP
from pinarms.robots.ik.descent import FREE as _FREE
from pinarms.robots.ik.descent import LMDescent
from pinarms.robots.ik.limit_rules import JointLimitRules
from pinarms.robots.ik.numerical_batch import BatchIKResult, batch_errors, seed_int32, solve_batch
from pinarms.robots.ik.starts import StartTable

__all__ = ["NumericalIK", "IKResult", "BatchIKResult"]



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


class NumericalIK(JointLimitRules, StartTable, LMDescent):
    """Levenberg–Marquardt IK of one robot frame, joint limits respected, seeded random restarts.

    Args:
        robot: a :class:`pinarms.robots.Robot`.
        frame: target frame (default the tcp).
        max_iter: iterations per attempt.
        damping: initial ``μ`` of ``λ = μ‖e‖² + λ_min``.
        min_damping: ``λ_min`` [1 / (m or rad)²].
        max_step: largest change of one joint per iteration [rad or m].
        stall_ratio, stall_steps: an attempt stops when ``‖e‖²`` falls by less than
            ``1 − stall_ratio`` for ``stall_steps`` accepted steps in a row.
        compiled_stall_steps: the same for the compiled solver's attempts (``Robot.ik``,
            :meth:`solve`, :meth:`solve_batch`), whose restarts from stored poses cost a few µs:
            giving a stalled descent up after 2 steps instead of 4 saved 4-8 % of the iterations
            per target (aubo_i3, ur5, panda; 3 500 seeded targets each, every one still solved); the
            interpreted descent (refinement, diagnosis, fallback) keeps ``stall_steps``.
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
        compiled_stall_steps: int = 2,
    ) -> None:
        self.robot = robot
        self.model = robot.model
        self._local = threading.local()  # per-thread Pinocchio data: one solver serves many threads
        self._table = None  # start table (see table_start), made on first use
        self._kernel_args = None  # the compiled solver's constant arrays (see _compiled), made on first use
        self.frame_id = robot.frame_id(frame)
        self._frame = frame
        self.nq = robot.nq
        self._init_limits(robot)
        self._identity_coords = (not self._any_unbounded) and self.model.nq == self.nq
        self._coords = robot.kinematic_tree.coordinates
        self.max_iter = int(max_iter)
        self.damping = float(damping)
        self.min_damping = float(min_damping)
        self.max_step = float(max_step)
        self.stall_ratio = float(stall_ratio)
        self.stall_steps = int(stall_steps)
        self.compiled_stall_steps = int(compiled_stall_steps)

    # ------------------------------------------------------------------ compiled path
    def _compiled(self) -> tuple:
        """``(kernel module, C, L, P, table)``: the chain, limits and settings as arrays for :mod:`._kernel`, made once."""
        args = self._kernel_args
        if args is None:
            from pinarms.robots.ik import _kernel  # numba: imported (and its functions loaded from the cache) on first use

            tree = self.robot.kinematic_tree
            joint, fR, fp = tree.frame_of(self.frame_id)
            chain = np.array(tree.ancestors[joint], dtype=np.int64)
            C = (
                np.ascontiguousarray(tree.q_index[chain], dtype=np.int64),
                np.ascontiguousarray(tree.scale[chain], dtype=float),
                np.ascontiguousarray(tree.offset[chain], dtype=float),
                np.ascontiguousarray(tree.kind[chain] == REVOLUTE),
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
            P = np.array([self.damping, self.min_damping, self.max_step, self.stall_ratio, self.compiled_stall_steps,
                          self.max_iter], dtype=float)
            digest = hashlib.sha256(b"".join(np.ascontiguousarray(a).tobytes() for a in C + L))
            table = self._grid_table(digest.hexdigest())
            args = self._kernel_args = (_kernel, C, L, P, table)  # one assignment: thread-safe
        return args

    def solve_compiled(self, target: np.ndarray, q_seed, position_only: bool, tol: float, max_restarts: int,
                        seed) -> IKResult:
        """:meth:`solve_checked` (limits on, no final polish) compiled: the first start (``q_seed`` or the nearest of
        32 768 stored poses), then up to ``max_restarts`` more: the 8 stored poses next nearest the
        target, then seeded uniform starts nearest pose first.

        A success is confirmed by Pinocchio's forward kinematics of the returned ``q`` and an exact
        limit check (independent of the compiled chain evaluation).
        """
        kernel, C, L, P, table = self._compiled()
        Rt = np.ascontiguousarray(target[:3, :3], dtype=float)
        pt = np.ascontiguousarray(target[:3, 3], dtype=float)
        if q_seed is None:
            q0 = table[0][kernel.grid_index(table, Rt, pt, position_only)]
        else:
            q0 = np.ascontiguousarray(q_seed, dtype=float)
        q = np.empty(self.nq)
        ok, pe, re, attempts, its = kernel.solve(q0, table, C, L, P, Rt, pt, position_only, tol, max_restarts,
                                                 seed_int32(seed), q)
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
        _check_restarts(max_restarts)
        return self.solve_checked(
            T[0], q_seed, position_only=position_only, tol=_check_tolerance(tol, "tol [m, rad]", positive=True),
            max_restarts=int(max_restarts), seed=_check_seed(seed), limits=bool(limits),
        )

    def solve_checked(
        self, target, q_seed, *, position_only, tol, max_restarts, seed, limits, first: bool = True, polish: bool = True,
        compiled: bool = True,
    ) -> IKResult:
        """:meth:`solve` on arguments already checked (``Robot.ik`` checks them once).

        ``first=False`` skips the attempt from the first start (already tried by the caller);
        ``polish=False`` skips the final projected descent of a failed solve; ``compiled=False``
        runs the attempts interpreted (step by step through Pinocchio) instead of :mod:`._kernel`.
        """
        target = np.asarray(target, dtype=float)
        target_to_base, target_in_base = self._target(target, position_only)
        tol = float(tol)
        if compiled and limits and first:
            res = self.solve_compiled(target, q_seed, bool(position_only), tol, int(max_restarts), seed)
            if res.success or not polish:
                return res
            # the closest configuration within the limits: a patient projected descent from the best end
            q, pe, re, it = self._descend(res.q.copy(), target_to_base, target_in_base, position_only, tol, _CLIP, patience=4)
            if pe + re > res.position_error + res.rotation_error:
                return res
            if pe <= tol and re <= tol:
                pe, re = self._errors_to(q, target_to_base, target_in_base, position_only)
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
                q, pe, re, it, ok = self._attempt_within_limits(q0, target_to_base, target_in_base, position_only, tol)
            else:
                q, pe, re, it = self._descend(q0, target_to_base, target_in_base, position_only, tol, _FREE)
                ok = pe <= tol and re <= tol
            iterations += it
            if ok:  # confirm on the returned q itself (after wrapping) with a fresh FK
                pe, re = self._errors_to(q, target_to_base, target_in_base, position_only)
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
            q, pe, re, it = self._descend(q.copy(), target_to_base, target_in_base, position_only, tol, _CLIP, patience=4)
            iterations += it
            if pe + re > best[1] + best[2]:
                q, pe, re = best
            elif pe <= tol and re <= tol:
                pe, re = self._errors_to(q, target_to_base, target_in_base, position_only)
                if pe <= tol and re <= tol:
                    return IKResult(q, True, pe, re, int(max_restarts) + 1, iterations)
        return IKResult(q, False, pe, re, int(max_restarts) + 1, iterations)


NumericalIK.solve_batch = solve_batch
NumericalIK.batch_errors = batch_errors
