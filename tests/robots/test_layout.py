"""check_layout: reachability, IK branches and dexterity margin of a line's pick/place points."""

from __future__ import annotations

import numpy as np
import pytest

import robots
from robots.errors import InvalidInput
from robots.layout import check_layout, default_orientation
from robots.workspace import sample_workspace



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
        np.testing.assert_allclose(robot.fk(check.solutions)[:, :3, 3], check.target[None, :3, 3].repeat(check.n_branches, 0), atol=1e-6)
        assert np.all(robot.within_limits(check.solutions))
        np.testing.assert_allclose(check.manipulability, robot.manipulability(check.solutions, part="position"), rtol=1e-9)
        assert check.manipulability[check.best] == check.manipulability.max()
        assert check.dexterity_ratio == pytest.approx(check.manipulability.max() / report.median_manipulability)
    assert report.points[3].best == -1 and report.points[3].boundary_margin == 0.0
    assert "UNREACHABLE" in report.text()
