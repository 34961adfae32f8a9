"""Continuous joints in plan_motion take the short way across ±π (issue 36, finding 6).

A two-joint arm (a revolute lift and a continuous wrist about the vertical, its hand a box) under
a fixed shelf that leaves 40 mm above the hand: the wrist from 3.0 rad to -3.0 rad is the same pose
as 3.0 → 2π − 3.0 (a turn of 0.28 rad across π), where the long way turns 6 rad."""

from __future__ import annotations

import numpy as np
import pytest

ARM = """
  <link name="base_link"/>
  <link name="upper"><collision><geometry><box size="0.4 0.05 0.05"/></geometry></collision></link>
  <link name="hand"><collision><origin xyz="0.1 0 0.06"/><geometry><box size="0.2 0.04 0.04"/></geometry>
    </collision></link>
  <joint name="mount" type="fixed"><parent link="world"/><child link="base_link"/></joint>
  <joint name="lift" type="revolute"><parent link="base_link"/><child link="upper"/>
    <axis xyz="0 1 0"/><origin xyz="0 0 0.3"/><limit lower="-1.5" upper="1.5" effort="20" velocity="1"/></joint>
  <joint name="wrist" type="continuous"><parent link="upper"/><child link="hand"/>
    <axis xyz="0 0 1"/><origin xyz="0.4 0 0"/><limit effort="5" velocity="2"/></joint>
"""
#: a shelf whose bottom is 40 mm above the hand's top (z 0.38 m) over x 0.2 … 0.35 m: the hand passes under it
SHELF = """
  <link name="shelf"><collision><geometry><box size="0.15 0.2 0.04"/></geometry></collision></link>
  <joint name="shelf_mount" type="fixed"><parent link="world"/><child link="shelf"/>
    <origin xyz="0.275 0 0.44"/></joint>
"""


@pytest.fixture(scope="module")
def shelf_cell(tmp_path_factory):
    import re

    from pinarms.robots.cell import load_cell

    body = re.sub(r'(name|link)="(?!world)([^"]+)"', r'\1="arm_\2"', ARM)
    path = tmp_path_factory.mktemp("shelf_cell") / "shelf_cell.urdf"
    path.write_text(f'<robot name="shelf_cell"><link name="world"/>{body}{SHELF}</robot>')
    return load_cell(path)


def _plan(cell, start, goal):
    from pinarms.optim.motion import MotionLimits, MotionOptions, MotionRequest, plan_motion

    request = MotionRequest(cell, "arm", np.array(start), np.array(goal), options=MotionOptions(seed=0),
                            limits=MotionLimits(amax=1.0, torque=False))
    return plan_motion(request)


def test_the_cell_has_a_continuous_wrist_under_the_shelf(shelf_cell):
    assert shelf_cell.robot.continuous.tolist() == [False, True]
    assert [f.name for f in shelf_cell.fixtures] == ["shelf"]


def test_the_wrist_from_3_to_minus_3_turns_across_pi(shelf_cell):
    plan = _plan(shelf_cell, [0.0, 3.0], [0.0, -3.0])
    assert plan.status.name == "SOLVED"
    q = np.asarray(plan.trajectory.sample(np.linspace(plan.trajectory.start_time, plan.trajectory.end_time, 400))[0])
    travel = np.abs(np.diff(q[:, 1])).sum()
    assert f"{travel:.3f}" == f"{2.0 * np.pi - 6.0:.3f}"  # 0.283 rad, not 6 rad
    assert q[0, 1] == pytest.approx(3.0, abs=1e-9)
    assert q[-1, 1] == pytest.approx(2.0 * np.pi - 3.0, abs=1e-9)  # the goal's angle nearest the start, unwrapped
    assert np.all(q[:, 1] >= 3.0 - 1e-9)  # across π, never back through 0
    assert plan.trajectory.end_time - plan.trajectory.start_time < 1.2  # bang-bang over 0.283 rad at 1 rad/s²: 1.06 s
    assert plan.check.collision_free  # the cell's own re-check proves the unwrapped motion clear
    assert f"{plan.clearance.min_environment * 1e3:.1f}" == "40.0"  # the hand under the shelf, at its true pose


def test_ends_beyond_one_turn_are_accepted_and_kept_unwrapped(shelf_cell):
    """A start at 10 rad and a goal at -9 rad (the same pose as 9.8496 rad): planned from 10 rad, 0.150 rad."""
    plan = _plan(shelf_cell, [0.0, 10.0], [0.0, -9.0])
    assert plan.status.name == "SOLVED" and plan.check.collision_free
    tr = plan.trajectory
    q0, q1 = (np.asarray(tr.sample(t)[0]).reshape(-1) for t in (tr.start_time, tr.end_time))
    assert q0.tolist() == [0.0, 10.0]
    assert f"{q1[1]:.4f}" == f"{6.0 * np.pi - 9.0:.4f}" == "9.8496"
    assert f"{plan.goal[1]:.4f}" == "9.8496"  # the plan's goal: the angle the trajectory ends at


def test_checker_and_cover_see_the_same_pose_every_turn(shelf_cell):
    """Coal (Pinocchio's cos/sin of the angle) and the compiled cover give the same distances at θ and θ ± 2πk."""
    from pinarms.optim.motion.checker import MotionChecker
    from pinarms.optim.motion.fast import fast_check

    checker = MotionChecker(shelf_cell, ["arm"], margin=0.01)
    checker.span_turns(np.array([[0.0, -20.0], [0.0, 20.0]]))
    fc = fast_check(checker)
    assert fc is not None
    for theta in (2.9, 3.0, np.pi, 0.5):
        x = np.array([0.3, theta])
        turned = [x + [0.0, 2.0 * np.pi * k] for k in (-3, -1, 1, 3)]
        d = checker.closest(x)[2]
        assert all(f"{checker.closest(y)[2]:.9f}" == f"{d:.9f}" for y in turned)
        e = fc.excess(x)
        assert all(f"{fc.excess(y):.9f}" == f"{e:.9f}" for y in turned)
        np.testing.assert_allclose(shelf_cell.robot.fk(x), shelf_cell.robot.fk(turned[-1]), atol=1e-12)
    assert f"{checker.closest(np.array([0.0, np.pi]))[2] * 1e3:.1f}" == "40.0"  # under the shelf
    assert f"{checker.closest(np.array([0.0, 0.0]))[2] * 1e3:.1f}" == "64.0"  # pointing away: hypot(50, 40) mm


@pytest.fixture(scope="module")
def two_cell(tmp_path_factory):
    """Two of the arms side by side (``a`` at the origin, ``b`` 0.9 m along y), no shelf."""
    import re

    from pinarms.robots.cell import load_cell

    arms = []
    for name, y in (("a", 0.0), ("b", 0.9)):
        body = re.sub(r'(name|link)="(?!world)([^"]+)"', rf'\1="{name}_\2"', ARM)
        arms.append(body.replace(f'<child link="{name}_base_link"/></joint>',
                                 f'<child link="{name}_base_link"/><origin xyz="0 {y} 0"/></joint>'))
    path = tmp_path_factory.mktemp("two_cell") / "two_cell.urdf"
    path.write_text(f'<robot name="two_cell"><link name="world"/>{"".join(arms)}</robot>')
    return load_cell(path)


def test_planning_around_a_moving_arm_turns_the_short_way(two_cell):
    """plan_around (B around A's timed move) takes B's wrist from 3.5 rad to -2.5 rad (3.783 rad) across π."""
    from pinarms import planning
    from pinarms.optim.motion import MotionLimits, MotionOptions, MotionRequest
    from pinarms.optim.motion.two_arms import AroundRequest, plan_around

    assert [a.name for a in two_cell.arms] == ["a", "b"]
    A = planning.polynomial([0.0, 1.0], np.array([[0.0, 0.0], [0.3, 1.0]]), 5)
    request = MotionRequest(two_cell, "b", np.array([0.0, 3.5]), np.array([0.0, -2.5]),
                            options=MotionOptions(seed=0), limits=MotionLimits(amax=1.0, torque=False))
    around = plan_around(AroundRequest(request, {"a": A})).raise_for_status()
    q = np.asarray(around.trajectory.sample(np.linspace(around.trajectory.start_time, around.trajectory.end_time,
                                                        400))[0])
    assert f"{np.abs(np.diff(q[:, 1])).sum():.3f}" == f"{2.0 * np.pi - 6.0:.3f}"
    assert f"{q[-1, 1]:.4f}" == f"{2.0 * np.pi - 2.5:.4f}"
    assert around.check.collision_free


def test_a_pose_goal_is_reached_the_short_way_and_exported_unwrapped(shelf_cell, tmp_path):
    """The goal as a tool pose (the hand at wrist -3.0 rad): its IK solution is taken at the angle nearest the start;
    the controller file and CSV hold the unwrapped angles the wrist turns through."""
    from pinarms.export import controller_trajectory, read_trajectory_csv, write_trajectory_csv, write_trajectory_yaml
    from pinarms.optim.motion import MotionLimits, MotionOptions, MotionRequest, plan_motion

    arm = shelf_cell.arm("arm")
    pose = arm.tcp_to_world(np.array([0.0, -3.0]))
    plan = plan_motion(MotionRequest(shelf_cell, "arm", np.array([0.0, 3.0]), pose, options=MotionOptions(seed=0),
                                     limits=MotionLimits(amax=1.0, torque=False)))
    assert plan.status.name == "SOLVED" and plan.check.collision_free
    np.testing.assert_allclose(arm.tcp_to_world(plan.goal), pose, atol=1e-6)
    assert f"{plan.goal[1]:.3f}" == f"{2.0 * np.pi - 3.0:.3f}"
    sampled = controller_trajectory(plan, 100)
    wrist = sampled.positions[:, 1]
    assert f"{wrist[0]:.4f}" == "3.0000" and f"{wrist[-1]:.3f}" == "3.283" and np.all(np.diff(wrist) >= -1e-12)
    back = read_trajectory_csv(write_trajectory_csv(tmp_path / "turn.csv", sampled))
    np.testing.assert_allclose(back.positions, sampled.positions, atol=1e-12, rtol=0)
    from pathlib import Path

    text = Path(write_trajectory_yaml(tmp_path / "turn.yaml", sampled)).read_text()
    assert "3.28" in text and "-3.0" not in text  # the JointTrajectory's last point unwrapped, never wrapped back


@pytest.fixture(scope="module")
def post_cell(tmp_path_factory):
    """The arm with its lift held within ±0.05 rad and a post from floor to ceiling at x = 0.3 m: the hand
    pointing back (wrist near π) hits it, so the wrist cannot cross π."""
    import re

    from pinarms.robots.cell import load_cell

    arm = ARM.replace('lower="-1.5" upper="1.5"', 'lower="-0.05" upper="0.05"')
    body = re.sub(r'(name|link)="(?!world)([^"]+)"', r'\1="arm_\2"', arm)
    post = ('<link name="post"><collision><geometry><box size="0.04 0.04 2.0"/></geometry></collision></link>'
            '<joint name="post_mount" type="fixed"><parent link="world"/><child link="post"/>'
            '<origin xyz="0.3 0 0.3"/></joint>')
    path = tmp_path_factory.mktemp("post_cell") / "post_cell.urdf"
    path.write_text(f'<robot name="post_cell"><link name="world"/>{body}{post}</robot>')
    return load_cell(path)


def test_a_blocked_short_way_is_planned_the_other_way_round(post_cell):
    """Wrist 2.5 → -2.5 rad: the short way (0.78 rad across π) runs into the post; the long way (5.0 rad through
    0) is planned instead, ending at -2.5 rad."""
    from pinarms.optim.motion import MotionLimits, MotionOptions, MotionRequest, plan_motion

    request = MotionRequest(post_cell, "arm", np.array([0.0, 2.5]), np.array([0.0, -2.5]),
                            options=MotionOptions(seed=0, time_limit=0.5), limits=MotionLimits(amax=1.0, torque=False))
    plan = plan_motion(request)
    assert plan.status.name == "SOLVED", plan.reason
    tr = plan.trajectory
    q = np.asarray(tr.sample(np.linspace(tr.start_time, tr.end_time, 400))[0])
    assert f"{q[-1, 1]:.4f}" == "-2.5000" and np.all(np.abs(q[:, 1]) <= 2.5 + 1e-9)  # through 0, never across π
    assert plan.check.collision_free
