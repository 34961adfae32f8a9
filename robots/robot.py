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

from math import isfinite as _isfinite
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike
import pinocchio as pin

from pinarms.robots._checks import as_batch as _as_batch
from pinarms.robots._checks import as_generator as _as_generator
from pinarms.robots._checks import check_tolerance as _check_tolerance
from pinarms.errors import InvalidInput, ModelError
from pinarms.robots.kinematic_tree import KinematicTree
from pinarms.robots.manipulability import manipulability_of_jacobian
from pinarms.robots.robot_ik import RobotIK

if TYPE_CHECKING:
    from pinarms.robots.payload import Payload

__all__ = ["Robot", "MAX_RANDOM_SAMPLES", "ACCELERATION_RISE_TIME"]

ACCELERATION_RISE_TIME = 0.25
"""Time [s] from rest to the velocity limit under the default acceleration limit: a URDF has no
acceleration field, so :attr:`Robot.acceleration_limit` is ``velocity_limit / 0.25 s`` unless set (the
rule the built-in arms' efforts are sized by, docs/dynamics.md)."""

MAX_RANDOM_SAMPLES = 50_000_000
"""Most configurations :meth:`Robot.random_q` (and so ``sample_workspace``) draws at once (about 5 GB of work)."""

#: Batches of at most this many configurations are evaluated by one Pinocchio call per
#: configuration (about 1-2 µs each); larger ones by the batched numpy evaluation, whose
#: fixed cost (about 100 µs) pays from a few dozen configurations on.
SMALL_BATCH = 24

_F64 = np.dtype(np.float64)
_NDARRAY = np.ndarray
_LWA = pin.LOCAL_WORLD_ALIGNED
# Pinocchio's calls of the one-configuration fast paths, looked up once
_pin_fk, _pin_place, _pin_jacobian = pin.forwardKinematics, pin.updateFramePlacement, pin.computeFrameJacobian


class _PerThread(threading.local):
    """Per-thread slot of a Robot's Pinocchio data: ``pair = (model, data)``, the data and the model it was made for."""

    pair = (None, None)


class Robot(RobotIK):
    """A robot arm: Pinocchio model plus batched kinematics.

    Build one with :func:`pinarms.robots.load` (by name) or :func:`pinarms.robots.from_urdf` (any URDF).

    Attributes:
        name: registry name, or the URDF's robot name.
        model: the Pinocchio model (``<mimic>`` joints honoured).
        nq: number of independent joints.
        joint_names: names of the independent joints, in ``q`` order.
        lower, upper: joint position limits ``(nq,)`` [rad or m]; a continuous joint has none and
            holds ``±π`` here: the one-turn window that sampling and IK wrap into (limit checks
            use :attr:`position_limits`).
        continuous: continuous joints ``(nq,)`` bool (URDF ``type="continuous"``: unlimited).
        velocity_limit: joint speed limits ``(nq,)`` [rad/s or m/s].
        acceleration_limit: joint acceleration limits ``(nq,)`` [rad/s² or m/s²]: by default
            ``velocity_limit /`` :data:`ACCELERATION_RISE_TIME`; ``acceleration_source`` says which.
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
        #: shape of one configuration that Pinocchio takes as it is (None: continuous joints need conversion)
        self._pin_shape1 = self._shape1 if self._same_q else None
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
        # continuous joints: Pinocchio stores cos/sin limits; pinarms keeps one angle, no position limit,
        # and ±π as the window that sampling and IK wrap into (docs/ik.md, "Continuous joints")
        #: continuous joints ``(nq,)`` bool: one angle each (any real value, the same pose every 2π), unlimited
        self.continuous = np.array(coords.is_unbounded, dtype=bool)
        lo[self.continuous] = -np.pi
        hi[self.continuous] = np.pi
        self.lower = lo
        self.upper = hi
        self.velocity_limit = np.array(model.velocityLimit, dtype=float)
        #: joint acceleration limits [rad/s² or m/s²]: the stated default rule unless set (then say so in
        #: :attr:`acceleration_source`); 0 where the URDF gives no velocity limit
        self.acceleration_limit = self.velocity_limit / ACCELERATION_RISE_TIME
        self.acceleration_source = f"default: velocity limit / {ACCELERATION_RISE_TIME:g} s"
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
        model, data = self._local.pair
        if model is not self.model:
            data = self.model.createData()
            self._local.pair = (self.model, data)  # one assignment: the pair is always consistent
        return data

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
            from pinarms.robots.ik import attach_analytic_ik  # the closed form was proven for the old tcp: recognise again

            attach_analytic_ik(self)

    @property
    def kinematic_tree(self) -> KinematicTree:
        """The joint tree behind batched FK and Jacobians (:class:`~pinarms.robots.kinematic_tree.KinematicTree`)."""
        return self._tree

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

    def check_q(self, q: ArrayLike) -> tuple[np.ndarray, bool]:
        """``q`` as a ``(N, nq)`` array plus a flag telling it was one ``(nq,)`` vector."""
        return _as_batch(q, self.nq, f"joint vector q of '{self.name}' (joints {list(self.joint_names)})")

    def q_to_pinocchio(self, q: ArrayLike) -> np.ndarray:
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
    @property
    def position_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)`` ``(nq,)`` [rad or m] that a configuration must keep: :attr:`lower` and
        :attr:`upper` with ``∓inf`` at continuous joints (the URDF gives them no limit)."""
        return np.where(self.continuous, -np.inf, self.lower), np.where(self.continuous, np.inf, self.upper)

    def within_limits(self, q: ArrayLike, tol: float = 1e-9) -> bool | np.ndarray:
        """Whether ``q`` lies within the position limits (``tol`` in rad or m; continuous joints: any angle); never clamps."""
        arr, single = self.check_q(q)
        tol = _check_tolerance(tol, "limit tolerance tol [rad or m]")
        lower, upper = self.position_limits
        ok = np.all((arr >= lower - tol) & (arr <= upper + tol), axis=1)
        return bool(ok[0]) if single else ok

    def limit_violations(self, q: ArrayLike, tol: float = 1e-9) -> list[str]:
        """Human-readable list of the joints of one ``q (nq,)`` that are out of their limits."""
        arr, single = self.check_q(q)
        if not single:
            raise InvalidInput("limit_violations takes one configuration of shape (nq,)")
        tol = _check_tolerance(tol, "limit tolerance tol [rad or m]")
        out = []
        for name, v, lo, hi in zip(self.joint_names, arr[0], *self.position_limits):
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
    def fk(self, q: ArrayLike, frame: str = "tcp") -> np.ndarray:
        """Pose ``T_frame_to_base``: ``(4, 4)`` for ``q (nq,)``, ``(N, 4, 4)`` for ``q (N, nq)``.

        One configuration (and batches of up to :data:`SMALL_BATCH`) are evaluated by
        Pinocchio directly; larger batches by the batched evaluator (:mod:`.kinematic_tree`).
        Both agree to rounding (about 1e-15).
        """
        try:
            fid = self._frame_lookup[frame]
        except (KeyError, TypeError):
            fid = self.frame_id(frame)  # raises the named error
        # the fast path of _one, inlined (a call costs as much as the check); finite: the sum of the
        # entries as Python floats (a NaN or inf makes it non-finite; an overflow goes the slow way)
        if (q.__class__ is _NDARRAY and q.shape == self._pin_shape1 and q.dtype is _F64
                and _isfinite(sum(q.tolist()))):
            model = self.model
            made_for, data = self._local.pair
            if made_for is not model:
                data = self._pin_data()
            _pin_fk(model, data, q)
            return _pin_place(model, data, fid).homogeneous
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

    def position(self, q: ArrayLike, frame: str = "tcp") -> np.ndarray:
        """Origin of ``frame`` in the base frame [m]: ``(3,)`` or ``(N, 3)``."""
        T = self.fk(q, frame)
        return T[..., :3, 3]

    def fk_pinocchio(self, q: ArrayLike, frame: str = "tcp") -> np.ndarray:
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

    def jacobian(self, q: ArrayLike, frame: str = "tcp") -> np.ndarray:
        """Frame Jacobian ``(6, nq)`` or ``(N, 6, nq)``: base axes at the frame origin, linear rows first.

        Small batches by Pinocchio directly, large ones batched, as :meth:`fk`.
        """
        try:
            fid = self._frame_lookup[frame]
        except (KeyError, TypeError):
            fid = self.frame_id(frame)
        if (q.__class__ is _NDARRAY and q.shape == self._pin_shape1 and q.dtype is _F64
                and _isfinite(sum(q.tolist()))):  # the fast path of fk
            model = self.model
            made_for, data = self._local.pair
            if made_for is not model:
                data = self._pin_data()
            J = _pin_jacobian(model, data, q, fid, _LWA)
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

    def manipulability(self, q: ArrayLike, frame: str = "tcp", part: str = "full") -> float | np.ndarray:
        """Yoshikawa's manipulability ``w = sqrt(det(J Jᵀ))`` of the frame Jacobian.

        Args:
            part: ``"full"`` (6 rows), ``"position"`` (3 linear rows) or ``"orientation"``.
                When the Jacobian has fewer columns than rows (an arm with fewer joints
                than task dimensions), ``w = sqrt(det(Jᵀ J))``: the volume of the velocity
                ellipsoid within the arm's own motion space.

        Returns:
            a float for one ``q (nq,)``, an array ``(N,)`` for a batch
            (:func:`pinarms.robots.manipulability.manipulability_of_jacobian`).
        """
        return manipulability_of_jacobian(self.jacobian(q, frame), part)

    # --------------------------------------------------------------- dynamics
    #: The :class:`pinarms.robots.payload.Payload` this robot carries (``None``: the bare arm).
    payload = None

    def with_payload(self, mass: Payload | float, com: ArrayLike | None = None, inertia: ArrayLike | None = None,
                     frame: str | None = None) -> "Robot":
        """A copy of this robot carrying a payload (this robot is unchanged).

        ``mass`` [kg] (or a :class:`pinarms.robots.payload.Payload`), ``com`` (3,) [m] in ``frame``
        (default the tcp), ``inertia`` (3, 3) [kg·m²] about the centre of mass (default a point
        mass). See :func:`pinarms.robots.payload.with_payload`.
        """
        from pinarms.robots.payload import with_payload

        return with_payload(self, mass, com=com, inertia=inertia, frame=frame)

    def inverse_dynamics(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> np.ndarray:
        """Joint torques [N·m or N] for ``q, qd, qdd`` (each (nq,) or (N, nq)), by Pinocchio's RNEA.

        See :func:`pinarms.robots.dynamics.inverse_dynamics` (gravity along the base's −z, mimic joints
        mapped onto the independent joints).
        """
        from pinarms.robots.dynamics import inverse_dynamics

        return inverse_dynamics(self, q, qd, qdd)

    def gravity(self, q: ArrayLike) -> np.ndarray:
        """Joint torques [N·m or N] holding ``q`` ((nq,) or (N, nq)) still against gravity."""
        from pinarms.robots.dynamics import gravity_torques

        return gravity_torques(self, q)
