"""The reachability grid of a path section: the path's breaks, equal steps, dense where the tangent turns."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.optim import SettingOutOfRange
from pinarms.optim.topp.grid import path_grid, refined_section
from pinarms.planning import JointAccelerationConstraint, JointVelocityConstraint, joint_spline


@pytest.fixture(scope="module")
def path():
    return joint_spline(np.array([[0.0, 0.0], [1.0, 0.5], [0.2, 1.5], [0.8, 0.1]]))


def test_grid_holds_the_breaks_and_the_tangent_turns_little_across_each_interval(path):
    g = path_grid(path, 0.0, path.length, path.length, 20, 0.02)
    assert g[0] == 0.0 and g[-1] == path.length and np.all(np.diff(g) > 0.0)
    assert np.isin(path.breaks, g).all()
    assert g.size > 21  # refined where the path bends
    _, dq, _ = path.sample(g[:-1], "right")
    _, dq_end, _ = path.sample(g[1:], "left")
    size = np.maximum(np.abs(dq).max(axis=1), np.abs(dq_end).max(axis=1))
    assert np.all(np.abs(dq_end - dq).max(axis=1) <= 0.02 * size)


def test_refined_section_meets_the_rows_between_grid_points(path):
    cons = (JointVelocityConstraint(1.0), JointAccelerationConstraint(2.0))
    g = path_grid(path, 0.0, path.length, path.length, 20, 0.02)
    s, x, u, f2, rounds, ratios = refined_section(path, cons, g, 0.0, 0.0, 1e-3, 8)
    assert x[0] == 0.0 and x[-1] == 0.0 and s.size >= g.size
    assert 1.0 <= f2 <= 1.0 + 1e-3 or rounds == 8
    assert 0.9 < max(ratios.values()) <= f2 * (1.0 + 1e-12)  # a limit binds (time-optimal), none beyond f²


def test_a_grid_that_would_grow_past_the_cap_is_a_named_error(path, monkeypatch):
    import pinarms.optim.topp.grid as grid

    monkeypatch.setattr(grid, "MAX_PATH_GRID_POINTS", 30)
    with pytest.raises(SettingOutOfRange, match="grew past 30 points"):
        path_grid(path, 0.0, path.length, path.length, 20, 0.001)
