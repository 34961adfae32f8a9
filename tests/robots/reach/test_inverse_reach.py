"""Inverse reachability: base poses on a plane from which every task pose is reachable."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.robots.reach.inverse_reach import IKCheck, base_placements, tool_down_poses
from pinarms.errors import InvalidInput, ModelError
from pinarms.robots.reach.reachability import reachability_map


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


@pytest.fixture(scope="module")
def down_map(aubo):
    return reachability_map(aubo, 0.08, 6, tool_down=np.radians(15), roll_steps=6)


def _station(tool_axis):
    """Picks along 0.4 m of conveyor and four places in a crate, tool down (world frame, m)."""
    picks = np.column_stack([np.full(5, 1.0), np.linspace(-0.2, 0.2, 5), np.full(5, 0.10)])
    places = np.array([[0.55, 0.55, 0.05], [0.65, 0.55, 0.05], [0.55, 0.65, 0.05], [0.65, 0.65, 0.05]])
    return tool_down_poses(np.vstack([picks, places]), tool_axis)


def test_the_best_base_reaches_every_task_by_an_independent_ik(aubo, down_map):
    tasks = _station(down_map.orientations.tool_axis)
    bp = base_placements(down_map, tasks, z=0.0, yaw_step=np.radians(30), check=IKCheck(aubo, verify=10))
    assert len(bp) > 10 and bp.verified[:3].all()
    B = bp.poses(1)[0]
    rolls = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    axis = down_map.orientations.tool_axis
    for T in tasks:  # any roll about the tool axis will do
        T_b = np.linalg.inv(B) @ T
        assert any(aubo.ik_all(_roll(T_b, axis, r)).shape[0] > 0 for r in rolls)
    # the grid is aligned on the step and the ranking puts the highest index sum first
    np.testing.assert_allclose(np.round(bp.candidates[:, :2] / bp.xy_step), bp.candidates[:, :2] / bp.xy_step, atol=1e-9)
    assert bp.index_sum[0] == bp.index_sum[bp.verified].max()
    assert 0 < bp.index_mean[0] <= 1


def _roll(T, axis, angle):
    from pinarms.robots.so3 import about as rotations_about

    out = T.copy()
    out[:3, :3] = T[:3, :3] @ rotations_about(np.asarray(axis, float), np.array([angle]))[0]
    return out


def test_tasks_too_far_apart_have_no_base(aubo, down_map):
    tasks = tool_down_poses([[0.0, 0.0, 0.1], [3.0, 0.0, 0.1]], down_map.orientations.tool_axis)
    bp = base_placements(down_map, tasks, check=IKCheck(aubo, verify=5))
    assert len(bp) == 0 and bp.best is None and bp.n_grid > 0


def test_candidates_stay_within_reach_of_every_task(aubo, down_map):
    tasks = _station(down_map.orientations.tool_axis)
    bp = base_placements(down_map, tasks)
    d = np.hypot(bp.candidates[:, None, 0] - tasks[None, :, 0, 3], bp.candidates[:, None, 1] - tasks[None, :, 1, 3])
    assert d.max() < 0.85
    assert not bp.checked.any()


def test_a_map_of_another_robot_is_refused(down_map):
    with pytest.raises(ModelError, match="built for 'aubo_i3'"):
        base_placements(down_map, _station([0, 0, 1]), check=IKCheck(robots.load("ur5")))
    with pytest.raises(InvalidInput, match="IKCheck needs the robot="):
        IKCheck(None)
    with pytest.raises(InvalidInput, match="verify must be a non-negative integer"):
        IKCheck(robots.load("aubo_i3"), verify=-1)
    with pytest.raises(InvalidInput, match="check must be a robots.reach.inverse_reach.IKCheck, got dict"):
        base_placements(down_map, _station([0, 0, 1]), check={"verify": 0})
    with pytest.raises(InvalidInput, match="proper rotation"):
        base_placements(down_map, np.ones((1, 4, 4)))


def test_candidates_feed_search_layout_directly(aubo, down_map):
    from pinarms import optim

    pick, place = np.array([0.45, 0.0, 0.1]), np.array([0.0, 0.45, 0.1])
    tasks = tool_down_poses(np.vstack([pick, pick + [0, 0, 0.05], place, place + [0, 0, 0.05]]),
                            down_map.orientations.tool_axis)
    bp = base_placements(down_map, tasks, z=0.0, yaw_step=2 * np.pi, check=IKCheck(aubo, verify=3))
    assert bp.verified[:3].all() and np.all(bp.candidates[:, 3] == 0.0)
    res = optim.search_layout(optim.LayoutRequest(aubo, pick, place, bp.candidates[:3], lift=0.05, refine=0))
    assert res.ok.all() and res.best_picks_per_minute > 0
