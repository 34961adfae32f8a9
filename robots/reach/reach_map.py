"""A reachability map as data: :class:`ReachabilityMap` and its stored solutions (:class:`PoseSolutions`).

Built by :func:`pinarms.robots.reach.reachability.reachability_map` (its module docstring says what
a map holds and how it is computed), written and read by :mod:`pinarms.robots.reach.reach_write` and
:mod:`pinarms.robots.reach.reach_io`. Units: m, rad.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike
from scipy import ndimage

from pinarms.errors import InvalidInput
from pinarms.robots.reach.orientations import OrientationSet

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.reach.voxels import VoxelMap

__all__ = ["ReachabilityMap", "PoseSolutions", "MAX_GRID_VOXELS", "cell_centres"]

#: Most voxels the grid box may hold (the guaranteed bound of the reach at this resolution).
MAX_GRID_VOXELS = 200_000_000


def cell_centres(origin: np.ndarray, resolution: float, shape: tuple, flat: np.ndarray) -> np.ndarray:
    """Centres (N, 3) [m] of the voxels with flat indices ``flat`` in a grid of ``shape`` from corner ``origin``
    with edge ``resolution`` [m]."""
    ijk = np.stack(np.unravel_index(flat, shape), axis=1)
    return origin + (ijk + 0.5) * resolution


@dataclass(frozen=True, eq=False)
class PoseSolutions:
    """The stored IK solution of every reached pose (arrays read-only, in computation order).

    Attributes:
        voxel: ``(K,)`` grid flat index of the pose's voxel.
        orientation: ``(K,)`` index into the map's orientation set.
        q: ``(K, nq)`` joint values [rad or m] within the limits; FK meets the pose.
        manipulability: ``(K,)`` of ``q`` (the map's measure).
    """

    voxel: np.ndarray = field(repr=False)
    orientation: np.ndarray = field(repr=False)
    q: np.ndarray = field(repr=False)
    manipulability: np.ndarray = field(repr=False)

    def __post_init__(self) -> None:
        for name in ("voxel", "orientation", "q", "manipulability"):
            getattr(self, name).flags.writeable = False

    def __len__(self) -> int:
        return int(self.voxel.size)


@dataclass(frozen=True, eq=False)
class ReachabilityMap:
    """A reachability map (see the module doc). Arrays are read-only.

    Attributes:
        robot: the robot's name; ``urdf_sha256`` the SHA-256 of its URDF text; ``tcp_frame``.
        joint_names, joint_lower, joint_upper: the joints and limits [rad or m] the map used.
        solver: ``"analytic"`` (every closed-form branch) or ``"numerical"``.
        manipulability_kind: ``"full"`` or ``"position"``.
        origin: ``(3,)`` corner of voxel ``[0, 0, 0]`` [m]; ``resolution`` the voxel edge [m];
            ``shape`` the grid ``(nx, ny, nz)``. Voxel ``(i, j, k)`` has centre
            ``origin + (i + ½, j + ½, k + ½)·resolution`` and flat index
            ``(i·ny + j)·nz + k``.
        orientations: the :class:`~pinarms.robots.reach.orientations.OrientationSet` tried per voxel.
        voxels: ``(V,)`` sorted flat indices of the computed voxels (the others have index 0).
        reached: ``(V, M)`` bool, pose ``k`` of voxel ``voxels[v]`` reached.
        index: ``(V,)`` reachability index in [0, 1].
        best_manipulability: ``(V,)`` best manipulability over the voxel's poses (NaN: none).
        solutions: the stored solution per reached pose, or ``None`` (not kept).
        parameters: how the map was made (JSON-able): seed, chunking, IK options, collisions,
            bound, statistics.
        reader_wall: for a map loaded from a file, the wall its reader process was behind
            (``"landlock (ABI n)"``, ``"user nobody (no Landlock)"`` or ``"resource limits
            only"``); ``""`` for a map built here. Not saved, not compared.
    """

    robot: str
    urdf_sha256: str
    tcp_frame: str
    joint_names: tuple[str, ...]
    joint_lower: np.ndarray = field(repr=False)
    joint_upper: np.ndarray = field(repr=False)
    solver: str = "analytic"
    manipulability_kind: str = "full"
    origin: np.ndarray = field(default=None, repr=False)
    resolution: float = 0.025
    shape: tuple[int, int, int] = (0, 0, 0)
    orientations: OrientationSet = field(default=None, repr=False)
    voxels: np.ndarray = field(default=None, repr=False)
    reached: np.ndarray = field(default=None, repr=False)
    index: np.ndarray = field(default=None, repr=False)
    best_manipulability: np.ndarray = field(default=None, repr=False)
    solutions: PoseSolutions | None = field(default=None, repr=False)
    parameters: dict = field(default_factory=dict)
    reader_wall: str = field(default="", repr=False)

    def __post_init__(self) -> None:
        for name in ("joint_lower", "joint_upper", "origin", "voxels", "reached", "index", "best_manipulability"):
            getattr(self, name).flags.writeable = False

    # ------------------------------------------------------------------ sizes
    @property
    def n_voxels(self) -> int:
        """Computed voxels ``V``."""
        return int(self.voxels.size)

    @property
    def n_orientations(self) -> int:
        """Poses per voxel ``M``."""
        return self.orientations.size

    @property
    def n_poses(self) -> int:
        """Poses checked ``V·M``."""
        return self.n_voxels * self.n_orientations

    @property
    def n_reached(self) -> int:
        """Reached poses."""
        return int(np.count_nonzero(self.reached))

    @property
    def nq(self) -> int:
        """Joints of the robot."""
        return len(self.joint_names)

    def centres(self, voxels: np.ndarray | None = None) -> np.ndarray:
        """Centres ``(n, 3)`` [m] of grid flat indices (default: the computed voxels)."""
        flat = self.voxels if voxels is None else np.asarray(voxels, dtype=np.int64)
        return cell_centres(self.origin, self.resolution, self.shape, flat)

    def rows_of(self, points: ArrayLike) -> np.ndarray:
        """Row into :attr:`voxels` of the voxel holding each of ``points (N, 3)`` [m]; −1 when not computed or outside."""
        P = _points(points, "points")
        ijk = np.floor((P - self.origin) / self.resolution).astype(np.int64)
        shape = np.array(self.shape)
        inside = np.all((ijk >= 0) & (ijk < shape), axis=1)
        flat = np.where(inside, (ijk[:, 0] * shape[1] + ijk[:, 1]) * shape[2] + ijk[:, 2], -1)
        pos = np.searchsorted(self.voxels, flat)
        pos = np.minimum(pos, max(self.n_voxels - 1, 0))
        found = inside & (self.n_voxels > 0) & (self.voxels[pos] == flat) if self.n_voxels else np.zeros(P.shape[0], bool)
        return np.where(found, pos, -1)

    def index_at(self, points: ArrayLike) -> np.ndarray:
        """Reachability index ``(N,)`` of the voxels holding ``points (N, 3)`` [m] (0 outside or not computed)."""
        rows = self.rows_of(points)
        return np.where(rows >= 0, self.index[np.maximum(rows, 0)], 0.0)

    def reaches(self, poses: ArrayLike) -> np.ndarray:
        """``(N,)`` bool: does the map mark ``poses (N, 4, 4)`` reachable (their voxel, their nearest orientation)?

        For a roll-free set, a pose counts when its tool-axis direction's group is reached with
        any roll; otherwise the nearest orientation of the set must be reached. This is a
        lookup at the voxel's centre and the set's nearest orientation, not an IK solve.
        """
        T = np.asarray(poses, dtype=float).reshape(-1, 4, 4)
        rows = self.rows_of(T[:, :3, 3])
        out = np.zeros(T.shape[0], dtype=bool)
        ok = rows >= 0
        if not ok.any():
            return out
        k, _ = self.orientations.nearest(T[ok, :3, :3])
        if self.orientations.roll_free:
            g = self.orientations.group[k]
            members = self.orientations.group[None, :] == g[:, None]
            out[ok] = np.any(self.reached[rows[ok]] & members, axis=1)
        else:
            out[ok] = self.reached[rows[ok], k]
        return out

    def reachable_centres(self, min_index: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Centres ``(k, 3)`` [m] and indices ``(k,)`` of voxels with index ``> min_index``."""
        keep = self.index > float(min_index)
        return self.centres(self.voxels[keep]), self.index[keep]

    @property
    def open_faces(self) -> int:
        """Reachable computed voxels on the grid's outer faces (0: the grid holds all the reach)."""
        keep = self.index > 0
        ijk = np.stack(np.unravel_index(self.voxels[keep], self.shape), axis=1)
        edge = np.any((ijk == 0) | (ijk == np.array(self.shape) - 1), axis=1)
        return int(np.count_nonzero(edge))

    def voxel_map(self, min_index: float = 0.0) -> "VoxelMap":
        """The map as a :class:`~pinarms.robots.reach.voxels.VoxelMap` (reuse its margins and queries).

        ``count`` = reached directions of the voxel (a voxel is reachable when its index exceeds
        ``min_index``: ``min_count`` = the smallest count above it); ``mean_manipulability`` and
        ``min_manipulability`` both hold the voxel's *best* manipulability; ``margin`` the
        distance to the nearest voxel at or below ``min_index`` (minus half a voxel) [m].
        """
        from pinarms.robots.reach.voxels import VoxelMap

        G = self.orientations.n_index
        counts = np.zeros(int(np.prod(self.shape)), dtype=np.int64)
        counts[self.voxels] = np.round(self.index * G).astype(np.int64)
        min_count = int(np.floor(float(min_index) * G + 1e-9)) + 1
        w = np.full(counts.size, np.nan)
        w[self.voxels] = self.best_manipulability
        occupied = (counts >= min_count).reshape(self.shape)
        padded = np.pad(occupied, 1, constant_values=False)
        dist = ndimage.distance_transform_edt(padded)[1:-1, 1:-1, 1:-1]
        margin = np.where(occupied, (dist - 0.5) * self.resolution, 0.0)
        w = np.where(counts >= 1, w, np.nan).reshape(self.shape)
        return VoxelMap(origin=np.array(self.origin), voxel_size=float(self.resolution), count=counts.reshape(self.shape),
                        mean_manipulability=w, min_manipulability=w.copy(), margin=margin, min_count=min_count)

    def pose(self, voxel_row: int, orientation: int) -> np.ndarray:
        """The target pose ``(4, 4)`` (tool frame → base) of a voxel row and orientation."""
        T = np.eye(4)
        T[:3, :3] = self.orientations.rotations[orientation]
        T[:3, 3] = self.centres(self.voxels[[voxel_row]])[0]
        return T

    def text(self) -> str:
        """A readable summary (mm, %)."""
        lo = self.origin
        hi = self.origin + np.array(self.shape) * self.resolution
        reach = self.index > 0
        p = self.parameters
        lines = [
            f"reachability map of {self.robot} ({self.tcp_frame}), {self.resolution * 1000:g} mm voxels, "
            f"{self.solver} IK, manipulability {self.manipulability_kind}",
            f"  orientations: {self.orientations.describe()}",
            "  grid [mm]: x {:.0f}..{:.0f}, y {:.0f}..{:.0f}, z {:.0f}..{:.0f} ({} voxels)".format(
                *(v * 1000 for pair in zip(lo, hi) for v in pair), int(np.prod(self.shape))),
            f"  computed {self.n_voxels} voxels, {self.n_poses} poses; reached {self.n_reached} poses "
            f"({self.n_reached / max(self.n_poses, 1):.1%}); voxels with index > 0: {int(reach.sum())}",
            f"  mean index of reachable voxels: {float(self.index[reach].mean()) if reach.any() else 0.0:.3f}; "
            f"voxels with index ≥ 0.5: {int(np.count_nonzero(self.index >= 0.5))}",
        ]
        if "seconds" in p:
            lines.append(f"  built in {p['seconds']:.2f} s ({p.get('poses_per_second', 0):.0f} poses/s, {p.get('rounds')} rounds)")
        return "\n".join(lines)

    # ------------------------------------------------------------------ comparison and files
    def _arrays(self) -> dict[str, np.ndarray]:
        out = {
            "joint_lower": self.joint_lower, "joint_upper": self.joint_upper, "origin": self.origin,
            "rotations": self.orientations.rotations, "group": self.orientations.group,
            "voxels": self.voxels, "reached": self.reached, "index": self.index,
            "best_manipulability": self.best_manipulability,
        }
        if self.solutions is not None:
            s = self.solutions
            out.update(pose_voxel=s.voxel, pose_orientation=s.orientation, pose_q=s.q, pose_w=s.manipulability)
        return out

    def identical(self, other: "ReachabilityMap") -> bool:
        """Same metadata and bit-equal arrays (dtype, shape, bytes); timing statistics ignored."""
        if not isinstance(other, ReachabilityMap):
            return False
        meta = ("robot", "urdf_sha256", "tcp_frame", "joint_names", "solver", "manipulability_kind", "resolution", "shape")
        if any(getattr(self, k) != getattr(other, k) for k in meta):
            return False
        strip = lambda d: {k: v for k, v in d.items() if k not in ("seconds", "poses_per_second", "scheduler")}  # noqa: E731
        if strip(self.parameters) != strip(other.parameters):
            return False
        a, b = self._arrays(), other._arrays()
        return a.keys() == b.keys() and all(
            a[k].dtype == b[k].dtype and a[k].shape == b[k].shape and a[k].tobytes() == b[k].tobytes() for k in a
        )

    def save(self, path: str | os.PathLike) -> Path:
        """Write the map to an HDF5 file (atomically; see :mod:`pinarms.robots.reach.reach_io`); return the path."""
        from pinarms.robots.reach.reach_write import write_map

        return write_map(self, path)


def _points(points: Any, what: str) -> np.ndarray:
    try:
        P = np.asarray(points, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be numbers with shape (N, 3) [m], got {points!r}") from exc
    if P.ndim == 1:
        P = P[None, :]
    if P.ndim != 2 or P.shape[1] != 3 or not np.all(np.isfinite(P)):
        raise InvalidInput(f"{what} must be finite with shape (N, 3) [m], got shape {np.shape(points)}")
    return P
