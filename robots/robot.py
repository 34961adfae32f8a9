"""The :class:`Robot`: a URDF loaded into Pinocchio, with batched kinematics in SI units.

Conventions
-----------
- ``q`` holds one value per *independent* joint (rad for revolute, m for prismatic), in
  the order of :attr:`Robot.joint_names`. ``<mimic>`` joints are not coordinates: they
  follow their master. A single configuration has shape ``(nq,)``, a batch ``(N, nq)``.
- Poses are homogeneous transforms *frame → base*, i.e. ``T_frame_to_base`` (the base
  is the URDF's root link), shape ``(4, 4)`` or ``(N, 4, 4)``.
- Jacobians are ``(6, nq)`` (or ``(N, 6, nq)``), expressed in the base axes at the
  frame's origin (Pinocchio's ``LOCAL_WORLD_ALIGNED``), linear rows first, with respect
  to the independent joints.
"""

from __future__ import annotations

import math
from math import isfinite as _isfinite
import threading
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from scipy.linalg.lapack import dpotrf as _potrf

from ._checks import as_batch as _as_batch
from ._checks import as_generator as _as_generator
from ._checks import check_seed as _check_seed
from ._checks import check_tolerance as _check_tolerance
from .errors import InvalidInput, ModelError, UnreachableTarget
from .ik.numerical import NumericalIK
from .ik.solver import LIMIT_TOL, split_by_target
from .kinematic_tree import KinematicTree

__all__ = ["Robot", "MAX_RANDOM_SAMPLES"]

MAX_RANDOM_SAMPLES = 50_000_000
"""Most configurations :meth:`Robot.random_q` (and so ``sample_workspace``) draws at once (about 5 GB of work)."""

#: Batches of at most this many configurations are evaluated by one Pinocchio call per
#: configuration (about 1-2 µs each); larger ones by the batched numpy evaluation, whose
#: fixed cost (about 100 µs) pays from a few dozen configurations on.
SMALL_BATCH = 24

_F64 = np.dtype(np.float64)
_LWA = pin.LOCAL_WORLD_ALIGNED


class _PerThread(threading.local):
    """Per-thread slot of a Robot's Pinocchio data (``model`` is the model it was made for)."""

    model = None
    data = None


_PARTS = {"full": slice(0, 6), "position": slice(0, 3), "orientation": slice(3, 6)}


def _limit_tolerance(value: Any) -> float:
    """``limit_tolerance`` checked (a finite distance ≥ 0, rad or m), at least the solvers' own 1e-9."""
    return max(_check_tolerance(value, "limit_tolerance [rad or m]"), LIMIT_TOL)


class Robot:
    """A robot arm: Pinocchio model plus batched kinematics.

    Build one with :func:`robots.load` (by name) or :func:`robots.from_urdf` (any URDF).

    Attributes:
        name: registry name, or the URDF's robot name.
        model: the Pinocchio model (``<mimic>`` joints honoured).
        nq: number of independent joints.
        joint_names: names of the independent joints, in ``q`` order.
        lower, upper: joint position limits ``(nq,)`` [rad or m].
        velocity_limit: joint speed limits ``(nq,)`` [rad/s or m/s].
        effort_limit: joint effort limits ``(nq,)`` [N·m or N].
        urdf_text: the URDF the model was built from.
        urdf_path: its file, when it came from one.
        package_dirs: folders that resolve ``package://`` mesh paths.
        tcp_frame: the frame used when ``frame="tcp"`` is asked.
    """

    def __init__(
        self,
        model: pin.Model,
        *,
        name: str,
        urdf_text: str,
        urdf_path: Path | None = None,
        package_dirs: tuple[str, ...] = (),
        tcp_frame: str = "tcp",
        description: str = "",
    ) -> None:
        self.model = model
        self.name = name
        self.urdf_text = urdf_text
        self.urdf_path = urdf_path
        self.package_dirs = tuple(package_dirs)
        self.description = description
        self._local = _PerThread()  # per-thread Pinocchio data (see _pin_data)
        self._tree = KinematicTree(model)
        self.nq: int = self._tree.nq
        coords = self._tree.coordinates
        #: Pinocchio's configuration vector is pinarms' q itself (no continuous joint)
        self._same_q = (not coords.is_unbounded.any()) and model.nq == self.nq
        self._shape1 = (self.nq,)
        self._frame_ids: dict[str, int] = {}
        for i, f in enumerate(model.frames):
            self._frame_ids.setdefault(f.name, i)  # the first frame of a name, as Pinocchio's getFrameId
        names = [""] * self.nq
        for i in range(1, model.njoints):
            j = model.joints[i]
            if "Mimic" not in j.shortname():
                names[j.idx_v] = model.names[i]
        self.joint_names: tuple[str, ...] = tuple(names)
        coords = self._tree.coordinates
        lo = np.array(model.lowerPositionLimit)[coords.idx_q_pin]
        hi = np.array(model.upperPositionLimit)[coords.idx_q_pin]
        # continuous joints: Pinocchio stores cos/sin limits; pinarms uses one turn
        lo[coords.is_unbounded] = -np.pi
        hi[coords.is_unbounded] = np.pi
        self.lower = lo
        self.upper = hi
        self.velocity_limit = np.array(model.velocityLimit, dtype=float)
        self.effort_limit = np.array(model.effortLimit, dtype=float)
        self.tcp_frame = tcp_frame
        self._analytic_ik = None  # set by the registry for arms with a closed form
        self._ik_rejected: dict[str, str] = {}  # why each closed-form family was refused (recognition)

    # ------------------------------------------------------------- threads
    # Thread-safety rule: a Robot may be shared by any number of threads. Pinocchio's Data
    # (the scratch memory of its algorithms) is the only state written during kinematics
    # and IK, and every thread gets its own, created on first use; everything else a call
    # reads (model, limits, compiled constants) is never written after construction.
    def _pin_data(self) -> pin.Data:
        """This thread's Pinocchio data of :attr:`model` (created on first use, again if the model was replaced)."""
        local = self._local
        if local.model is not self.model:
            local.data = self.model.createData()
            local.model = self.model
        return local.data

    @property
    def _data(self) -> pin.Data:
        """This thread's Pinocchio data (kept for code written before the per-thread data)."""
        return self._pin_data()

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        state.pop("_local", None)  # per-thread scratch data: never copied
        state.pop("_numerical_ik_solver", None)
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._local = _PerThread()

    # ----------------------------------------------------------------- basics
    def __repr__(self) -> str:
        return f"Robot({self.name!r}, nq={self.nq}, joints={list(self.joint_names)})"

    @property
    def frame_names(self) -> tuple[str, ...]:
        """Names of every Pinocchio frame (links, joints, fixed frames)."""
        return tuple(f.name for f in self.model.frames)

    @property
    def tcp_frame(self) -> str:
        """The frame used when ``frame="tcp"`` is asked."""
        return self._tcp_frame

    @tcp_frame.setter
    def tcp_frame(self, name: str) -> None:
        if not isinstance(name, str) or name not in self._frame_ids:
            raise ModelError(
                f"robot '{self.name}' has no frame {name!r} to use as tcp; frames are: {', '.join(self.frame_names)}"
            )
        changed = name != getattr(self, "_tcp_frame", name)
        self._tcp_frame = name
        self._frame_lookup = {**self._frame_ids, "tcp": self._frame_ids[name]}
        if changed and (self.__dict__.get("_analytic_ik") is not None or self.__dict__.get("_ik_auto", False)):
            from .ik import attach_analytic_ik  # the closed form was proven for the old tcp: recognise again

            attach_analytic_ik(self)

    def frame_id(self, frame: str) -> int:
        """Pinocchio id of ``frame`` (``"tcp"`` means :attr:`tcp_frame`)."""
        try:
            return self._frame_lookup[frame]
        except (KeyError, TypeError):
            raise InvalidInput(
                f"robot '{self.name}' has no frame {frame!r}; frames are: {', '.join(self.frame_names)}"
            ) from None

    def _one(self, q: Any) -> np.ndarray | None:
        """Pinocchio's vector for ``q`` when it is one valid float64 configuration ``(nq,)``, else ``None``.

        The fast path of the one-configuration calls; anything else (lists, batches, wrong
        shapes, NaN) goes through :meth:`check_q`, which names what is wrong.
        """
        if q.__class__ is np.ndarray and q.shape == self._shape1 and q.dtype is _F64:
            s = q.dot(q)
            if _isfinite(s):  # finite (a NaN or inf entry makes it NaN; an overflow goes the slow way)
                return q if self._same_q else self._tree.coordinates.to_pin(q)
        return None

    def check_q(self, q: Any) -> tuple[np.ndarray, bool]:
        """``q`` as a ``(N, nq)`` array plus a flag telling it was one ``(nq,)`` vector."""
        return _as_batch(q, self.nq, f"joint vector q of '{self.name}' (joints {list(self.joint_names)})")

    def q_to_pinocchio(self, q: Any) -> np.ndarray:
        """Pinocchio's configuration vector(s) for ``q`` (continuous joints as cos/sin)."""
        arr, single = self.check_q(q)
        out = self._tree.coordinates.to_pin(arr)
        return out[0] if single else out

    @property
    def joint_units(self) -> tuple[str, ...]:
        """Unit of each independent joint's position, in ``q`` order: ``"rad"`` (revolute) or ``"m"`` (prismatic)."""
        units = [""] * self.nq
        for j in self.model.joints[1:]:
            if "Mimic" not in j.shortname():
                units[j.idx_v] = "m" if j.shortname().startswith("JointModelP") else "rad"
        return tuple(units)

    @property
    def neutral(self) -> np.ndarray:
        """The zero configuration, moved inside the limits where zero is outside them."""
        return np.clip(np.zeros(self.nq), self.lower, self.upper)

    # ----------------------------------------------------------------- limits
    def within_limits(self, q: Any, tol: float = 1e-9) -> bool | np.ndarray:
        """Whether ``q`` lies within the position limits (``tol`` in rad or m); never clamps."""
        arr, single = self.check_q(q)
        tol = _check_tolerance(tol, "limit tolerance tol [rad or m]")
        ok = np.all((arr >= self.lower - tol) & (arr <= self.upper + tol), axis=1)
        return bool(ok[0]) if single else ok

    def limit_violations(self, q: Any, tol: float = 1e-9) -> list[str]:
        """Human-readable list of the joints of one ``q (nq,)`` that are out of their limits."""
        arr, single = self.check_q(q)
        if not single:
            raise InvalidInput("limit_violations takes one configuration of shape (nq,)")
        tol = _check_tolerance(tol, "limit tolerance tol [rad or m]")
        out = []
        for name, v, lo, hi in zip(self.joint_names, arr[0], self.lower, self.upper):
            if v < lo - tol or v > hi + tol:
                out.append(f"{name} = {v:.6g} outside [{lo:.6g}, {hi:.6g}]")
        return out

    def random_q(self, n: int, seed: int | np.random.Generator | None = 0) -> np.ndarray:
        """``n`` configurations ``(n, nq)`` drawn uniformly within the position limits."""
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n <= 0:
            raise InvalidInput(f"number of samples n must be a positive integer, got {n!r}")
        if n > MAX_RANDOM_SAMPLES:
            raise InvalidInput(f"n = {n:,} samples is more than {MAX_RANDOM_SAMPLES:,} at once (about "
                               f"{n * 100 / 1e9:.3g} GB of work); draw several seeded batches instead")
        rng = _as_generator(seed)
        return rng.uniform(self.lower, self.upper, size=(int(n), self.nq))

    # ------------------------------------------------------------- kinematics
    def fk(self, q: Any, frame: str = "tcp") -> np.ndarray:
        """Pose ``T_frame_to_base``: ``(4, 4)`` for ``q (nq,)``, ``(N, 4, 4)`` for ``q (N, nq)``.

        One configuration (and batches of up to :data:`SMALL_BATCH`) are evaluated by
        Pinocchio directly; larger batches by the batched evaluator (:mod:`.kinematic_tree`).
        Both agree to rounding (about 1e-15).
        """
        try:
            fid = self._frame_lookup[frame]
        except (KeyError, TypeError):
            fid = self.frame_id(frame)  # raises the named error
        if q.__class__ is np.ndarray and q.shape == self._shape1 and q.dtype is _F64 and self._same_q:
            s = q.dot(q)  # the fast path of _one, inlined (a call costs as much as the check)
            if _isfinite(s):
                local = self._local
                data = local.data if local.model is self.model else self._pin_data()
                pin.forwardKinematics(self.model, data, q)
                return pin.updateFramePlacement(self.model, data, fid).homogeneous
        x = self._one(q)
        if x is not None:
            data = self._pin_data()
            pin.forwardKinematics(self.model, data, x)
            return pin.updateFramePlacement(self.model, data, fid).homogeneous
        arr, single = self.check_q(q)
        if arr.shape[0] <= SMALL_BATCH:
            T = self._pin_poses(arr, fid)
        else:
            T = self._tree.frame_pose(arr, fid)
        return T[0] if single else T

    def _pin_poses(self, arr: np.ndarray, fid: int) -> np.ndarray:
        """Poses ``(N, 4, 4)`` of a checked batch by one Pinocchio call per configuration."""
        model, data = self.model, self._pin_data()
        qp = arr if self._same_q else self._tree.coordinates.to_pin(arr)
        out = np.empty((arr.shape[0], 4, 4))
        fk, place = pin.forwardKinematics, pin.updateFramePlacement
        for k in range(arr.shape[0]):
            fk(model, data, qp[k])
            out[k] = place(model, data, fid).homogeneous
        return out

    def position(self, q: Any, frame: str = "tcp") -> np.ndarray:
        """Origin of ``frame`` in the base frame [m]: ``(3,)`` or ``(N, 3)``."""
        T = self.fk(q, frame)
        return T[..., :3, 3]

    def fk_pinocchio(self, q: Any, frame: str = "tcp") -> np.ndarray:
        """Reference FK by Pinocchio itself, one configuration at a time (slow; for checks)."""
        arr, single = self.check_q(q)
        fid = self.frame_id(frame)
        qp = self._tree.coordinates.to_pin(arr)
        out = np.empty((arr.shape[0], 4, 4))
        data = self._pin_data()
        for k in range(arr.shape[0]):
            pin.framesForwardKinematics(self.model, data, qp[k])
            out[k] = data.oMf[fid].homogeneous
        return out[0] if single else out

    def jacobian(self, q: Any, frame: str = "tcp") -> np.ndarray:
        """Frame Jacobian ``(6, nq)`` or ``(N, 6, nq)``: base axes at the frame origin, linear rows first.

        Small batches by Pinocchio directly, large ones batched, as :meth:`fk`.
        """
        try:
            fid = self._frame_lookup[frame]
        except (KeyError, TypeError):
            fid = self.frame_id(frame)
        if q.__class__ is np.ndarray and q.shape == self._shape1 and q.dtype is _F64 and self._same_q:
            s = q.dot(q)  # the fast path of _one, inlined
            if _isfinite(s):
                local = self._local
                data = local.data if local.model is self.model else self._pin_data()
                J = pin.computeFrameJacobian(self.model, data, q, fid, _LWA)
                return J if J.ndim == 2 else J.reshape(6, 1)  # Pinocchio gives (6,) for a 1-DoF model
        x = self._one(q)
        if x is not None:
            J = pin.computeFrameJacobian(self.model, self._pin_data(), x, fid, _LWA)
            return J if J.ndim == 2 else J.reshape(6, 1)
        arr, single = self.check_q(q)
        if arr.shape[0] <= SMALL_BATCH:
            model, data = self.model, self._pin_data()
            qp = arr if self._same_q else self._tree.coordinates.to_pin(arr)
            J = np.empty((arr.shape[0], 6, self.nq))
            for k in range(arr.shape[0]):
                J[k] = pin.computeFrameJacobian(model, data, qp[k], fid, _LWA).reshape(6, -1)
        else:
            J = self._tree.frame_jacobian(arr, fid)
        return J[0] if single else J

    def manipulability(self, q: Any, frame: str = "tcp", part: str = "full") -> float | np.ndarray:
        """Yoshikawa's manipulability ``w = sqrt(det(J Jᵀ))`` of the frame Jacobian.

        Args:
            part: ``"full"`` (6 rows), ``"position"`` (3 linear rows) or ``"orientation"``.
                When the Jacobian has fewer columns than rows (an arm with fewer joints
                than task dimensions), ``w = sqrt(det(Jᵀ J))``: the volume of the velocity
                ellipsoid within the arm's own motion space.

        Returns:
            a float for one ``q (nq,)``, an array ``(N,)`` for a batch.
        """
        J = self.jacobian(q, frame)
        rows = _PARTS.get(part) if isinstance(part, str) else None
        if rows is None:
            raise InvalidInput(f"part must be one of {sorted(_PARTS)}, got {part!r}")
        J = J[..., rows, :]
        m, n = J.shape[-2:]
        if J.ndim == 2:  # one configuration: sqrt(det G) is the product of G's Cholesky diagonal
            G = J.dot(J.T) if m <= n else J.T.dot(J)
            L, info = _potrf(G, overwrite_a=1)
            if info == 0:
                return math.prod(L.diagonal().tolist())
            G = J.dot(J.T) if m <= n else J.T.dot(J)  # singular in floating point: as the batch does
            return float(np.sqrt(max(np.linalg.det(G), 0.0)))
        G = J @ np.swapaxes(J, -1, -2) if m <= n else np.swapaxes(J, -1, -2) @ J
        return np.sqrt(np.clip(np.linalg.det(G), 0.0, None))

    # -------------------------------------------------------- inverse kinematics
    @property
    def has_analytic_ik(self) -> bool:
        """Whether :meth:`ik_all` has a closed form for this arm."""
        return self._analytic_ik is not None

    @property
    def ik_family(self) -> str | None:
        """The closed-form family recognised from the arm's geometry, or ``None`` (numerical IK only).

        ``"ur_type"``, ``"scara"``, ``"gantry"`` or ``"koji"``: the kinematic structure
        (joint types, axes, offsets, lengths read from the model) matched that family and
        its closed form solved back random configurations at load (``robots.ik.recognise``).
        """
        solver = self._analytic_ik
        return None if solver is None else solver.key

    def check_target(self, target: Any, *, position_only: bool = False) -> tuple[np.ndarray, bool]:
        """Validate IK target(s): a pose ``(4, 4)`` / ``(N, 4, 4)`` frame → base [m], proper rotation.

        With ``position_only`` a position ``(3,)`` / ``(N, 3)`` [m] is accepted too.
        Returns the ``(N, 4, 4)`` array and whether a single target was given.

        Raises:
            InvalidInput: wrong shape, non-finite entries, or a rotation block that is not a
                proper rotation (orthonormal within 1e-6, determinant +1).
        """
        if target.__class__ is np.ndarray and target.shape == (4, 4) and target.dtype is _F64:
            m = target.tolist()  # one pose: the checks below in plain floats (numpy calls cost µs each)
            (a, b, c, x), (d, e, f, y), (g, h, i, z), last = m
            if all(map(math.isfinite, (a, b, c, d, e, f, g, h, i, x, y, z))) and last == [0.0, 0.0, 0.0, 1.0]:
                ortho = max(
                    abs(a * a + b * b + c * c - 1.0), abs(d * d + e * e + f * f - 1.0), abs(g * g + h * h + i * i - 1.0),
                    abs(a * d + b * e + c * f), abs(a * g + b * h + c * i), abs(d * g + e * h + f * i),
                )
                det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
                if ortho <= 1e-6 and det > 0.0:
                    return target[None], True
        try:
            if np.iscomplexobj(target):
                raise TypeError("complex numbers")
            arr = np.asarray(target, dtype=float)
        except (TypeError, ValueError) as exc:
            raise InvalidInput(f"IK target must be numbers (real), got {target!r}") from exc
        if position_only and arr.shape[-1:] == (3,) and arr.ndim in (1, 2):
            single = arr.ndim == 1
            pts = arr.reshape(-1, 3)
            arr = np.tile(np.eye(4), (pts.shape[0], 1, 1))
            arr[:, :3, 3] = pts
        else:
            single = arr.ndim == 2
            if single:
                arr = arr[None]
            if arr.ndim != 3 or arr.shape[1:] != (4, 4):
                extra = " or a position (3,)" if position_only else ""
                hint = (
                    "; for a position without orientation use Robot.ik(position, position_only=True)"
                    if not position_only and np.shape(target)[-1:] == (3,)
                    else ""
                )
                raise InvalidInput(
                    f"IK target must be a pose of shape (4, 4) or (N, 4, 4){extra}, got shape {np.shape(target)}{hint}"
                )
        if arr.shape[0] == 0:
            return arr, single
        if not np.all(np.isfinite(arr)):
            raise InvalidInput("IK target holds a non-finite value (NaN or inf)")
        if not position_only or not single or np.shape(target) == (4, 4):
            R = arr[:, :3, :3]
            ortho = np.abs(R @ np.swapaxes(R, 1, 2) - np.eye(3)).max(axis=(1, 2))
            det = np.linalg.det(R)
            bad = np.flatnonzero((ortho > 1e-6) | (det < 0.0))
            if bad.size:
                k = int(bad[0])
                raise InvalidInput(
                    f"IK target {k}: its rotation block is not a proper rotation "
                    f"(|R Rᵀ − I| = {ortho[k]:.3g}, det = {det[k]:.6g}); pass a homogeneous transform"
                )
            if np.abs(arr[:, 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max() > 1e-9:
                raise InvalidInput("IK target: the last row of a homogeneous transform must be (0, 0, 0, 1)")
        return arr, single

    def ik_all(
        self, target: Any, q_ref: Any = None, *, respect_limits: bool = True, equivalents: bool = False,
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
                joint a rounding error past its limit (see :mod:`robots.ik.near_limits`).

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

    def ik_branches(self, target: Any, q_ref: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`ik_all` of one pose ``(4, 4)`` with the branch label of every solution.

        Returns:
            ``q (k, nq)`` as :meth:`ik_all` and ``branch (k,)`` integers: the closed form's
            branch (UR-type: shoulder × wrist flip × elbow, 0-7; SCARA: elbow; koji arm:
            arm-plane candidates). Along a continuous path a solution keeps its label until
            the path crosses a singularity, so equal labels mean "the same arm
            configuration" for consecutive waypoints (see
            :func:`planning.joint_waypoints`).
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

    def _numerical_ik(self) -> NumericalIK:
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

    def ik_failure_reason(self, target: Any, *, position_only: bool = False) -> str | None:
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
        solver = self._numerical_ik()
        res = solver._solve(T[0], None, position_only=position_only, tol=1e-9, max_restarts=20, seed=0, limits=True)
        if res.success:
            return None
        free = solver._solve(T[0], None, position_only=position_only, tol=1e-9, max_restarts=20, seed=0, limits=False)
        if free.success:
            return (
                f"the {what} is within reach but needs a joint outside its limits: "
                f"{'; '.join(self._limit_diagnosis(free.q)) or 'a limit'}"
            )
        return self._unreachable_text(T[0], position_only, res)

    def _unreachable_text(self, T: np.ndarray, position_only: bool, res=None) -> str:
        if res is None:
            res = self._numerical_ik()._solve(
                T, None, position_only=position_only, tol=1e-9, max_restarts=10, seed=0, limits=False
            )
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
        target: Any,
        q_seed: Any = None,
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
        if isinstance(max_restarts, bool) or not isinstance(max_restarts, (int, np.integer)) or max_restarts < 0:
            raise InvalidInput(f"max_restarts must be a non-negative integer, got {max_restarts!r}")
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
        solver = self._numerical_ik()
        T0 = T[0]
        # compiled Levenberg–Marquardt: the first start, then the seeded restarts, in one native call
        res = solver._solve_compiled(T0, seed_q, bool(position_only), tol, int(max_restarts), seed)
        if res.success:
            return res.q if seed_q is None else solver.nearest_equivalent(res.q, seed_q)
        # not found: the interpreted solver's path (closed-form branches, restarts, a final polish) for the diagnosis
        res = solver._solve(T0, seed_q, position_only=position_only, tol=tol, max_restarts=0, seed=seed, limits=True,
                            polish=False, compiled=False)
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
        res = solver._solve(
            T0, seed_q, position_only=position_only, tol=tol, max_restarts=int(max_restarts), seed=seed, limits=True,
            first=False,
        )
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
        solver = self._numerical_ik()
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
        solver = self._numerical_ik()
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
        from .ik.numerical import IKResult

        first = IKResult(res.q[k], False, float(res.position_error[k]), float(res.rotation_error[k]), 1 + max_restarts, 0)
        exc = UnreachableTarget(
            f"{bad.size} of {N} targets not solved (indices {bad[:10].tolist()}{' ...' if bad.size > 10 else ''}); "
            f"target {k}: {self._ik_failure_text(T[k], position_only, tol, first)}"
        )
        exc.solved = ok
        exc.q = res.q
        raise exc

    # --------------------------------------------------------------- dynamics
    #: The :class:`robots.dynamics.Payload` this robot carries (``None``: the bare arm).
    payload = None

    def with_payload(self, mass: Any, com: Any = None, inertia: Any = None, frame: str | None = None) -> "Robot":
        """A copy of this robot carrying a payload (this robot is unchanged).

        ``mass`` [kg] (or a :class:`robots.dynamics.Payload`), ``com`` (3,) [m] in ``frame``
        (default the tcp), ``inertia`` (3, 3) [kg·m²] about the centre of mass (default a point
        mass). See :func:`robots.dynamics.with_payload`.
        """
        from .dynamics import with_payload

        return with_payload(self, mass, com=com, inertia=inertia, frame=frame)

    def inverse_dynamics(self, q: Any, qd: Any, qdd: Any) -> np.ndarray:
        """Joint torques [N·m or N] for ``q, qd, qdd`` (each (nq,) or (N, nq)), by Pinocchio's RNEA.

        See :func:`robots.dynamics.inverse_dynamics` (gravity along the base's −z, mimic joints
        mapped onto the independent joints).
        """
        from .dynamics import inverse_dynamics

        return inverse_dynamics(self, q, qd, qdd)

    def gravity(self, q: Any) -> np.ndarray:
        """Joint torques [N·m or N] holding ``q`` ((nq,) or (N, nq)) still against gravity."""
        from .dynamics import gravity_torques

        return gravity_torques(self, q)
