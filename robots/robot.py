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

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from .errors import InvalidInput, ModelError
from .kinematic_tree import KinematicTree

if TYPE_CHECKING:  # pragma: no cover
    pass

__all__ = ["Robot"]


def as_batch(values: Any, width: int, what: str) -> tuple[np.ndarray, bool]:
    """Validate ``values`` as ``(width,)`` or ``(N, width)`` finite floats.

    Returns the ``(N, width)`` array and whether the input was a single vector.
    """
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be numbers, got {values!r}") from exc
    single = arr.ndim == 1
    if single:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != width:
        raise InvalidInput(
            f"{what} must have shape ({width},) or (N, {width}), got {np.shape(values)}"
        )
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise InvalidInput(f"{what} holds a non-finite value at index {tuple(bad.tolist())}")
    return arr, single


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
        self._data = model.createData()
        self._tree = KinematicTree(model)
        self.nq: int = self._tree.nq
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
        if tcp_frame not in self.frame_names:
            raise ModelError(
                f"robot '{name}' has no frame '{tcp_frame}' to use as tcp; "
                f"frames are: {', '.join(self.frame_names)}"
            )
        self.tcp_frame = tcp_frame
        self._analytic_ik = None  # set by the registry for arms with a closed form

    # ----------------------------------------------------------------- basics
    def __repr__(self) -> str:
        return f"Robot({self.name!r}, nq={self.nq}, joints={list(self.joint_names)})"

    @property
    def frame_names(self) -> tuple[str, ...]:
        """Names of every Pinocchio frame (links, joints, fixed frames)."""
        return tuple(f.name for f in self.model.frames)

    def frame_id(self, frame: str) -> int:
        """Pinocchio id of ``frame`` (``"tcp"`` means :attr:`tcp_frame`)."""
        name = self.tcp_frame if frame == "tcp" else frame
        if not isinstance(name, str) or not self.model.existFrame(name):
            raise InvalidInput(
                f"robot '{self.name}' has no frame {frame!r}; frames are: {', '.join(self.frame_names)}"
            )
        return self.model.getFrameId(name)

    def check_q(self, q: Any) -> tuple[np.ndarray, bool]:
        """``q`` as a ``(N, nq)`` array plus a flag telling it was one ``(nq,)`` vector."""
        return as_batch(q, self.nq, f"joint vector q of '{self.name}' (joints {list(self.joint_names)})")

    def q_to_pinocchio(self, q: Any) -> np.ndarray:
        """Pinocchio's configuration vector(s) for ``q`` (continuous joints as cos/sin)."""
        arr, single = self.check_q(q)
        out = self._tree.coordinates.to_pin(arr)
        return out[0] if single else out

    @property
    def neutral(self) -> np.ndarray:
        """The zero configuration, moved inside the limits where zero is outside them."""
        return np.clip(np.zeros(self.nq), self.lower, self.upper)

    # ----------------------------------------------------------------- limits
    def within_limits(self, q: Any, tol: float = 1e-9) -> bool | np.ndarray:
        """Whether ``q`` lies within the position limits (``tol`` in rad or m); never clamps."""
        arr, single = self.check_q(q)
        ok = np.all((arr >= self.lower - tol) & (arr <= self.upper + tol), axis=1)
        return bool(ok[0]) if single else ok

    def limit_violations(self, q: Any, tol: float = 1e-9) -> list[str]:
        """Human-readable list of the joints of one ``q (nq,)`` that are out of their limits."""
        arr, single = self.check_q(q)
        if not single:
            raise InvalidInput("limit_violations takes one configuration of shape (nq,)")
        out = []
        for name, v, lo, hi in zip(self.joint_names, arr[0], self.lower, self.upper):
            if v < lo - tol or v > hi + tol:
                out.append(f"{name} = {v:.6g} outside [{lo:.6g}, {hi:.6g}]")
        return out

    def random_q(self, n: int, seed: int | np.random.Generator | None = 0) -> np.ndarray:
        """``n`` configurations ``(n, nq)`` drawn uniformly within the position limits."""
        if not isinstance(n, (int, np.integer)) or n <= 0:
            raise InvalidInput(f"number of samples n must be a positive integer, got {n!r}")
        rng = np.random.default_rng(seed)
        return rng.uniform(self.lower, self.upper, size=(int(n), self.nq))

    # ------------------------------------------------------------- kinematics
    def fk(self, q: Any, frame: str = "tcp") -> np.ndarray:
        """Pose ``T_frame_to_base``: ``(4, 4)`` for ``q (nq,)``, ``(N, 4, 4)`` for ``q (N, nq)``."""
        arr, single = self.check_q(q)
        T = self._tree.frame_pose(arr, self.frame_id(frame))
        return T[0] if single else T

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
        for k in range(arr.shape[0]):
            pin.framesForwardKinematics(self.model, self._data, qp[k])
            out[k] = self._data.oMf[fid].homogeneous
        return out[0] if single else out

    def jacobian(self, q: Any, frame: str = "tcp") -> np.ndarray:
        """Frame Jacobian ``(6, nq)`` or ``(N, 6, nq)``: base axes at the frame origin, linear rows first."""
        arr, single = self.check_q(q)
        J = self._tree.frame_jacobian(arr, self.frame_id(frame))
        return J[0] if single else J

    def manipulability(self, q: Any, frame: str = "tcp", part: str = "full") -> float | np.ndarray:
        """Yoshikawa's manipulability ``w = sqrt(det(J Jᵀ))`` of the frame Jacobian.

        Args:
            part: ``"full"`` (6 rows), ``"position"`` (3 linear rows) or ``"orientation"``.
                When the Jacobian has fewer columns than rows (an arm with fewer joints
                than task dimensions), ``w = sqrt(det(Jᵀ J))``: the volume of the velocity
                ellipsoid within the arm's own motion space.
        """
        J = self.jacobian(q, frame)
        rows = {"full": slice(0, 6), "position": slice(0, 3), "orientation": slice(3, 6)}
        if part not in rows:
            raise InvalidInput(f"part must be one of {sorted(rows)}, got {part!r}")
        J = J[..., rows[part], :]
        m, n = J.shape[-2:]
        G = J @ np.swapaxes(J, -1, -2) if m <= n else np.swapaxes(J, -1, -2) @ J
        w = np.sqrt(np.clip(np.linalg.det(G), 0.0, None))
        return float(w) if np.ndim(w) == 0 else w

    # -------------------------------------------------------- inverse kinematics
    @property
    def has_analytic_ik(self) -> bool:
        """Whether :meth:`ik_all` has a closed form for this arm."""
        return self._analytic_ik is not None
