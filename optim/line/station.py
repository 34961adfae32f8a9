"""A station of the line: one arm at its base beside the belt, its place box and its limits.

The arm's base frame is given in the world frame (``base_to_world``, z up: every arm of the
line stands upright). Limits: joint velocity (default the URDF's), acceleration (default
:data:`ACCELERATION_FACTOR` × velocity limit, 1/s), and joint torques with the item as
payload on the move to the box where the arm has inertials (default on when the URDF gives
masses and effort limits).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.optim.line.belt import PlaceBox
from pinarms.errors import InvalidInput

__all__ = ["Station", "ACCELERATION_FACTOR", "base_pose"]

#: Default acceleration limit per joint: this many times its velocity limit [1/s].
ACCELERATION_FACTOR = 10.0


def base_pose(x: float, y: float, z: float, yaw: float = 0.0) -> np.ndarray:
    """(4, 4) base → world of an upright arm at (x, y, z) [m] turned by ``yaw`` [rad] about z."""
    c, s = np.cos(yaw), np.sin(yaw)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:3, 3] = [x, y, z]
    return T


@dataclass(frozen=True, eq=False)
class Station:
    """One arm of the line (module doc).

    Attributes:
        name: the arm's name (named in errors and reports).
        robot: a :class:`pinarms.robots.Robot` (``robots.load(...)``).
        base_to_world: (4, 4) pose of its base in the world frame (z up).
        place: the :class:`PlaceBox` it releases items into (world frame).
        vmax, amax: joint velocity [rad/s or m/s] and acceleration limits (nq,) (None: defaults).
        torque: time the moves under the URDF's effort limits with the item as payload
            (None: when the arm has inertials and effort limits).
    """

    name: str
    robot: Any
    base_to_world: Any
    place: PlaceBox
    vmax: Any = None
    amax: Any = None
    torque: bool | None = None
    _limits: dict = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InvalidInput(f"station name must be a non-empty string, got {self.name!r}")
        T = np.array(self.base_to_world, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)) or np.abs(T[:3, 2] - [0, 0, 1]).max() > 1e-9:
            raise InvalidInput(f"base_to_world of arm {self.name!r} must be a finite (4, 4) pose of an upright base")
        T.setflags(write=False)
        object.__setattr__(self, "base_to_world", T)
        if not isinstance(self.place, PlaceBox):
            raise InvalidInput(f"place of arm {self.name!r} must be a PlaceBox")
        nq = int(self.robot.nq)
        v = np.array(self.robot.velocity_limit if self.vmax is None else self.vmax, dtype=float).reshape(-1)
        v = np.broadcast_to(v, (nq,)).copy() if v.size in (1, nq) else v
        if v.shape != (nq,) or not np.all(np.isfinite(v) & (v > 0)):
            raise InvalidInput(f"vmax of arm {self.name!r} must be {nq} positive numbers, got {self.vmax!r}")
        a = ACCELERATION_FACTOR * np.asarray(self.robot.velocity_limit, float) if self.amax is None else self.amax
        a = np.broadcast_to(np.array(a, dtype=float).reshape(-1), (nq,)).copy()
        if not np.all(np.isfinite(a) & (a > 0)):
            raise InvalidInput(f"amax of arm {self.name!r} must be {nq} positive numbers, got {self.amax!r}")
        has_dyn = bool(np.all(np.asarray(self.robot.effort_limit) > 0)) and \
            float(sum(i.mass for i in self.robot.model.inertias)) > 0.0
        torque = has_dyn if self.torque is None else bool(self.torque)
        if torque and not has_dyn:
            raise InvalidInput(f"arm {self.name!r} ({self.robot.name}) has no inertials or effort limits: torque=False")
        self._limits.update(vmax=v, amax=a, torque=torque)

    @property
    def limits(self) -> dict:
        """``{"vmax": (nq,), "amax": (nq,), "torque": bool}`` as used."""
        return self._limits

    def world_to_base(self, p_world: ArrayLike) -> np.ndarray:
        """Points (..., 3) [m] from the world frame to the arm's base frame."""
        T = self.base_to_world
        return (np.asarray(p_world, float) - T[:3, 3]) @ T[:3, :3]
