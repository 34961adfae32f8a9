"""Inverse kinematics of a :class:`pinarms.robots.Robot`: the methods ``ik``, ``ik_all``, ``ik_branches``,
``check_target``, ``ik_failure_reason`` and their helpers, as a base class of ``Robot`` (a target's
checks: :mod:`pinarms.robots.ik_target`).

Its own module so that ``robots/robot.py`` (model, kinematics, dynamics) stays readable; the
conventions (units, frames, shapes) are those of :mod:`pinarms.robots.robot`.
"""


from typing import Any, Mapping

import numpy as np
from numpy.typing import ArrayLike

from pinarms.robots._checks import check_restarts as _check_restarts
from pinarms.robots._checks import check_seed as _check_seed
from pinarms.robots._checks import check_tolerance as _check_tolerance
from pinarms.errors import InvalidInput, ModelError, UnreachableTarget
from pinarms.robots.ik.attempts import IKAttempts
from pinarms.robots.ik.numerical import NumericalIK
from pinarms.robots.ik.solver import LIMIT_TOL, split_by_target
from pinarms.robots.ik_target import check_ik_target


__all__: list[str] = []


def _limit_tolerance(value: Any) -> float:
    """``limit_tolerance`` checked (a finite distance ≥ 0, rad or m), at least the solvers' own 1e-9."""
    return max(_check_tolerance(value, "limit_tolerance [rad or m]"), LIMIT_TOL)


class RobotIK:
    """The inverse-kinematics methods of :class:`pinarms.robots.Robot` (which inherits them)."""

    # -------------------------------------------------------- inverse kinematics
    @property
    def has_analytic_ik(self) -> bool:
        """Whether :meth:`ik_all` has a closed form for this arm."""
        return self._analytic_ik is not None

    @property
    def analytic_ik(self) -> Any:
        """The closed-form solver of :meth:`ik_all` (``candidates``, ``solve``, ``starts``), or ``None``."""
        return self._analytic_ik

    def set_analytic_ik(self, solver: Any, *, rejected: Mapping[str, str] | None = None,
                        recognised: bool = False) -> None:
        """Give this arm the closed-form ``solver`` (``None``: numerical IK only).

        ``rejected``: why each closed-form family was refused (named when :meth:`ik_all` has no
        closed form); ``recognised``: the solver was recognised from the geometry, so a new tcp
        frame recognises it again (:func:`~pinarms.robots.ik.attach_analytic_ik`).
        """
        self._analytic_ik = solver
        self._ik_rejected = dict(rejected or {})
        if recognised:
            self._ik_auto = True

    @property
    def ik_family(self) -> str | None:
        """The closed-form family recognised from the arm's geometry, or ``None`` (numerical IK only).

        ``"ur_type"``, ``"scara"``, ``"gantry"`` or ``"koji"``: the kinematic structure
        (joint types, axes, offsets, lengths read from the model) matched that family and
        its closed form solved back random configurations at load (``robots.ik.recognise``).
        """
        solver = self._analytic_ik
        return None if solver is None else solver.key

    def check_target(self, target: ArrayLike, *, position_only: bool = False) -> tuple[np.ndarray, bool]:
        """Validate IK target(s): a pose ``(4, 4)`` / ``(N, 4, 4)`` frame → base [m], proper rotation.

        With ``position_only`` a position ``(3,)`` / ``(N, 3)`` [m] is accepted too.
        Returns the ``(N, 4, 4)`` array and whether a single target was given.

        Raises:
            InvalidInput: wrong shape, non-finite entries, or a rotation block that is not a
                proper rotation (orthonormal within 1e-6, determinant +1).
        """
        return check_ik_target(target, position_only=position_only)

    def ik_all(
        self, target: ArrayLike, q_ref: ArrayLike | None = None, *, respect_limits: bool = True, equivalents: bool = False,
        limit_tolerance: float = 0.0,
    ) -> np.ndarray | list[np.ndarray]:
        """Every closed-form IK branch within the joint limits (tolerance 1e-9 rad or m), each once.

        A branch (UR-type: shoulder × wrist flip × elbow) is listed once, each revolute angle
        at its 2π equivalent within the limits nearest ``q_ref``; a branch none of whose
        equivalents lies within the limits is left out.

        Args:
            target: tcp pose ``(4, 4)`` (frame → base, m), or a batch ``(N, 4, 4)``.
            q_ref: ``(nq,)`` or ``(N, nq)``: solutions are sorted by distance to it
                (default :attr:`neutral`); it also fixes the free joint at singular poses
                and picks each angle's 2π equivalent.
            equivalents: also list every other 2π equivalent within the limits (a UR's ±2π
                joints give up to 2⁶ = 64 rows per branch, about 228 per pose).
            respect_limits: ``False`` returns the geometric solutions whatever the joint
                limits (each revolute angle once, in ``(-π, π]``), e.g. to see how far a
                printed pose lies outside a range. Check them with :meth:`within_limits`.
            limit_tolerance: accept solutions up to this far outside a joint's range [rad or
                m] (returned as they are, never clamped), e.g. a printed pose that needs a
                joint a rounding error past its limit (see :mod:`pinarms.robots.ik.near_limits`).

        Returns:
            ``(k, nq)`` for one target (``k = 0`` allowed: see :meth:`ik_failure_reason`), a
            list of ``N`` such arrays for a batch. Every row's FK meets the target within
            1e-9 m and 1e-9 rad.

        Raises:
            ModelError: the arm has no closed form (use :meth:`ik`).
        """
        T, single, ref = self._analytic_targets(target, q_ref)
        limit_tol = _limit_tolerance(limit_tolerance)
        if T.shape[0] == 0:
            return []
        if respect_limits:
            sols = self._analytic_ik.solve(T, ref, equivalents=bool(equivalents), limit_tol=limit_tol)
        else:
            idx, q = self._analytic_ik.candidates(T, ref, respect_limits=False)
            sols = split_by_target(idx, q, T.shape[0])
        return sols[0] if single else sols

    def ik_branches(self, target: ArrayLike, q_ref: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`ik_all` of one pose ``(4, 4)`` with the branch label of every solution.

        Returns:
            ``q (k, nq)`` as :meth:`ik_all` and ``branch (k,)`` integers: the closed form's
            branch (UR-type: shoulder × wrist flip × elbow, 0-7; SCARA: elbow; koji arm:
            arm-plane candidates). Along a continuous path a solution keeps its label until
            the path crosses a singularity, so equal labels mean "the same arm
            configuration" for consecutive waypoints (see
            :func:`pinarms.planning.joint_waypoints`).
        """
        T, single, ref = self._analytic_targets(target, q_ref)
        if not single:
            raise InvalidInput("ik_branches takes one pose of shape (4, 4)")
        _, q, branch = self._analytic_ik.candidates(T, ref, with_branches=True)
        return q, branch

    def _analytic_targets(self, target: Any, q_ref: Any) -> tuple[np.ndarray, bool, np.ndarray | None]:
        """Checked targets ``(N, 4, 4)``, single flag and ``q_ref`` rows for the closed forms."""
        if self._analytic_ik is None:
            why = "; ".join(f"{k}: {v}" for k, v in getattr(self, "_ik_rejected", {}).items())
            raise ModelError(
                f"robot '{self.name}' has no analytic IK (closed forms: SCARA, gantry, koji arm, UR-type; "
                f"{'refused: ' + why if why else 'its joints are not those of any of them'}); "
                "use Robot.ik for a numerical solution"
            )
        T, single = self.check_target(target)
        ref = None
        if q_ref is not None:
            ref, _ = self.check_q(q_ref)
            if ref.shape[0] not in (1, T.shape[0]):
                raise InvalidInput(f"q_ref must be one configuration or one per target ({T.shape[0]}), got {ref.shape[0]}")
        return T, single, ref

    def numerical_ik(self) -> NumericalIK:
        """This arm's numerical solver (:class:`~pinarms.robots.ik.numerical.NumericalIK`), built once."""
        solver = getattr(self, "_numerical_ik_solver", None)
        if solver is None:  # two threads may both build one: either is fine (no shared scratch state)
            solver = self._numerical_ik_solver = NumericalIK(self)
        return solver

    def _limit_diagnosis(self, q: np.ndarray) -> list[str]:
        """Joints of ``q`` outside their limits, each revolute angle taken at its 2π equivalent nearest the range."""
        return self.limit_violations(self._wrapped_to_range(q))

    def _limit_excess(self, q: np.ndarray) -> float:
        """Total distance of ``q`` outside its limits [rad or m], revolute angles wrapped as above."""
        q = self._wrapped_to_range(q)
        return float(np.sum(np.maximum(self.lower - q, 0.0) + np.maximum(q - self.upper, 0.0)))

    def _wrapped_to_range(self, q: np.ndarray) -> np.ndarray:
        q = np.array(q, dtype=float)
        tree = self._tree
        for j in range(self.nq):
            rev = tree.kind[[i for i in range(1, self.model.njoints) if tree.q_index[i] == j and tree.scale[i] == 1.0][0]] == 1
            if rev:
                mid = 0.5 * (self.lower[j] + self.upper[j])
                q[j] = mid + (q[j] - mid + np.pi) % (2.0 * np.pi) - np.pi
        return q

    def ik_failure_reason(self, target: ArrayLike, *, position_only: bool = False) -> str | None:
        """Why ``target`` (one pose ``(4, 4)``) has no IK solution within the limits, or ``None`` if it has one.

        The answer says whether the pose is out of reach (or has an orientation the arm cannot
        take) or needs a joint outside its limits, naming the joints.
        """
        T, single = self.check_target(target, position_only=position_only)
        if not single:
            raise InvalidInput("ik_failure_reason takes one target")
        what = "position" if position_only else "pose"
        if self._analytic_ik is not None and not position_only:
            if self._analytic_ik.solve(T)[0].shape[0]:
                return None
            idx, free = self._analytic_ik.candidates(T, respect_limits=False)
            if free.shape[0]:
                worst = min(free, key=self._limit_excess)
                return (
                    f"the {what} is within reach but every solution needs a joint outside its limits; "
                    f"nearest: {'; '.join(self._limit_diagnosis(worst))}"
                )
            # none from the closed form (also at singular poses, where θ free joints were fixed):
            # the numerical diagnosis below decides
        solver = self.numerical_ik()
        res = solver.solve_checked(T[0], None, IKAttempts(bool(position_only), 1e-9, 20, 0, True))
        if res.success:
            return None
        free = solver.solve_checked(T[0], None, IKAttempts(bool(position_only), 1e-9, 20, 0, False))
        if free.success:
            return (
                f"the {what} is within reach but needs a joint outside its limits: "
                f"{'; '.join(self._limit_diagnosis(free.q)) or 'a limit'}"
            )
        return self._unreachable_text(T[0], position_only, res)

    def _unreachable_text(self, T: np.ndarray, position_only: bool, res=None) -> str:
        if res is None:
            res = self.numerical_ik().solve_checked(T, None, IKAttempts(bool(position_only), 1e-9, 10, 0, False))
        if res.position_error > 1e-6 or position_only:
            return (
                f"the target is out of reach: the closest tcp position found is {res.position_error:.4g} m away "
                f"(rotation error {res.rotation_error:.3g} rad)"
            )
        return (
            f"the target's orientation cannot be taken by '{self.name}' at that position "
            f"(rotation error {res.rotation_error:.3g} rad remains)"
        )

    def ik(
        self,
        target: ArrayLike,
        q_seed: ArrayLike | None = None,
        *,
        position_only: bool = False,
        tol: float = 1e-10,
        max_restarts: int = 40,
        seed: int | np.random.Generator | None = 0,
        limit_tolerance: float = 0.0,
    ) -> np.ndarray:
        """A configuration within the limits whose tcp meets ``target`` within ``tol``: ``(nq,)``, or ``(N, nq)`` for a batch.

        One target: Levenberg–Marquardt (:class:`~pinarms.robots.ik.NumericalIK`, compiled)
        from ``q_seed`` (default: of 256 configurations stored with their poses, the one nearest
        the target), then seeded random restarts; if none meets the target, arms with a closed
        form try their analytic branches nearest ``q_seed`` (default :attr:`neutral`; each
        revolute angle at its 2π equivalent within the limits nearest it), refined by the
        interpreted solver, then its restarts. The answer is the solution the descent reaches, normally the one nearest
        the start; use :meth:`ik_all` (``q_ref``) for the closed-form branch nearest a
        configuration. A batch of targets ``(N, 4, 4)`` (or positions ``(N, 3)`` with
        ``position_only``) is solved by the compiled solver in thread blocks
        (:meth:`~pinarms.robots.ik.NumericalIK.solve_batch`); ``q_seed`` is then ``(nq,)`` or
        ``(N, nq)``; for an integer ``seed``, row ``k`` equals ``ik(target[k], q_seed[k],
        seed=seed + k)``.

        Args:
            target: tcp pose ``(4, 4)`` frame → base [m], or ``(N, 4, 4)``; with
                ``position_only`` a position ``(3,)`` / ``(N, 3)`` [m] (or a pose, whose
                rotation must still be a proper rotation, ignored).
            q_seed: start ``(nq,)`` (or ``(N, nq)`` for a batch).
            tol: required position error [m] and rotation error [rad].
            max_restarts: random restarts after the first attempt (per target).
            seed: seed or generator of the restarts (results are reproducible).
            limit_tolerance: one target: when no configuration within the limits meets it,
                accept one up to this far outside a joint's range [rad or m] (not clamped; a
                configuration within the limits is always preferred). Not for batches.

        Raises:
            InvalidInput: a malformed target or ``q_seed`` (shape, NaN/inf, not a proper
                rotation), ``tol`` not finite and positive, ``max_restarts`` not a non-negative
                integer, or a bad ``seed``.
            UnreachableTarget: no configuration within the limits found; the message gives the
                remaining error and says whether the target is out of reach or needs a joint
                outside its limits. A configuration that misses the target is never returned.
                For a batch the message names the targets that failed; the exception carries
                ``solved`` (``(N,)`` bool) and ``q`` (``(N, nq)``, the solved rows valid).
        """
        T, single = self.check_target(target, position_only=position_only)
        tol = _check_tolerance(tol, "tol [m, rad]", positive=True)
        _check_restarts(max_restarts)
        _check_seed(seed)
        limit_tol = _limit_tolerance(limit_tolerance)
        if not single:
            if limit_tol > LIMIT_TOL:
                raise InvalidInput("limit_tolerance is for one target; solve a batch within the limits, or one by one")
            return self._ik_batch(T, q_seed, position_only, tol, int(max_restarts), seed)
        seed_q = None
        if q_seed is not None:
            seed_q, one = self.check_q(q_seed)
            if not one:
                raise InvalidInput(f"q_seed of one target must have shape ({self.nq},), got {np.shape(q_seed)}")
            seed_q = seed_q[0]
        solver = self.numerical_ik()
        T0 = T[0]
        # compiled Levenberg–Marquardt: the first start, then the seeded restarts, in one native call
        res = solver.solve_compiled(T0, seed_q, bool(position_only), tol, int(max_restarts), seed)
        if res.success:
            return res.q if seed_q is None else solver.nearest_equivalent(res.q, seed_q)
        # not found: the interpreted solver's path (closed-form branches, restarts, a final polish) for the diagnosis
        res = solver.solve_checked(T0, seed_q, IKAttempts(bool(position_only), tol, 0, seed, True, polish=False,
                                                          compiled=False))
        if res.success:
            return res.q if seed_q is None else solver.nearest_equivalent(res.q, seed_q)
        if self._analytic_ik is not None and not position_only:  # closed-form starts: where the first descent failed
            starts = self._analytic_ik.starts(T0, self.neutral if seed_q is None else seed_q)
            for q in starts[:4]:
                q2, pe, re, _ = solver.attempt(q, T0, False, tol)
                if pe <= tol and re <= tol and solver.in_limits(q2):
                    pe, re = solver.errors(q2, T0, False)
                    if pe <= tol and re <= tol:
                        return q2
        res = solver.solve_checked(T0, seed_q, IKAttempts(bool(position_only), tol, int(max_restarts), seed, True,
                                                          first=False))
        if res.success and self.within_limits(res.q):
            return res.q if seed_q is None else solver.nearest_equivalent(res.q, seed_q)
        if limit_tol > LIMIT_TOL:
            q = self._ik_within_tolerance(T0, seed_q, res.q, position_only, tol, limit_tol)
            if q is not None:
                return q
        raise UnreachableTarget(self._ik_failure_text(T0, position_only, tol, res))

    def _ik_within_tolerance(self, T: np.ndarray, seed_q: np.ndarray | None, best: np.ndarray,
                             position_only: bool, tol: float, limit_tol: float) -> np.ndarray | None:
        """A configuration meeting ``T`` within ``tol`` and the limits widened by ``limit_tol``, or None.

        Starts: the closed-form branches within the widened limits, then ``best`` (the
        strict search's closest configuration); each refined with the joints free.
        """
        solver = self.numerical_ik()
        starts = [best]
        if self._analytic_ik is not None and not position_only:
            ref = self.neutral if seed_q is None else seed_q
            starts = list(self._analytic_ik.starts(T, ref, limit_tol)[:4]) + starts
        for q in starts:
            q2, pe, re, _ = solver.attempt(np.array(q, dtype=float), T, position_only, tol, limits=False)
            q2 = self._wrapped_to_range(q2)
            if pe <= tol and re <= tol and self.within_limits(q2, tol=limit_tol):
                return q2
        return None

    def _ik_failure_text(self, T0: np.ndarray, position_only: bool, tol: float, res) -> str:
        reason = self.ik_failure_reason(T0[:3, 3] if position_only else T0, position_only=position_only)
        return (
            f"robot '{self.name}': no configuration within the joint limits reaches the "
            f"{'position' if position_only else 'pose'} within tol = {tol:g} "
            f"(best: position error {res.position_error:.3g} m, rotation error {res.rotation_error:.3g} rad "
            f"after {res.attempts} starts); {reason or 'the solver did not converge: try more max_restarts or another q_seed'}"
        )

    def _ik_batch(self, T: np.ndarray, q_seed: Any, position_only: bool, tol: float, max_restarts: int, seed) -> np.ndarray:
        """:meth:`ik` of a checked batch ``T (N, 4, 4)``."""
        N = T.shape[0]
        if N == 0:
            return np.zeros((0, self.nq))
        seeds = None
        if q_seed is not None:
            seeds, _ = self.check_q(q_seed)
            if seeds.shape[0] not in (1, N):
                raise InvalidInput(f"q_seed must be one configuration or one per target ({N}), got {seeds.shape[0]}")
        solver = self.numerical_ik()
        # the compiled solver for every target (≈ 10-30 µs each): cheaper than the closed form's
        # batched evaluation, FK check and sorting, which cost ≈ 10-80 µs per pose here
        res = solver.solve_batch(T, seeds, position_only=position_only, tol=tol, max_restarts=max_restarts, seed=seed)
        if seeds is not None:  # as for one target: the 2π equivalents within the limits nearest the seeds
            q = solver.nearest_equivalent(res.q, seeds if seeds.shape[0] == N else seeds[0])
            res = type(res)(q, res.success, res.position_error, res.rotation_error, res.iterations)
        ok = res.success & self.within_limits(res.q, tol=0.0)
        if ok.all():
            return res.q
        bad = np.flatnonzero(~ok)
        k = int(bad[0])
        from pinarms.robots.ik.numerical import IKResult

        first = IKResult(res.q[k], False, float(res.position_error[k]), float(res.rotation_error[k]), 1 + max_restarts, 0)
        exc = UnreachableTarget(
            f"{bad.size} of {N} targets not solved (indices {bad[:10].tolist()}{' ...' if bad.size > 10 else ''}); "
            f"target {k}: {self._ik_failure_text(T[k], position_only, tol, first)}"
        )
        exc.solved = ok
        exc.q = res.q
        raise exc
