"""The parts of a cell as users see them: its arms (:class:`CellArm`) and fixtures (:class:`Fixture`, made of :class:`Shape` s).

:class:`~pinarms.robots.cell.Cell` holds them (:attr:`Cell.arms`, :attr:`Cell.fixtures`);
:mod:`.assembly` reads them from the cell's URDF and models.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput
from pinarms.robots.robot import Robot

__all__ = ["CellArm", "Fixture", "Shape"]


@dataclass(frozen=True, eq=False)
class CellArm:
    """One arm of a cell.

    Attributes:
        name: the arm's name in the cell (``"left"``).
        robot: the arm alone (link and joint names without the prefix, its base link as
            root): IK, limits and trajectories work on it as on any :class:`Robot`.
        base_to_world: ``(4, 4)`` pose of the arm's base frame in the world [m].
        q_slice: the arm's coordinates in the cell joint vector.
        prefix: what the arm's names carry in the cell (``"left_"``).
        model: the built-in arm it is (``"scara_mushroom"``), told from its kinematics, never
            from names (:func:`~pinarms.robots.registry.match_builtin`), or ``None``.
        states: the arm's named states ``{name: q (nq,)}`` [rad or m] from the cell
            description (each within the limits; empty when none is given: no ``home`` is implied).
        hold: the arm's configuration ``(nq,)`` whenever it does not move (the description's
            ``hold``, else :attr:`Robot.neutral`): planning, checks, cycles and sessions use it.
        frozen: ``{joint: value}`` of the joints the description freezes (no longer in ``q``).
        tcp_choice: which frame is the tool point and why, in words (``"flange + xyz (0.05, 0, 0) m,
            rpy (0, 0, 0) rad"``, ``"finger (the last link; no tcp given)"``).
    """

    name: str
    robot: Robot
    base_to_world: np.ndarray
    q_slice: slice
    prefix: str
    model: str | None
    states: Mapping[str, np.ndarray] = field(default_factory=dict)
    hold: np.ndarray | None = None
    frozen: Mapping[str, float] = field(default_factory=dict)
    tcp_choice: str = ""

    @property
    def nq(self) -> int:
        """Number of the arm's joint coordinates."""
        return self.robot.nq

    @property
    def ik_family(self) -> str | None:
        """The closed-form IK family recognised from the arm's geometry (``robot.ik_family``), or ``None``."""
        return self.robot.ik_family

    def to_world(self, pose: ArrayLike) -> np.ndarray:
        """A pose ``(4, 4)`` / ``(N, 4, 4)`` or a point ``(3,)`` / ``(N, 3)`` from the arm's base frame to the world."""
        arr = np.asarray(pose, dtype=float)
        if arr.shape[-2:] == (4, 4):
            return self.base_to_world @ arr
        if arr.shape[-1:] == (3,):
            return arr @ self.base_to_world[:3, :3].T + self.base_to_world[:3, 3]
        raise InvalidInput(f"to_world takes poses (4, 4) or points (3,), got shape {arr.shape}")

    def to_base(self, pose: ArrayLike) -> np.ndarray:
        """Inverse of :meth:`to_world`: world pose(s) or point(s) in the arm's base frame."""
        inv = np.linalg.inv(self.base_to_world)
        arr = np.asarray(pose, dtype=float)
        if arr.shape[-2:] == (4, 4):
            return inv @ arr
        if arr.shape[-1:] == (3,):
            return arr @ inv[:3, :3].T + inv[:3, 3]
        raise InvalidInput(f"to_base takes poses (4, 4) or points (3,), got shape {arr.shape}")

    def tcp_to_world(self, q_arm: ArrayLike) -> np.ndarray:
        """Pose(s) of the arm's tcp in the world for the arm's own ``q (nq,)`` / ``(N, nq)``."""
        return self.base_to_world @ self.robot.fk(q_arm)


@dataclass(frozen=True, eq=False)
class Shape:
    """One collision primitive of a fixture.

    Attributes:
        kind: ``"box"``, ``"cylinder"``, ``"sphere"``, ``"capsule"`` or ``"mesh"``.
        size: box ``(sx, sy, sz)``, cylinder and capsule ``(radius, length)`` along local
            z, sphere ``(radius,)``, mesh its scale ``(x, y, z)`` [m or 1].
        shape_to_world: ``(4, 4)`` pose of the primitive's centre (mesh: its origin).
        mesh: the mesh file as the URDF names it (``None`` for primitives).
        geometry: its name in :attr:`Cell.collision_model`.
    """

    kind: str
    size: tuple[float, ...]
    shape_to_world: np.ndarray
    mesh: str | None
    geometry: str


@dataclass(frozen=True, eq=False)
class Fixture:
    """A fixed body of the cell (a link without joints to the arms): name and shapes."""

    name: str
    shapes: tuple[Shape, ...]
