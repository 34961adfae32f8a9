"""The belt: a straight conveyor in the cell's world frame, and the place targets beside it.

Belt frame: ``u`` along the belt (the direction items travel) from its start, ``w`` across
it (to the left of the direction, 0 on the centre line), ``z`` up from the surface. An item
that crosses ``u = 0`` at time ``t0`` is at ``u = speed · (t − t0)`` at time ``t`` and
leaves the belt at ``u = length``.

Units: m, m/s, s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput
from pinarms.optim.line.numbers import finite_number

__all__ = ["Belt", "PlaceBox"]


def _vector(value: Any, what: str) -> np.ndarray:
    try:
        v = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidInput(f"{what} must be 3 numbers [m], got {value!r}") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InvalidInput(f"{what} must be 3 finite numbers [m], got {value!r}")
    v.setflags(write=False)
    return v


@dataclass(frozen=True, eq=False)
class Belt:
    """A straight belt (module doc).

    Attributes:
        origin: the start of the belt's centre line, on its surface, in the world frame [m] (3,).
        direction: the direction items travel, horizontal (3,) (normalised here).
        speed: belt speed [m/s] (> 0).
        width: belt width [m] (> 0).
        length: belt extent along ``direction`` [m] (> 0).

    Raises:
        InvalidInput: a speed ≤ 0 or NaN, a width or length ≤ 0, a direction that is zero or
            not horizontal.
    """

    origin: Any
    direction: Any = (1.0, 0.0, 0.0)
    speed: float = 0.2
    width: float = 0.3
    length: float = 3.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "origin", _vector(self.origin, "belt origin"))
        d = np.array(_vector(self.direction, "belt direction"))
        if abs(d[2]) > 1e-9 or np.linalg.norm(d) < 1e-9:
            raise InvalidInput(f"belt direction must be a non-zero horizontal vector (z = 0), got {d.tolist()}")
        d /= np.linalg.norm(d)
        d.setflags(write=False)
        object.__setattr__(self, "direction", d)
        object.__setattr__(self, "speed", finite_number(self.speed, "belt speed [m/s]", positive=True))
        object.__setattr__(self, "width", finite_number(self.width, "belt width [m]", positive=True))
        object.__setattr__(self, "length", finite_number(self.length, "belt length [m]", positive=True))

    def with_speed(self, speed: float) -> "Belt":
        """The same belt running at ``speed`` [m/s]."""
        return Belt(self.origin, self.direction, speed, self.width, self.length)

    @property
    def belt_to_world(self) -> np.ndarray:
        """(4, 4) transform of the belt frame (u along, w across to the left, z up) to the world."""
        T = np.eye(4)
        T[:3, 0] = self.direction
        T[:3, 1] = np.cross([0.0, 0.0, 1.0], self.direction)
        T[:3, 2] = [0.0, 0.0, 1.0]
        T[:3, 3] = self.origin
        return T

    @property
    def velocity(self) -> np.ndarray:
        """Belt velocity in the world frame [m/s] (3,)."""
        return self.speed * self.direction

    def to_world(self, u: ArrayLike, w: ArrayLike, z: ArrayLike = 0.0) -> np.ndarray:
        """World points (..., 3) [m] of belt coordinates ``u``, ``w``, ``z`` (broadcast)."""
        u, w, z = np.broadcast_arrays(np.asarray(u, float), np.asarray(w, float), np.asarray(z, float))
        T = self.belt_to_world
        return self.origin + u[..., None] * T[:3, 0] + w[..., None] * T[:3, 1] + z[..., None] * T[:3, 2]

    def to_belt(self, p_world: ArrayLike) -> np.ndarray:
        """Belt coordinates (..., 3) (u, w, z) [m] of world points (..., 3)."""
        T = self.belt_to_world
        d = np.asarray(p_world, dtype=float) - self.origin
        return np.stack([d @ T[:3, 0], d @ T[:3, 1], d @ T[:3, 2]], axis=-1)

    def as_dict(self) -> dict[str, Any]:
        return {"origin_m": self.origin.tolist(), "direction": self.direction.tolist(), "speed_m_s": self.speed,
                "width_m": self.width, "length_m": self.length}


@dataclass(frozen=True, eq=False)
class PlaceBox:
    """A fixed place target: where the tcp releases an item, in the world frame [m] (3,).

    Attributes:
        position: release point of the tcp (world, m), above the box floor.
        name: a label for reports.
    """

    position: Any
    name: str = "box"

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", _vector(self.position, f"place box {self.name!r} position"))
