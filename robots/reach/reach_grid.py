"""The grid of a reachability map: a guaranteed bound of the reach, and how the computed voxels grow.

:func:`reach_bound` bounds every position of the tool by a sphere; :func:`bounding_grid` is the
sphere's bounding box on a grid of edge ``resolution`` aligned so that voxel centres lie at
``(i + ½)·resolution``; :func:`seed_voxels` marks the voxels seeded joint samples enter, and
:func:`face_neighbours` grows a set of voxels by its 6 face neighbours inside the sphere (steps 1
and 2 of the method in :mod:`pinarms.robots.reach.reachability`). Units: m.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy import ndimage

from pinarms.errors import InvalidInput, ModelError
from pinarms.robots.reach.reach_map import MAX_GRID_VOXELS, cell_centres

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.robot import Robot

__all__ = ["reach_bound", "ReachGrid", "bounding_grid", "seed_voxels", "face_neighbours"]


def reach_bound(robot: "Robot", frame: str = "tcp") -> tuple[np.ndarray, float]:
    """A sphere ``(centre (3,), radius)`` [m] that contains every position of ``frame``'s origin.

    The centre is the origin of the first joint on the chain from the base to ``frame`` (fixed
    in the base frame for a revolute first joint); the radius adds, by the triangle inequality,
    the length of every later joint placement's offset, the frame's offset from its joint, and
    the largest travel ``max(|lower|, |upper|)`` of every prismatic joint on the chain.
    """
    model = robot.model
    fid = robot.frame_id(frame)
    f = model.frames[fid]
    chain = []
    j = f.parentJoint
    while j > 0:
        chain.append(j)
        j = model.parents[j]
    chain.reverse()
    if not chain:
        raise ModelError(f"frame {frame!r} of '{robot.name}' does not move with any joint")
    centre = np.array(model.jointPlacements[chain[0]].translation, dtype=float)
    radius = float(np.linalg.norm(f.placement.translation))
    radius += sum(float(np.linalg.norm(model.jointPlacements[j].translation)) for j in chain[1:])
    tree = robot.kinematic_tree
    for j in chain:
        if tree.kind[j] == 2:  # prismatic (mimic prismatic joints move by scale·q + offset)
            q_index = tree.q_index[j]
            stroke = max(abs(robot.lower[q_index]), abs(robot.upper[q_index]))
            radius += abs(float(tree.scale[j])) * stroke + abs(float(tree.offset[j]))
    return centre, radius



@dataclass(frozen=True, eq=False)
class ReachGrid:
    """The grid box around the reach bound.

    Attributes:
        origin: ``(3,)`` corner of voxel ``[0, 0, 0]`` [m]; ``resolution`` the voxel edge [m];
            ``shape`` the grid ``(nx, ny, nz)`` (flat index ``(i·ny + j)·nz + k``).
        centre, radius: the bound sphere (:func:`reach_bound`) [m].
        inside: ``(nx·ny·nz,)`` bool, the voxel's centre lies in the sphere.
    """

    origin: np.ndarray
    resolution: float
    shape: tuple[int, int, int]
    centre: np.ndarray
    radius: float
    inside: np.ndarray


def bounding_grid(arm: "Robot", resolution: float) -> ReachGrid:
    """The grid of edge ``resolution`` [m] over the bounding box of ``arm``'s reach sphere.

    Raises:
        InvalidInput: the grid would hold more than :data:`MAX_GRID_VOXELS` voxels.
    """
    centre, radius = reach_bound(arm)
    lo_i = np.floor((centre - radius) / resolution).astype(np.int64)
    hi_i = np.ceil((centre + radius) / resolution).astype(np.int64)
    shape = tuple(int(v) for v in np.maximum(hi_i - lo_i, 1))
    n_grid = int(np.prod(shape))
    if n_grid > MAX_GRID_VOXELS:
        raise InvalidInput(
            f"resolution {resolution} m gives a grid of {n_grid} voxels around the reach of '{arm.name}' "
            f"(radius {radius:.3f} m); use a larger resolution (at most {MAX_GRID_VOXELS} voxels)"
        )
    origin = lo_i * resolution
    all_centres_inside = np.zeros(n_grid, dtype=bool)
    for start in range(0, n_grid, 1 << 21):
        flat = np.arange(start, min(n_grid, start + (1 << 21)))
        c = cell_centres(origin, resolution, shape, flat)
        all_centres_inside[flat] = np.einsum("ij,ij->i", c - centre, c - centre) <= radius * radius
    return ReachGrid(origin=origin, resolution=resolution, shape=shape, centre=centre, radius=radius,
                     inside=all_centres_inside)


def seed_voxels(robot: "Robot", grid: ReachGrid, n: int, seed: int) -> np.ndarray:
    """Grid flat indices entered by the tool in ``n`` seeded joint samples (streamed in blocks)."""
    origin, resolution, shape = grid.origin, grid.resolution, grid.shape
    size = int(np.prod(shape))
    hit = np.zeros(size, dtype=bool)
    rng = np.random.default_rng([int(seed), 0x5EED])
    dims = np.array(shape)
    for start in range(0, n, 200_000):
        m = min(200_000, n - start)
        q = rng.uniform(robot.lower, robot.upper, size=(m, robot.nq))
        p = robot.position(q)
        ijk = np.floor((p - origin) / resolution).astype(np.int64)
        ok = np.all((ijk >= 0) & (ijk < dims), axis=1)
        ijk = ijk[ok]
        hit[(ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]] = True
    return np.flatnonzero(hit)


def face_neighbours(flat: np.ndarray, grid: ReachGrid) -> np.ndarray:
    """``flat`` and its 6 face neighbours, restricted to the voxels inside the bound sphere."""
    shape = grid.shape
    cells = np.zeros(int(np.prod(shape)), dtype=bool)
    cells[flat] = True
    grown = ndimage.binary_dilation(cells.reshape(shape), structure=ndimage.generate_binary_structure(3, 1))
    return np.flatnonzero(grown.reshape(-1) & grid.inside)
