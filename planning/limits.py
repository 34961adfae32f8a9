"""Kinematic limits of a set of joints, as a specification object.

A :class:`JointLimits` only *describes* limits; :meth:`pinarms.planning.Trajectory.check` and the
optimisers of :mod:`pinarms.optim` apply them. Units are SI and per joint: rad, rad/s, rad/s²,
rad/s³ for revolute joints (m, m/s, ... for prismatic ones).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning._inputs import finite_array
from pinarms.planning.errors import TrajectoryError

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot

__all__ = ["JointLimits"]

_POSITIVE = ("velocity", "acceleration", "jerk", "torque")
_FIELDS = ("velocity", "acceleration", "jerk", "lower", "upper", "torque")


@dataclass(frozen=True, eq=False)
class JointLimits:
    """Per-joint limits; scalars apply to every joint, ``None`` means "not limited".

    Attributes:
        velocity: max |qd| (rad/s or m/s), scalar or (n_joints,), > 0.
        acceleration: max |qdd| (rad/s² or m/s²), optional, > 0.
        jerk: max |qddd| (rad/s³ or m/s³), optional, > 0.
        lower, upper: position bounds (rad or m), optional; ``lower < upper``; ``-inf`` / ``inf``
            for a joint without that bound (a continuous joint: :meth:`from_robot` gives it none).
        torque: max |joint torque| (N·m, or N for prismatic joints), optional, > 0; checking it
            needs the robot whose inverse dynamics give the torques
            (:meth:`pinarms.planning.Trajectory.check` with ``robot=``).
    """

    velocity: Any
    acceleration: Any = None
    jerk: Any = None
    lower: Any = None
    upper: Any = None
    torque: Any = None

    def __post_init__(self) -> None:
        for name in _FIELDS:
            value = getattr(self, name)
            if value is None:
                if name == "velocity":
                    raise TrajectoryError("velocity limit is required (rad/s or m/s per joint)")
                continue
            arr = _bound_array(value, name) if name in ("lower", "upper") else finite_array(value, f"{name} limit")
            if arr.ndim > 1:
                raise TrajectoryError(f"{name} limit must be a scalar or a 1-D per-joint array, got shape {arr.shape}")
            if name in _POSITIVE and np.any(arr <= 0.0):
                bad = arr.reshape(-1)[np.argmax(arr.reshape(-1) <= 0.0)]
                raise TrajectoryError(f"{name} limit must be positive, got {float(bad)!r}")
            arr = arr.copy()
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
        if self.lower is not None and self.upper is not None:
            try:
                lo, hi = np.broadcast_arrays(self.lower, self.upper)
            except ValueError:
                raise TrajectoryError(
                    f"lower and upper position limits must have the same number of joints, got "
                    f"{self.lower.size} and {self.upper.size} entries"
                ) from None
            if np.any(lo >= hi):
                i = int(np.argmax(np.atleast_1d(lo >= hi)))
                raise TrajectoryError(
                    f"lower position limit must be below upper; joint {i}: "
                    f"{float(np.atleast_1d(lo)[i])!r} >= {float(np.atleast_1d(hi)[i])!r}"
                )

    def for_joints(self, name: str, n_joints: int) -> np.ndarray:
        """Limit ``name`` broadcast to (n_joints,); raises if it has a different joint count."""
        if name not in _FIELDS:
            raise TrajectoryError(f"unknown limit {name!r}; expected one of {_FIELDS}")
        arr = getattr(self, name)
        if arr is None:
            raise TrajectoryError(f"no {name} limit is set")
        if arr.ndim == 1 and arr.size not in (1, n_joints):
            raise TrajectoryError(f"{name} limit has {arr.size} entries but the trajectory has {n_joints} joints")
        return np.broadcast_to(arr.reshape(-1) if arr.ndim else arr, (n_joints,)).astype(float)

    @classmethod
    def from_robot(cls, robot: Robot, acceleration: ArrayLike | None = None, jerk: ArrayLike | None = None, torque: bool | ArrayLike | None = None) -> "JointLimits":
        """Velocity and position limits of a robot (``velocity_limit``, ``position_limits`` or ``lower``, ``upper``), plus optional ones.

        ``torque=True`` takes the URDF's joint ``effort`` limits (``robot.effort_limit``);
        a number or array gives them explicitly (N·m or N).
        """
        if torque is True:
            effort = np.asarray(robot.effort_limit, dtype=float)
            missing = [name for name, e in zip(robot.joint_names, effort) if not e > 0.0]
            if missing:
                raise TrajectoryError(
                    f"robot '{robot.name}' has no effort limit for joint(s) {missing} in its URDF: "
                    "pass torque=[...] (N·m or N per joint; on the command line --torque-max)"
                )
            torque = effort
        elif torque is False:
            torque = None
        # a Robot's position_limits: its continuous joints -inf..inf (none); a robot-like object: lower, upper
        bounds = getattr(robot, "position_limits", None) or (robot.lower, robot.upper)
        return cls(
            velocity=np.asarray(robot.velocity_limit, dtype=float),
            acceleration=acceleration,
            jerk=jerk,
            lower=np.asarray(bounds[0], dtype=float),
            upper=np.asarray(bounds[1], dtype=float),
            torque=torque,
        )

    def as_dict(self) -> dict[str, Any]:
        """JSON-able form (``None`` for unset limits)."""
        out = {k: (None if getattr(self, k) is None else getattr(self, k).tolist()) for k in _FIELDS}
        for k in ("lower", "upper"):  # no bound (a continuous joint): None, as JSON has no infinity
            arr = getattr(self, k)
            if arr is not None and not np.all(np.isfinite(arr)):
                out[k] = [x if np.isfinite(x) else None for x in np.atleast_1d(arr).tolist()]
        return out


def _bound_array(value: Any, name: str) -> np.ndarray:
    """A position bound: finite values, or ``-inf`` (lower) / ``inf`` (upper) for none; NaN and the wrong infinity refused."""
    try:
        raw = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return finite_array(value, f"{name} limit")  # raises with the project's message
    free = raw == (-np.inf if name == "lower" else np.inf)
    return np.where(free, raw, finite_array(np.where(free, 0.0, raw), f"{name} limit"))
