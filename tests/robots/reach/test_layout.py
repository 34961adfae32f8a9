"""check_layout: reachability, IK branches and dexterity margin of a line's pick/place points."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.errors import InvalidInput
from pinarms.robots.reach.layout import check_layout, default_orientation
from pinarms.robots.reach.workspace import sample_workspace



def test_default_orientation_points_the_tool_down_for_six_axis_arms():
    aubo = robots.load("aubo_i3")
    R = default_orientation(aubo)
    np.testing.assert_allclose(R @ [0, 0, 1], [0, 0, -1])
    scara = robots.load("scara_mushroom")
    np.testing.assert_allclose(default_orientation(scara), scara.fk(scara.neutral)[:3, :3])


@pytest.mark.parametrize(
    "points, match",
    [(np.zeros((2, 2)), "positions"), (np.full((1, 3), np.nan), "finite"), (np.zeros((0, 3)), "non-empty")],
)
def test_bad_points_raise_invalid_input(points, match):
    with pytest.raises(InvalidInput, match=match):
        check_layout(robots.load("aubo_i3"), points)


def test_names_must_match_points():
    with pytest.raises(InvalidInput, match="2 names for 1 points"):
        check_layout(robots.load("aubo_i3"), [[0.3, 0.3, 0.2]], names=["a", "b"])


def test_bad_orientation_raises_invalid_input():
    with pytest.raises(InvalidInput, match="rotation"):
        check_layout(robots.load("aubo_i3"), [[0.3, 0.3, 0.2]], orientation=np.ones((3, 3)))


@pytest.mark.parametrize("name", ["aubo_i3", "scara_mushroom", "gantry_flower", "koji_turner"])
def test_sampled_points_are_reachable_and_far_points_are_not(name):
    robot = robots.load(name)
    ws = sample_workspace(robot, n=20000, seed=0)
    q = robot.random_q(3, seed=5)
    poses = robot.fk(q)
    far = poses[0].copy()
    far[:3, 3] += 10.0  # 10 m away
    report = check_layout(robot, np.concatenate([poses, far[None]]), workspace=ws)
    assert report.reachable.tolist() == [True, True, True, False]
    assert not report.all_reachable
    for check in report.points[:3]:
        # every branch meets the target and respects the limits
        np.testing.assert_allclose(robot.fk(check.solutions)[:, :3, 3], check.target[None, :3, 3].repeat(check.n_solutions, 0), atol=1e-6)
        assert np.all(robot.within_limits(check.solutions))
        np.testing.assert_allclose(check.manipulability, robot.manipulability(check.solutions, part="position"), rtol=1e-9)
        assert check.manipulability[check.best] == check.manipulability.max()
        assert check.dexterity_ratio == pytest.approx(check.manipulability.max() / report.median_manipulability)
    assert report.points[3].best == -1 and report.points[3].boundary_margin == 0.0
    assert "UNREACHABLE" in report.text()


def test_position_only_targets_of_the_koji_arm_search_the_free_yaw():
    """The koji wrist carries the tool 0.25 m off its axis: a reachable position needs a matching yaw."""
    koji = robots.load("koji_turner")
    q = koji.random_q(12, seed=5)
    ws = sample_workspace(koji, n=20000, seed=0)
    report = check_layout(koji, koji.position(q), workspace=ws)
    assert report.all_reachable  # every position is the FK of some q: it is reachable
    for check, p in zip(report.points, koji.position(q)):
        np.testing.assert_allclose(koji.fk(check.solutions)[:, :3, 3], np.repeat(p[None], check.n_solutions, 0), atol=1e-9)
        # the tool stays vertical; its yaw is the one recorded in the target
        np.testing.assert_allclose(check.target[:3, 2], [0.0, 0.0, 1.0], atol=1e-12)
        np.testing.assert_allclose(koji.fk(check.solutions)[:, :3, :3], np.repeat(check.target[None, :3, :3], check.n_solutions, 0), atol=1e-9)


def test_branches_count_arm_configurations_not_two_pi_copies():
    ur5 = robots.load("ur5")  # joints ±360°: each configuration comes with 2π-shifted copies
    ws = sample_workspace(ur5, n=5000, seed=0)
    report = check_layout(ur5, ur5.fk(ur5.random_q(2, seed=5)), workspace=ws)
    for check in report.points:
        assert 1 <= check.n_branches <= 8 < check.n_solutions
        wrapped = (check.solutions + np.pi) % (2 * np.pi) - np.pi
        distinct = np.unique(np.round(wrapped, 6), axis=0).shape[0]
        assert check.n_branches == distinct


def test_default_margin_map_finds_interior_points():
    """Default voxel size: ~10 samples per voxel, so points inside the workspace get a margin."""
    aubo = robots.load("aubo_i3")
    ws = sample_workspace(aubo, n=100_000, seed=0)
    inside = aubo.fk(aubo.random_q(50, seed=9))
    report = check_layout(aubo, inside, workspace=ws)
    margins = np.array([p.boundary_margin for p in report.points])
    assert np.mean(margins > 0) > 0.9 and np.median(margins) > 0.1


def test_bad_layout_options_raise_invalid_input():
    aubo = robots.load("aubo_i3")
    with pytest.raises(InvalidInput, match="n_seeds"):
        check_layout(aubo, [[0.3, 0.3, 0.2]], n_seeds=0)
    other = sample_workspace(robots.load("ur5"), n=500, seed=0)
    with pytest.raises(InvalidInput, match="workspace must be a Workspace sampled for this robot"):
        check_layout(aubo, [[0.3, 0.3, 0.2]], workspace=other)
    with pytest.raises(InvalidInput, match="workspace must be"):
        check_layout(aubo, [[0.3, 0.3, 0.2]], workspace=sample_workspace(aubo, n=500, seed=0, frame="flange"))
    with pytest.raises(InvalidInput, match="numbers"):
        check_layout(aubo, "conveyor")
