"""A delta robot in a cell: its block of the cell joint vector and its bodies, posed from the closed form.

A delta placed in a cell description (``delta = "delta_flexpicker"``, :mod:`.delta_urdf`) is
one of the cell's arms (:attr:`Cell.arms`): its block of the joint vector holds its three motor
angles [rad] (and the tool axis' angle), nothing else. Its bodies are those of
:func:`pinarms.robots.delta.collision.collision_bodies`: each upper arm a capsule from its motor
axis to its elbow, each of the six parallelogram rods a capsule between its two ball centres,
the platform a disk, the tool a capsule from the platform centre to the tcp, every one posed
from the closed form (the platform by the forward position, every passive joint of the tree
solved, :meth:`~pinarms.robots.delta.DeltaRobot.configuration`), never from a tree with its
passive joints at zero; and the base housing, a box (the family xacro's base plate). The tool
capsule lies on the tool axis, so the tool angle moves no body.

:class:`CellDelta` holds one delta of a cell; :func:`cell_deltas` finds them. The pairs they
form with everything else, and their distances, are in :mod:`.delta_pairs`.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np

from pinarms.errors import InvalidInput
from pinarms.robots.delta import DeltaRobot, elbow_positions, forward_position
from pinarms.robots.delta.collision import PART_RADII, PLATFORM_THICKNESS

__all__ = ["CellDelta", "DeltaPart", "cell_deltas", "base_housing", "SPHERES_PER_CAPSULE"]


def base_housing(delta: DeltaRobot) -> tuple[tuple[float, float, float], float]:
    """Size ``(x, y, z)`` [m] and height of the centre [m] of a delta's base housing (the family xacro's base plate)."""
    r = delta.geometry.base_radius
    return (2.4 * r, 2.4 * r, 0.04), 0.06


@dataclass(frozen=True, eq=False)
class DeltaPart:
    """One body of a delta in a cell: ``name`` (``<arm>_<body>``, body as in
    :func:`~pinarms.robots.delta.collision.collision_bodies` or ``base``), coal ``shape``, its pose
    ``world`` (4, 4) and its bounding sphere (``centre`` (3,), ``radius``) [m]."""

    name: str
    shape: object
    world: np.ndarray
    centre: np.ndarray
    radius: float


def _sphere_radius(shape: object) -> float:
    if isinstance(shape, coal.Capsule):
        return float(shape.halfLength + shape.radius)
    if isinstance(shape, coal.Cylinder):
        return float(np.hypot(shape.radius, shape.halfLength))
    return float(np.linalg.norm(shape.halfSide))


#: Spheres covering one capsule of a delta (:attr:`CellDelta.spheres`).
SPHERES_PER_CAPSULE = 8


def _spheres(shape: object) -> tuple[np.ndarray, np.ndarray]:
    """Centres (k, 3) and radii (k,) of spheres containing ``shape`` (in its frame)."""
    if isinstance(shape, coal.Capsule):
        k, half = SPHERES_PER_CAPSULE, float(shape.halfLength)
        z = -half + (2.0 * np.arange(k) + 1.0) * half / k
        return np.stack([np.zeros(k), np.zeros(k), z], axis=1), np.full(k, float(shape.radius) + half / k)
    return np.zeros((1, 3)), np.array([_sphere_radius(shape)])


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross products of (..., 3) vectors (broadcast)."""
    a, b = np.broadcast_arrays(a, b)
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def _along(p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """(..., 4, 4) poses at the middle of p0 -> p1 (..., 3) whose z axis runs along it (coal's capsules)."""
    z = p1 - p0
    z = z / np.linalg.norm(z, axis=-1, keepdims=True)
    helper = np.where((np.abs(z[..., :1]) < 0.9), np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    x = _cross(helper, z)
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    T = np.zeros(z.shape[:-1] + (4, 4))
    T[..., :3, 0], T[..., :3, 1], T[..., :3, 2], T[..., :3, 3] = x, _cross(z, x), z, 0.5 * (p0 + p1)
    T[..., 3, 3] = 1.0
    return T


@dataclass(frozen=True, eq=False)
class CellDelta:
    """One delta of a cell.

    Attributes:
        name: the arm's name in the cell; ``delta``: the :class:`~pinarms.robots.delta.DeltaRobot`.
        base_to_world: (4, 4) pose of its base frame (motor-axis plane, z up) in the world [m].
        q_slice: its block of the cell joint vector; ``motor_cols`` (3,): the motors' columns in
            the cell vector; ``tool_col``: the tool axis' column or ``None``.
    """

    name: str
    delta: DeltaRobot
    base_to_world: np.ndarray
    q_slice: slice
    motor_cols: np.ndarray
    tool_col: int | None

    def __post_init__(self) -> None:
        g = self.delta.geometry
        drop = self.delta.tcp_position(self.delta.home()) - forward_position(g, self.delta.home()[self.delta.motor_q])
        size, _ = base_housing(self.delta)
        shapes = [("base", coal.Box(*size)), *((n, None) for n in self._moving_names(drop))]
        built = []
        for name, shape in shapes:
            if shape is None:
                kind = name.split("_")[0]
                if kind == "upper":
                    shape = coal.Capsule(PART_RADII["upper_arm"], g.upper_arm)
                elif kind == "rod":
                    shape = coal.Capsule(PART_RADII["rod"], g.forearm)
                elif kind == "platform":
                    shape = coal.Cylinder(g.platform_radius + 0.5 * g.rod_spacing, PLATFORM_THICKNESS)
                else:
                    shape = coal.Capsule(PART_RADII["tool"], float(np.linalg.norm(drop)))
            built.append((f"{self.name}_{name}", shape))
        object.__setattr__(self, "_drop", drop)
        object.__setattr__(self, "_shapes", tuple(built))
        object.__setattr__(self, "_shape_list", tuple(s for _, s in built))
        centres, radii, owner = [], [], []
        for b, (_, shape) in enumerate(built):
            c, r = _spheres(shape)
            centres.append(c), radii.append(r), owner.append(np.full(len(r), b))
        object.__setattr__(self, "_spheres", (np.vstack(centres), np.concatenate(radii), np.concatenate(owner)))

    @staticmethod
    def _moving_names(drop: np.ndarray) -> list[str]:
        names = []
        for i in (1, 2, 3):
            names += [f"upper_arm_{i}", f"rod_{i}a", f"rod_{i}b"]
        return names + ["platform"] + (["tool"] if np.linalg.norm(drop) > 1e-9 else [])

    @property
    def body_names(self) -> tuple[str, ...]:
        """Names of its bodies (``<arm>_base``, ``<arm>_upper_arm_1``, ``<arm>_rod_1a``, ... ``<arm>_platform``,
        ``<arm>_tool``), in part order."""
        return tuple(n for n, _ in self._shapes)

    @property
    def shapes(self) -> tuple[object, ...]:
        """The coal shapes of its bodies, in part order (constant: only their poses change)."""
        return self._shape_list

    @property
    def spheres(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(centres (S, 3) in their body's frame, radii (S,), body (S,))``: spheres that together contain
        every body (a capsule of half-length H and radius ρ: :data:`SPHERES_PER_CAPSULE` spheres of radius
        ρ + H / k centred on its axis, each containing its piece of the capsule), for lower bounds of distances."""
        return self._spheres

    @property
    def radii(self) -> np.ndarray:
        """Bounding-sphere radius [m] of each body about its pose's origin, in part order."""
        return np.array([_sphere_radius(s) for _, s in self._shapes])

    def theta(self, q) -> np.ndarray:
        """Motor angles [rad] of cell configuration(s) ``q``: (3,) or (N, 3)."""
        arr = np.asarray(q, dtype=float)
        return arr[..., self.motor_cols]

    def platform_to_world(self, q) -> np.ndarray:
        """Platform centre(s) [m] in the world for cell configuration(s) ``q`` (closed form): (3,) or (N, 3)."""
        p = forward_position(self.delta.geometry, self.theta(q))
        return p @ self.base_to_world[:3, :3].T + self.base_to_world[:3, 3]

    def tcp_to_world(self, q) -> np.ndarray:
        """Tool point(s) [m] in the world (the platform centre plus the tool)."""
        return self.platform_to_world(q) + self.base_to_world[:3, :3] @ self._drop

    def poses(self, theta) -> np.ndarray:
        """World poses (N, B, 4, 4) of its B bodies (:attr:`body_names` order) at motor angles ``theta`` (N, 3) [rad].

        From the closed form: elbows ``E_i`` (:func:`~pinarms.robots.delta.elbow_positions`), the
        platform centre ``p`` (:func:`~pinarms.robots.delta.forward_position`), each rod between its
        ball centres ``E_i ± (s/2) u_i`` and ``p + r e_i ± (s/2) u_i`` (where the family's frames
        ``leg{i}_rod_top_a/b`` and ``platform_ball{i}_a/b`` are once every passive joint is solved).

        Raises:
            InvalidInput: motor angles that are not finite, or that cannot be assembled.
        """
        th = np.atleast_2d(np.asarray(theta, dtype=float))
        if th.ndim != 2 or th.shape[1] != 3 or not np.all(np.isfinite(th)):
            raise InvalidInput(f"delta {self.name!r}: motor angles must be finite, shape (N, 3) [rad], got {th.shape}")
        g = self.delta.geometry
        p = forward_position(g, th)
        if np.isnan(p).any():
            row = int(np.flatnonzero(np.isnan(p[:, 0]))[0])
            raise InvalidInput(f"delta {self.name!r}: motor angles {th[row].tolist()} rad cannot be assembled")
        e, u = g.radial, g.tangential
        elbow = elbow_positions(g, th)                                     # (N, 3, 3)
        motor = g.base_radius * e                                          # (3, 3)
        half = 0.5 * g.rod_spacing * u                                     # (3, 3)
        ball = p[:, None, :] + g.platform_radius * e[None]                 # (N, 3, 3)
        n = th.shape[0]
        out = np.empty((n, len(self._shapes), 4, 4))
        out[:, 0] = np.eye(4)
        out[:, 0, 2, 3] = base_housing(self.delta)[1]
        for i in range(3):
            out[:, 1 + 3 * i] = _along(np.broadcast_to(motor[i], (n, 3)), elbow[:, i])
            out[:, 2 + 3 * i] = _along(elbow[:, i] + half[i], ball[:, i] + half[i])
            out[:, 3 + 3 * i] = _along(elbow[:, i] - half[i], ball[:, i] - half[i])
        out[:, 10] = np.eye(4)
        out[:, 10, :3, 3] = p
        if len(self._shapes) > 11:
            out[:, 11] = _along(p, p + self._drop)
        return self.base_to_world @ out

    def parts(self, theta) -> list[DeltaPart]:
        """Its bodies at motor angles ``theta`` (3,) [rad], in the world (module doc)."""
        poses = self.poses(np.asarray(theta, dtype=float).reshape(1, 3))[0]
        return [DeltaPart(name, shape, T, T[:3, 3].copy(), _sphere_radius(shape))
                for (name, shape), T in zip(self._shapes, poses)]


def cell_deltas(arms, placements) -> tuple[CellDelta, ...]:
    """The deltas among a cell's ``arms`` (:class:`~.components.CellArm`), from their ``placements``
    (:class:`~.compose_file.ArmPlacement` with ``delta`` set)."""
    from pinarms.robots.cell.delta_urdf import placed_delta

    by_name = {a.name: a for a in arms}
    out = []
    for p in placements:
        if p.delta is None or p.name not in by_name:
            continue
        arm = by_name[p.name]
        names = list(arm.robot.joint_names)
        cols = np.array([arm.q_slice.start + names.index(f"leg{i}_motor") for i in (1, 2, 3)])
        tool = arm.q_slice.start + names.index("tool") if "tool" in names else None
        out.append(CellDelta(p.name, placed_delta(p), arm.base_to_world.copy(), arm.q_slice, cols, tool))
    return tuple(out)
