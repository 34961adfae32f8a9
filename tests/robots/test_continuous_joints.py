"""Continuous joints as the URDF says: one angle each, no position limit, in limit checks, trajectory limits,
controller files and SRDF states (docs/ik.md, "Continuous joints"); the Kinova Jaco2's wrist at 3.23083 rad."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from pinarms import robots
from pinarms.planning import JointLimits, multi_quintic

WRIST_URDF = textwrap.dedent(
    """\
    <robot name="turner">
      <link name="base_link"/><link name="upper"/><link name="hand"/><link name="tcp"/>
      <joint name="lift" type="revolute"><parent link="base_link"/><child link="upper"/>
        <axis xyz="0 1 0"/><origin xyz="0 0 0.3"/><limit lower="-1.5" upper="1.5" effort="20" velocity="1"/></joint>
      <joint name="wrist" type="continuous"><parent link="upper"/><child link="hand"/>
        <axis xyz="0 0 1"/><origin xyz="0.4 0 0"/><limit effort="5" velocity="2"/></joint>
      <joint name="tool" type="fixed"><parent link="hand"/><child link="tcp"/><origin xyz="0.1 0 0"/></joint>
    </robot>
    """
)


@pytest.fixture(scope="module")
def turner(tmp_path_factory):
    path = tmp_path_factory.mktemp("turner") / "turner.urdf"
    path.write_text(WRIST_URDF)
    return robots.from_urdf(path)


def test_a_continuous_joint_has_no_position_limit(turner):
    assert turner.continuous.tolist() == [False, True]
    lower, upper = turner.position_limits
    assert lower.tolist() == [-1.5, -np.inf] and upper.tolist() == [1.5, np.inf]
    assert turner.lower[1] == -np.pi and turner.upper[1] == np.pi  # the one-turn window sampling wraps into
    q = np.array([0.2, 3.23083])
    assert turner.within_limits(q) and turner.limit_violations(q) == []
    assert turner.within_limits(np.array([[0.2, -7.0], [0.2, 40.0]])).tolist() == [True, True]
    assert turner.limit_violations(np.array([1.6, 3.23083])) == ["lift = 1.6 outside [-1.5, 1.5]"]
    np.testing.assert_allclose(turner.fk(q), turner.fk(q - 2.0 * np.pi), atol=1e-12)  # the same pose every turn


def test_trajectory_limits_and_controller_files_let_the_wrist_turn_past_pi(turner, tmp_path):
    from pinarms.export import controller_trajectory, read_trajectory_csv, write_trajectory_csv

    limits = JointLimits.from_robot(turner)
    assert limits.lower.tolist() == [-1.5, -np.inf] and limits.as_dict()["upper"] == [1.5, None]
    turn = multi_quintic([0.0, 4.0], np.array([[0.0, 2.5], [0.5, 4.5]]))  # the wrist through π to 4.5 rad
    assert turn.check(limits).ok
    sampled = controller_trajectory(turn, 100, robot=turner)
    assert sampled.positions[-1, 1] == pytest.approx(4.5, abs=1e-12)
    back = read_trajectory_csv(write_trajectory_csv(tmp_path / "turn.csv", sampled))
    np.testing.assert_allclose(back.positions, sampled.positions, atol=1e-12, rtol=0)
    with pytest.raises(Exception, match="lower position limit must be below upper|finite"):
        JointLimits(velocity=1.0, lower=[np.inf], upper=[2.0])


def test_kinova_jaco2_wrist_beyond_pi_is_within_its_limits():
    """The finding: the Jaco2's wrist (j2s6s200_joint_6, continuous) at 3.23083 rad was 'outside [-3.14159, 3.14159]'."""
    from pinarms.robots.registry import example_robot_data_share

    share = example_robot_data_share()
    jaco = robots.from_urdf(share / "robots" / "kinova_description" / "robots" / "kinova.urdf",
                            package_dirs=(str(share.parent),))
    assert [n for n, c in zip(jaco.joint_names, jaco.continuous) if c] == [
        "j2s6s200_joint_1", "j2s6s200_joint_4", "j2s6s200_joint_6"]
    q = np.clip(np.zeros(jaco.nq), jaco.lower, jaco.upper)
    q[5] = 3.23083
    assert jaco.limit_violations(q) == [] and jaco.within_limits(q)
    q[1] = 0.5  # joint 2 is revolute, 0.82..5.46 rad: still checked
    assert jaco.limit_violations(q) == ["j2s6s200_joint_2 = 0.5 outside [0.820305, 5.46288]"]


@pytest.fixture(scope="module")
def turner_cell(tmp_path_factory):
    """The turner as arm ``arm`` of a cell (its upper arm a box), from a file under tmp_path."""
    import re

    from pinarms.robots.cell import load_cell

    body = WRIST_URDF.split("\n", 1)[1].rsplit("</robot>", 1)[0]
    body = re.sub(r'(name|link)="([^"]+)"', r'\1="arm_\2"', body).replace(
        '<link name="arm_upper"/>',
        '<link name="arm_upper"><collision><geometry><box size="0.4 0.05 0.05"/></geometry></collision></link>')
    path = tmp_path_factory.mktemp("turner_cell") / "turner_cell.urdf"
    path.write_text('<robot name="turner_cell"><link name="world"/><joint name="arm_mount" type="fixed">'
                    f'<parent link="world"/><child link="arm_base_link"/></joint>{body}</robot>')
    return load_cell(path)


def test_srdf_state_of_a_continuous_joint_is_written_wrapped(turner_cell):
    """An SRDF state may hold the wrist at 3.23083 rad: written as the same pose in (-π, π], MoveIt's bounds."""
    from pinarms.export.srdf import srdf_text

    assert turner_cell.robot.continuous.tolist() == [False, True]
    text = srdf_text(turner_cell, states={"turned": {"arm": np.array([0.2, 3.23083])}})
    turned = text.split('group_state name="turned"')[1].split("</group_state>")[0]
    assert f'<joint name="arm_wrist" value="{3.23083 - 2.0 * np.pi!r}" />' in turned


def test_plan_motion_starts_beyond_pi_and_turns_the_short_way(turner_cell):
    """plan_motion takes a continuous joint at any angle (tests/optim/test_motion_continuous.py): from 3.23083 rad
    to 1.0 rad it turns 2.23 rad, not the same pose inside one turn first."""
    from pinarms.optim.motion import MotionLimits, MotionRequest, plan_motion

    request = MotionRequest(turner_cell, "arm", np.array([0.2, 3.23083]), np.array([0.3, 1.0]),
                            limits=MotionLimits(amax=1.0, torque=False))
    plan = plan_motion(request)
    assert plan.status.name == "SOLVED" and plan.check.collision_free
    tr = plan.trajectory
    ends = np.array([np.asarray(tr.sample(t)[0]).reshape(-1) for t in (tr.start_time, tr.end_time)])
    assert ends.round(5).tolist() == [[0.2, 3.23083], [0.3, 1.0]]
