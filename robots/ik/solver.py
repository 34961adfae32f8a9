"""What every closed-form solver shares: candidates → 2π equivalents → limits → FK check.

A family solver (:mod:`.ur_type`, :mod:`.scara`, :mod:`.gantry`, :mod:`.koji`) only
implements :meth:`AnalyticIK.raw`: the branch candidates ``(N, B, nq)`` of a batch of
targets, NaN where a branch does not exist. :meth:`AnalyticIK.solve` then

1. wraps revolute angles to ``(-π, π]`` and adds every ``θ ± 2kπ`` that lies within the
   joint's limits (a joint with a range wider than 2π has several equivalents),
2. drops candidates outside the limits (tolerance :data:`LIMIT_TOL`),
3. recomputes the forward kinematics of every candidate and keeps those that meet the
   target within :data:`FK_TOL` (a branch through a singular configuration or a target
   the family cannot reach, e.g. a tilted target for a SCARA, fails here),
4. removes duplicates and sorts each target's solutions by distance to ``q_ref``.

All steps are vectorised over the batch (the number of solutions per target varies, so
rows are expanded with ``np.repeat`` and split once at the end).
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from pinarms.errors import ModelError
from pinarms.robots.ties import argsort_tied

__all__ = ["AnalyticIK", "LIMIT_TOL", "FK_TOL", "split_by_target"]

#: Joint-limit tolerance of the returned solutions [rad or m].
LIMIT_TOL = 1e-9
#: A returned solution's FK meets the target within this [m] in position and [rad] in rotation.
FK_TOL = 1e-9
#: Candidates whose FK misses the target by less than this [m, rad] are polished, not dropped.
POLISH_RANGE = 1e-5

#: Most combinations of 2π equivalents per branch that ``equivalents=True`` lists.
MAX_EQUIVALENTS = 4096
#: Seeded random configurations each closed form must solve back when it is built (the load-time proof).
PROOF_SAMPLES = 32

_TWO_PI = 2.0 * np.pi
_CHUNK = 8192  # targets per block
_MAX_ROWS = 1 << 20  # candidate rows per block (bounds memory for wide joint ranges)
_WORKERS = max(1, min(4, os.cpu_count() or 1))


def split_by_target(idx: np.ndarray, q: np.ndarray, n_targets: int) -> list[np.ndarray]:
    """Rows ``q (M, nq)`` sorted by target index ``idx (M,)`` as a list of ``n_targets`` arrays ``(k_i, nq)``.

    Plain slices (views): ``np.split`` costs ≈ 10× more per piece, which matters for 10⁵ targets.
    """
    ends = np.cumsum(np.bincount(idx, minlength=n_targets)).tolist()
    return [q[a:b] for a, b in zip([0] + ends[:-1], ends)]


class AnalyticIK:
    """Base of the closed-form solvers. Subclasses set :attr:`family` and implement :meth:`raw`.

    Args:
        robot: the :class:`pinarms.robots.Robot` to solve for; the solver reads its geometry from
            ``robot.model`` when built and checks the structure it assumes.
        frame: the target frame (default the robot's tcp).
    """

    family = "analytic"
    #: Short name of the family (a key of :data:`pinarms.robots.ik.FAMILIES`), reported as ``Robot.ik_family``.
    key = "analytic"
    #: Number of geometric branches of :meth:`raw` (its candidate slots modulo this are the
    #: branch labels; extra slots, e.g. at a singular wrist, repeat branches). None: every slot.
    n_branches: int | None = None

    def __init__(self, robot, frame: str = "tcp") -> None:
        self.robot = robot
        self.frame = frame
        nq = robot.nq
        self._revolute = np.zeros(nq, dtype=bool)

    # ------------------------------------------------------------ to implement
    def raw(self, targets: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
        """Branch candidates ``(N, B, nq)`` for targets ``(N, 4, 4)``; NaN where a branch does not exist.

        ``q_ref (N, nq)`` picks the free joint at singular configurations.
        """
        raise NotImplementedError

    # ----------------------------------------------------------------- helpers
    def _mark_revolute(self, axes) -> None:
        for a in axes:
            if a.kind == "revolute" and not a.is_mimic:
                self._revolute[a.q_index] = True

    def _self_check(self, n: int = PROOF_SAMPLES) -> None:
        """Prove the closed form on this robot: raise ModelError unless FK → IK recovers ``n`` random configurations.

        The configurations are seeded and within the limits. The verified solutions of each
        one's pose (within the limits, each reproducing the pose within :data:`FK_TOL`) must
        contain it: the solution nearest it lies within 1e-6 of it (2π equivalents of a
        revolute angle are taken nearest it, so they count as the same).
        """
        robot = self.robot
        q = robot.random_q(n, seed=12345)
        idx, sols = self.candidates(robot.fk(q, self.frame), q)  # sorted by target, nearest q first
        first = np.full(n, -1)
        found, at = np.unique(idx, return_index=True)
        first[found] = at
        err = np.full(n, np.inf)
        if sols.shape[0]:
            err = np.where(first >= 0, np.abs(sols[np.maximum(first, 0)] - q).max(axis=1), np.inf)
        bad = np.flatnonzero(err > 1e-6)
        if bad.size:
            raise ModelError(
                f"the {self.family} closed form does not reproduce robot '{robot.name}': the pose of "
                f"q = {np.round(q[bad[0]], 6).tolist()} has no solution (reproducing it within {FK_TOL:g}) equal to "
                f"it (joint error {err[bad[0]]:.3g}); its geometry differs from what the solver assumes"
            )

    # ------------------------------------------------------------------ public
    def _shift_ranges(self, limit_tol: float = LIMIT_TOL) -> list[tuple[int, float, float]]:
        """Revolute joints whose range (widened to ``limit_tol``) admits more than one 2π equivalent: ``(j, k_min, k_max)``.

        Counts only (no arrays): a joint with a huge range (±1e9 rad) costs nothing here.
        """
        widen = limit_tol - LIMIT_TOL
        lo, hi = self.robot.lower - widen, self.robot.upper + widen
        out = []
        for j in np.flatnonzero(self._revolute):
            k0, k1 = float(np.ceil((lo[j] - np.pi) / _TWO_PI)), float(np.floor((hi[j] + np.pi) / _TWO_PI))
            if not (k0 == 0.0 and k1 == 0.0):
                out.append((int(j), k0, k1))
        return out

    def _shifts(self, limit_tol: float = LIMIT_TOL) -> list[tuple[int, np.ndarray]]:
        """The 2π multiples ``k`` of each joint of :meth:`_shift_ranges` (``equivalents=True`` lists them all).

        Raises:
            InvalidInput: more than :data:`MAX_EQUIVALENTS` combinations per branch.
        """
        ranges = self._shift_ranges(limit_tol)
        total = float(np.prod([k1 - k0 + 1.0 for _, k0, k1 in ranges]))
        if total > MAX_EQUIVALENTS:
            from pinarms.errors import InvalidInput

            raise InvalidInput(
                f"robot '{self.robot.name}': its joint ranges hold {total:.3g} combinations of 2π equivalents per "
                f"branch; equivalents=True lists at most {MAX_EQUIVALENTS} (ask without equivalents)"
            )
        return [(j, np.arange(k0, k1 + 1.0)) for j, k0, k1 in ranges]

    def _dense(
        self, targets: np.ndarray, q_ref: np.ndarray, respect_limits: bool, equivalents: bool = False,
        limit_tol: float = LIMIT_TOL,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Solutions of one chunk sorted by distance to ``q_ref``: ``q (n, K, nq)``, ``valid (n, K)``, ``branch (n, K)``."""
        robot = self.robot
        q = self.raw(targets, q_ref)
        n, B = q.shape[:2]
        branch = np.broadcast_to(np.arange(B) % (self.n_branches or B), (n, B))
        rev = self._revolute
        q[..., rev] = np.pi - (np.pi - q[..., rev]) % _TWO_PI  # wrap to (-π, π]
        valid = np.all(np.isfinite(q), axis=-1)
        for b in range(1, B):  # branches that coincide (singular or boundary poses)
            same = np.all(np.abs(q[:, :b] - q[:, b : b + 1]) <= 1e-8, axis=-1) & valid[:, :b]
            valid[:, b] &= ~np.any(same, axis=1)
        widen = limit_tol - LIMIT_TOL  # a caller's tolerance beyond the solver's own
        lo, hi = robot.lower - widen, robot.upper + widen
        if respect_limits and equivalents:  # every 2π equivalent within the limits
            for j, k in self._shifts(limit_tol):
                q = np.repeat(q, k.size, axis=1)
                q[..., j] += _TWO_PI * np.tile(k, q.shape[1] // k.size)
                valid = np.repeat(valid, k.size, axis=1)
                branch = np.repeat(branch, k.size, axis=1)
        elif respect_limits:  # each branch once: every angle at its equivalent within the limits nearest q_ref
            js = [j for j, _, _ in self._shift_ranges(limit_tol)]
            if js:
                lo_j, hi_j = lo[js], hi[js]
                qj, ref = q[..., js], q_ref[:, None, js]
                base = qj + _TWO_PI * np.round((np.clip(ref, lo_j, hi_j) - qj) / _TWO_PI)
                cand = base[None] + _TWO_PI * np.array([0.0, -1.0, 1.0])[:, None, None, None]  # (3, n, B, m)
                inside = (cand >= lo_j - LIMIT_TOL) & (cand <= hi_j + LIMIT_TOL)
                pick = np.argmin(np.where(inside, np.abs(cand - ref), np.inf), axis=0)
                q[..., js] = np.take_along_axis(cand, pick[None], axis=0)[0]
        if respect_limits:
            valid &= np.all((q >= lo - LIMIT_TOL) & (q <= hi + LIMIT_TOL), axis=-1)
        rows = q[valid]
        if rows.shape[0]:
            ref = np.broadcast_to(targets[:, None], (n, q.shape[1], 4, 4))[valid]
            pos_err, rot_err = self._pose_errors(rows, ref)
            ok = (pos_err <= FK_TOL) & (rot_err <= FK_TOL)
            # Near a double root (a wrist or shoulder singularity) the closed form loses
            # half the digits (an error ~1e-8 from a square root of a rounding error):
            # polish those candidates with Gauss–Newton steps, then check them again.
            near = ~ok & (pos_err < POLISH_RANGE) & (rot_err < POLISH_RANGE)
            if near.any():
                polished = self._polish(rows[near], ref[near])
                pe, re = self._pose_errors(polished, ref[near])
                fixed = (pe <= FK_TOL) & (re <= FK_TOL)
                if respect_limits:
                    fixed &= np.all((polished >= lo - LIMIT_TOL) & (polished <= hi + LIMIT_TOL), axis=-1)
                rows[near] = polished
                ok[near] = fixed
                q[valid] = rows
            valid[valid] = ok
        dist = np.where(valid, np.linalg.norm(q - q_ref[:, None, :], axis=-1), np.inf)
        order = np.argsort(dist, axis=1, kind="stable")
        q = np.take_along_axis(q, order[..., None], axis=1)
        valid = np.take_along_axis(valid, order, axis=1)
        branch = np.take_along_axis(branch, order, axis=1)
        return q, valid, branch

    def _pose_errors(self, q: np.ndarray, ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Position error [m] and rotation error (Frobenius / √2, ≈ angle) [rad] of ``q (M, nq)``."""
        T = self.robot.fk(q, self.frame)
        pos_err = np.linalg.norm(T[:, :3, 3] - ref[:, :3, 3], axis=1)
        rot_err = np.linalg.norm((T[:, :3, :3] - ref[:, :3, :3]).reshape(-1, 9), axis=1) / np.sqrt(2.0)
        return pos_err, rot_err

    def _polish(self, q: np.ndarray, ref: np.ndarray, steps: int = 3) -> np.ndarray:
        """Gauss–Newton steps ``Δq = J⁺ e`` towards the targets ``ref (M, 4, 4)``, batched.

        ``e`` stacks the position error and the small-angle rotation error
        ``vee(R_ref Rᵀ − R R_refᵀ) / 2`` in base axes (the Jacobian's frame); the
        pseudo-inverse keeps the step minimal where the Jacobian is singular.
        """
        q = q.copy()
        for _ in range(steps):
            T = self.robot.fk(q, self.frame)
            J = self.robot.jacobian(q, self.frame)
            M = ref[:, :3, :3] @ np.swapaxes(T[:, :3, :3], 1, 2)
            e = np.concatenate(
                [
                    ref[:, :3, 3] - T[:, :3, 3],
                    0.5 * np.stack([M[:, 2, 1] - M[:, 1, 2], M[:, 0, 2] - M[:, 2, 0], M[:, 1, 0] - M[:, 0, 1]], axis=1),
                ],
                axis=1,
            )
            q += (np.linalg.pinv(J, rcond=1e-10) @ e[:, :, None])[:, :, 0]
        return q

    def candidates(
        self,
        targets: np.ndarray,
        q_ref: np.ndarray | None = None,
        *,
        respect_limits: bool = True,
        with_branches: bool = False,
        equivalents: bool = False,
        limit_tol: float = LIMIT_TOL,
    ) -> tuple[np.ndarray, ...]:
        """Verified solutions of a batch: ``(index (M,), q (M, nq))``, index = target row, sorted by target then distance.

        With ``respect_limits=False`` the joint limits are ignored (each revolute angle is
        given once, wrapped to ``(-π, π]``): used to tell *out of reach* from *limits*.
        With ``with_branches`` a third array ``branch (M,)`` gives each solution's branch
        label (see :meth:`pinarms.robots.Robot.ik_branches`). ``limit_tol`` [rad or m]: how far
        outside its range a joint may lie (default the solver's own :data:`LIMIT_TOL`).
        """
        robot = self.robot
        N = targets.shape[0]
        nq = robot.nq
        q_ref = robot.neutral[None, :] if q_ref is None else np.asarray(q_ref, dtype=float)
        q_ref = np.ascontiguousarray(np.broadcast_to(q_ref, (N, nq)))
        width = 8 * int(np.prod([k.size for _, k in self._shifts(limit_tol)])) if respect_limits and equivalents else 8
        chunk = max(1, min(_CHUNK, _MAX_ROWS // width))
        starts = list(range(0, N, chunk))
        parts: list = [None] * len(starts)

        def run(i: int) -> None:
            s = starts[i]
            q, valid, branch = self._dense(targets[s : s + chunk], q_ref[s : s + chunk], respect_limits, equivalents,
                                           limit_tol)
            counts = valid.sum(axis=1)
            parts[i] = (np.repeat(np.arange(s, s + q.shape[0]), counts), q[valid], branch[valid])

        if len(starts) > 1 and _WORKERS > 1:
            with ThreadPoolExecutor(max_workers=_WORKERS) as pool:
                list(pool.map(run, range(len(starts))))
        else:
            for i in range(len(starts)):
                run(i)
        if not parts:
            parts = [(np.zeros(0, dtype=int), np.zeros((0, nq)), np.zeros(0, dtype=int))]
        out = tuple(np.concatenate([p[k] for p in parts]) for k in range(3))
        return out if with_branches else out[:2]

    def starts(self, target: np.ndarray, q_ref: np.ndarray, limit_tol: float = LIMIT_TOL) -> np.ndarray:
        """Branch candidates of one target ``(4, 4)`` as starts of a local refinement: ``(k, nq)``.

        Each revolute angle is moved to its 2π equivalent within the limits nearest ``q_ref
        (nq,)``; branches that do not exist, or that no equivalent brings within the limits,
        are dropped, the rest sorted by distance to ``q_ref``. Unlike :meth:`solve` the
        candidates are *not* checked by forward kinematics (nor every 2π equivalent listed):
        :meth:`pinarms.robots.Robot.ik` refines and checks them with Pinocchio, which costs less for
        one target than the batched machinery. ``limit_tol`` [rad or m] widens the limits.
        """
        widen = limit_tol - LIMIT_TOL
        lo, hi = self.robot.lower - widen, self.robot.upper + widen
        q_ref = np.asarray(q_ref, dtype=float)
        q = self.raw(target[None], q_ref[None])[0]
        q = q[np.all(np.isfinite(q), axis=1)]
        rev = self._revolute
        if rev.any():
            lo_r, hi_r = lo[rev], hi[rev]
            centre = np.clip(q_ref[rev], lo_r, hi_r)
            nearest = q[:, rev] + _TWO_PI * np.round((centre - q[:, rev]) / _TWO_PI)
            options = nearest[None] + _TWO_PI * np.array([0.0, -1.0, 1.0])[:, None, None]  # (3, k, r)
            inside = (options >= lo_r - LIMIT_TOL) & (options <= hi_r + LIMIT_TOL)
            pick = np.argmin(np.where(inside, np.abs(options - q_ref[rev]), np.inf), axis=0)
            q[:, rev] = np.take_along_axis(options, pick[None], axis=0)[0]
        q = q[np.all((q >= lo - LIMIT_TOL) & (q <= hi + LIMIT_TOL), axis=1)]
        return q[argsort_tied(np.linalg.norm(q - q_ref, axis=1))]

    def solve(self, targets: np.ndarray, q_ref: np.ndarray | None = None, equivalents: bool = False,
              limit_tol: float = LIMIT_TOL) -> list[np.ndarray]:
        """The solutions within limits per target: a list of ``N`` arrays ``(k_i, nq)``, nearest to ``q_ref`` first.

        Each branch once (its angles at the 2π equivalents within the limits nearest
        ``q_ref``); with ``equivalents`` every 2π equivalent within the limits as well.
        ``limit_tol`` [rad or m]: how far outside its range a joint may lie.
        """
        idx, q = self.candidates(targets, q_ref, equivalents=equivalents, limit_tol=limit_tol)
        return split_by_target(idx, q, targets.shape[0])
