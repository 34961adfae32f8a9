"""The seeded sampling of a cell's pairs (robots/cell/pair_samples.py): the same contacts and depths as coal's
full distance sweep, in a fraction of its time on mesh arms (issue 36 item 8: 200 configurations x a few hundred
mesh pairs took 15-45 s, at every load with a cold cache)."""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin
import pytest

from pinarms.optim.motion.scenes import load_scene
from pinarms.robots.cell import pair_samples
from pinarms.robots.collision_requests import pair_probe


@pytest.fixture(scope="module")
def mesh_cell():
    """The UR5 (collision meshes) over its table and box: mesh-mesh and mesh-box pairs."""
    return load_scene("ur5_table_box")


def _sampled(cell) -> list[tuple[int, int]]:
    """The pairs the classification samples: the checked ones and those the sampling explained (coaxial)."""
    return [(p.index_a, p.index_b) for p in cell.pairs] + [
        (p.index_a, p.index_b) for p in cell.allowed if p.reason == "coaxial"]


def _full_sweep(cell, pairs, qs):
    """Reference: every pair's collision flag and coal distance at every configuration."""
    probe, gd = pair_probe(list(cell.collision_model.geometryObjects), pairs, 1e-12)
    data = cell.model.createData()
    hits, depth = np.zeros(len(pairs)), np.zeros(len(pairs))
    for q in qs:
        pin.updateGeometryPlacements(cell.model, data, probe, gd, q)
        pin.computeCollisions(probe, gd, False)
        pin.computeDistances(probe, gd)
        hit = np.array([r.isCollision() for r in gd.collisionResults])
        d = np.array([r.min_distance for r in gd.distanceResults])
        hits += hit
        depth = np.maximum(depth, np.where(hit, np.maximum(0.0, -d), 0.0))
    return hits, depth


def test_the_sampled_contacts_and_depths_equal_the_full_distance_sweep(mesh_cell, monkeypatch):
    pairs = _sampled(mesh_cell)
    monkeypatch.setattr(pair_samples, "SAMPLES", 24)  # a shorter draw: the same rule per configuration
    qs = np.atleast_2d(mesh_cell.robot.q_to_pinocchio(mesh_cell.random_q(24, seed=3)))
    # configurations with the arm folded onto the table and box: some pairs in contact
    qs[::3, 1] = 0.9
    probe = pair_probe(list(mesh_cell.collision_model.geometryObjects), pairs, 1e-12)
    got = pair_samples._measure(mesh_cell.model, mesh_cell.model.createData(), probe, qs, len(pairs))
    hits, depth = _full_sweep(mesh_cell, pairs, qs)
    assert hits.sum() > 0  # the comparison sees contacts
    np.testing.assert_array_equal(got["hits"], hits)
    np.testing.assert_allclose(got["depth"], depth, rtol=0.0, atol=1e-12)


def test_a_mesh_cell_samples_its_pairs_in_well_under_a_second_per_hundred_pairs(mesh_cell, tmp_path, monkeypatch):
    """Cold cache (an empty folder): the 200 configurations measured, not read."""
    monkeypatch.setenv("PINARMS_CACHE_DIR", str(tmp_path))
    pairs = _sampled(mesh_cell)
    objs = list(mesh_cell.collision_model.geometryObjects)
    assert len(pairs) >= 20 and any(objs[a].geometry.__class__.__name__.startswith("BVH") for a, _ in pairs)
    t0 = time.perf_counter()
    hits, depth = pair_samples.sample_pairs(mesh_cell, objs, mesh_cell.model.createData(), pairs, seed=0)
    seconds = time.perf_counter() - t0
    assert hits.shape == depth.shape == (len(pairs),) and np.all(depth >= 0.0)
    assert seconds < 2.0, f"{seconds:.2f} s for {len(pairs)} pairs x {pair_samples.SAMPLES} configurations"
