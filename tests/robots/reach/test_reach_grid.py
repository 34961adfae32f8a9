"""The grid of a reachability map: the reach bound, the grid box, the seeded voxels and their growth."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.robots.reach.reach_grid import bounding_grid, face_neighbours, reach_bound, seed_voxels

SHOULDER = np.array([0.0, 0.0, 0.157])  # AUBO-i3: origin of the first joint [m]


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


def test_reach_bound_contains_every_sampled_tcp(aubo):
    centre, radius = reach_bound(aubo)
    p = aubo.position(aubo.random_q(20_000, seed=2))
    assert np.linalg.norm(p - centre, axis=1).max() <= radius
    np.testing.assert_allclose(centre, SHOULDER)


def test_grid_box_holds_the_bound_sphere_and_seeds_grow_by_faces_inside_it(aubo):
    grid = bounding_grid(aubo, 0.1)
    lo = grid.origin
    hi = grid.origin + np.array(grid.shape) * grid.resolution
    assert np.all(lo <= grid.centre - grid.radius) and np.all(hi >= grid.centre + grid.radius)
    assert grid.inside.size == int(np.prod(grid.shape))
    seeds = seed_voxels(aubo, grid, 5000, seed=0)
    assert seeds.size > 0 and np.all(grid.inside[seeds])  # every tool position lies in the sphere
    grown = face_neighbours(seeds[:1], grid)
    ijk = np.stack(np.unravel_index(grown, grid.shape), axis=1)
    steps = np.abs(ijk - np.stack(np.unravel_index(seeds[:1], grid.shape), axis=1)).sum(axis=1)
    assert set(steps.tolist()) <= {0, 1} and 0 in steps  # the voxel and its face neighbours only
    assert np.all(grid.inside[grown])
