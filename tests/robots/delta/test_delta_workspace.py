"""Monte Carlo workspace and its cylinder-plus-dome description."""

from __future__ import annotations

import numpy as np

from pinarms.robots.delta import inverse_position
from pinarms.robots.delta.workspace import cylinder_dome, reachable, sample_workspace


def test_samples_are_seeded_and_reachable(delta):
    a, b = sample_workspace(delta, 2000, seed=5), sample_workspace(delta, 2000, seed=5)
    assert np.array_equal(a.points, b.points) and len(a.points) == 2000
    assert reachable(delta, a.points).all()
    assert np.abs(inverse_position(delta.geometry, a.points) - a.theta).max() < 1e-9
    assert a.points[:, 2].max() < 0.0                    # the platform hangs under the base


def test_cylinder_and_dome_lie_inside_the_workspace(delta):
    c = cylinder_dome(delta, height=0.3, dz=0.01, dr=0.01, n_azimuth=36)
    assert abs(c.height - 0.3) < 0.011 and c.diameter > 1.5 and c.dome_depth > 0.3
    rng = np.random.default_rng(2)
    n = 4000
    r = 0.5 * (c.diameter - 0.02) * np.sqrt(rng.uniform(0, 1, n))      # a grid step inside
    a = rng.uniform(0, 2 * np.pi, n)
    z = rng.uniform(c.z_bottom + 0.01, c.z_top - 0.01, n)
    assert reachable(delta, np.stack([r * np.cos(a), r * np.sin(a), z], axis=1)).all()
    # a little wider is not all reachable
    wide = np.stack([0.55 * c.diameter * np.cos(a), 0.55 * c.diameter * np.sin(a), z], axis=1)
    assert not reachable(delta, wide).all()
    assert reachable(delta, [[0.0, 0.0, c.z_dome + 1e-3]]).all()
    assert not reachable(delta, [[0.0, 0.0, c.z_dome - 0.02]]).any()
