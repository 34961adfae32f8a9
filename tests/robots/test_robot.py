"""Robot: batched FK and Jacobians against Pinocchio and finite differences; registry; bad input."""

from __future__ import annotations

import textwrap

import numpy as np
import pinocchio as pin
import pytest

from pinarms import robots
from pinarms.robots import InvalidInput, ModelError, RobotNotFound

BUILTIN = robots.builtin_names()
EXAMPLE = ["ur5", "panda"]

MIMIC_URDF = textwrap.dedent(
    """\
    <robot name="lever">
      <link name="base_link"/><link name="a"/><link name="b"/><link name="c"/><link name="tcp"/>
      <joint name="j1" type="revolute"><parent link="base_link"/><child link="a"/>
        <axis xyz="0 1 0"/><origin xyz="0 0 0.1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="j1_follow" type="revolute"><parent link="a"/><child link="b"/>
        <axis xyz="0 1 0"/><origin xyz="0.5 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
        <mimic joint="j1" multiplier="-0.5" offset="0.1"/></joint>
      <joint name="slide" type="prismatic"><parent link="b"/><child link="c"/>
        <axis xyz="0.6 0 0.8"/><origin xyz="0.4 0 0" rpy="0.3 0.2 0.1"/><limit lower="-0.2" upper="0.3" effort="1" velocity="2"/></joint>
      <joint name="tool" type="fixed"><parent link="c"/><child link="tcp"/><origin xyz="0 0.05 0.1" rpy="0 1.0 0"/></joint>
    </robot>
    """
)


@pytest.fixture(scope="module")
def mimic_robot():
    return robots.from_urdf_text(MIMIC_URDF)


def _fd_jacobian(robot, q, h=1e-6):
    """Central differences of the tcp pose: linear velocity and world-frame angular velocity."""
    J = np.zeros((6, robot.nq))
    for k in range(robot.nq):
        dq = np.zeros(robot.nq)
        dq[k] = h
        Tp, Tm = robot.fk(q + dq), robot.fk(q - dq)
        J[:3, k] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        J[3:, k] = pin.log3(Tp[:3, :3] @ Tm[:3, :3].T) / (2 * h)
    return J


def _interior_q(robot, n, seed):
    """Random configurations kept 1e-3 away from the limits (room for finite differences)."""
    rng = np.random.default_rng(seed)
    return rng.uniform(robot.lower + 1e-3, robot.upper - 1e-3, size=(n, robot.nq))


@pytest.mark.parametrize("name", BUILTIN + EXAMPLE)
def test_batched_fk_equals_pinocchio(name):
    robot = robots.load(name)
    q = robot.random_q(300, seed=7)
    for frame in ("tcp", robot.model.frames[robot.frame_id("tcp")].name, robot.model.names[robot.model.njoints - 1]):
        assert np.abs(robot.fk(q, frame) - robot.fk_pinocchio(q, frame)).max() < 1e-12
    # a single configuration returns one (4, 4) pose
    assert robot.fk(q[0]).shape == (4, 4)


@pytest.mark.parametrize("name", BUILTIN + EXAMPLE)
def test_batched_jacobian_equals_pinocchio(name):
    """World-aligned axes at the frame origin, w.r.t. the independent joints (mimics folded in)."""
    robot = robots.load(name)
    data = robot.model.createData()
    fid = robot.frame_id("tcp")
    q = robot.random_q(20, seed=8)
    J = robot.jacobian(q)
    for k in range(len(q)):
        J_pin = pin.computeFrameJacobian(robot.model, data, robot.q_to_pinocchio(q[k]), fid, pin.LOCAL_WORLD_ALIGNED)
        assert np.abs(J[k] - J_pin).max() < 1e-12


def test_mimic_robot_counts_independent_joints_only(mimic_robot):
    assert mimic_robot.nq == 2
    assert mimic_robot.joint_names == ("j1", "slide")
    q = mimic_robot.random_q(200, seed=3)
    assert np.abs(mimic_robot.fk(q) - mimic_robot.fk_pinocchio(q)).max() < 1e-12


def test_batched_fk_across_chunks_and_threads():
    robot = robots.load("ur5")
    q = robot.random_q(70_000, seed=11)  # several chunks → the threaded path
    T = robot.fk(q)
    idx = np.random.default_rng(0).choice(len(q), 200, replace=False)
    assert np.abs(T[idx] - robot.fk_pinocchio(q[idx])).max() < 1e-12


@pytest.mark.parametrize("name", BUILTIN + EXAMPLE)
def test_jacobian_matches_finite_differences(name):
    robot = robots.load(name)
    for q in _interior_q(robot, 5, seed=5):
        assert np.abs(robot.jacobian(q) - _fd_jacobian(robot, q)).max() < 1e-6


def test_mimic_jacobian_matches_pinocchio_and_fd(mimic_robot):
    data = mimic_robot.model.createData()
    fid = mimic_robot.frame_id("tcp")
    for q in _interior_q(mimic_robot, 10, seed=2):
        J_pin = pin.computeFrameJacobian(mimic_robot.model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        assert np.abs(mimic_robot.jacobian(q) - J_pin).max() < 1e-12
        assert np.abs(mimic_robot.jacobian(q) - _fd_jacobian(mimic_robot, q)).max() < 1e-6


def test_batched_jacobian_equals_single(mimic_robot):
    q = mimic_robot.random_q(40, seed=9)
    J = mimic_robot.jacobian(q)
    assert J.shape == (40, 6, 2)
    assert np.abs(J[17] - mimic_robot.jacobian(q[17])).max() <= 1e-12  # single: Pinocchio; batch: numpy


def test_manipulability_ur5():
    robot = robots.load("ur5")
    q = robot.random_q(50, seed=1)
    J = robot.jacobian(q)
    w = robot.manipulability(q)
    expected = np.sqrt(np.linalg.det(J @ np.swapaxes(J, 1, 2)))
    assert np.allclose(w, expected)
    # the UR5 is singular with the wrist straight (wrist_2 = 0): w vanishes
    q_sing = np.array([0.3, -1.0, 1.2, -0.5, 0.0, 0.7])
    assert robot.manipulability(q_sing) < 1e-12
    with pytest.raises(InvalidInput, match="part"):
        robot.manipulability(q, part="linear")


def test_manipulability_of_redundant_and_deficient_arms(mimic_robot):
    q = mimic_robot.random_q(5, seed=4)
    J = mimic_robot.jacobian(q)
    assert np.allclose(mimic_robot.manipulability(q), np.sqrt(np.linalg.det(np.swapaxes(J, 1, 2) @ J)))
    panda = robots.load("panda")
    qp = panda.random_q(5, seed=4)
    Jp = panda.jacobian(qp)
    assert np.allclose(panda.manipulability(qp), np.sqrt(np.linalg.det(Jp @ np.swapaxes(Jp, 1, 2))))


def test_within_limits_reports_and_never_clamps():
    robot = robots.load("panda")
    q = robot.neutral.copy()
    assert robot.within_limits(q)
    q[3] = robot.upper[3] + 0.1
    assert not robot.within_limits(q)
    assert robot.limit_violations(q) == [
        f"panda_joint4 = {q[3]:.6g} outside [{robot.lower[3]:.6g}, {robot.upper[3]:.6g}]"
    ]
    T = robot.fk(q)  # FK of an out-of-limit q is computed as asked, not clamped
    assert np.abs(T - robot.fk_pinocchio(q)).max() < 1e-12
    batch = np.stack([robot.neutral, q])
    assert robot.within_limits(batch).tolist() == [True, False]


def test_random_q_is_reproducible_and_within_limits():
    robot = robots.load("ur5")
    a, b = robot.random_q(100, seed=3), robot.random_q(100, seed=3)
    assert np.array_equal(a, b)
    assert robot.within_limits(a).all()
    with pytest.raises(InvalidInput, match="positive integer"):
        robot.random_q(0)


def test_registry_lists_and_rejects_unknown_names():
    assert set(BUILTIN) == {"scara_mushroom", "aubo_i3", "gantry_flower", "koji_turner", "koji_turner_rail"}
    assert {"ur5", "panda"} <= set(robots.names())
    with pytest.raises(RobotNotFound) as err:
        robots.load("ur55")
    for known in ("aubo_i3", "koji_turner", "ur5", "panda"):
        assert known in str(err.value)


def test_example_robot_data_files_are_found_through_the_package():
    robot = robots.load("ur5")
    assert robot.urdf_path.name == "ur5_robot.urdf" and robot.urdf_path.exists()
    assert robot.tcp_frame == "tool0"
    assert robots.load("panda").nq == 7  # fingers frozen


@pytest.mark.parametrize(
    "q, message",
    [
        (np.zeros(5), r"shape \(6,\) or \(N, 6\)"),
        (np.zeros((3, 7)), r"shape \(6,\) or \(N, 6\)"),
        (np.array([0, 0, np.nan, 0, 0, 0]), "non-finite value at index"),
        ("abc", "must be numbers"),
    ],
)
def test_bad_q_raises_named_error(q, message):
    robot = robots.load("ur5")
    with pytest.raises(InvalidInput, match=message):
        robot.fk(q)


def test_unknown_frame_lists_frames():
    robot = robots.load("ur5")
    with pytest.raises(InvalidInput, match="no frame 'gripper'.*tool0"):
        robot.fk(np.zeros(6), frame="gripper")


@pytest.mark.parametrize(
    "text, message",
    [
        ("<robot name='x'><link name='a'>", "not well-formed XML"),
        ("<model name='x'><link name='a'/></model>", "root element is <model>"),
        ("<robot name='x'></robot>", "defines no <link>"),
        ("<robot name='x'><link name='a'/></robot>", "no movable joint"),
        (
            "<robot name='x'><link name='a'/><link name='b'/><joint name='j' type='revolute'>"
            "<parent link='a'/><child link='zzz'/><limit lower='0' upper='1' effort='1' velocity='1'/></joint></robot>",
            "child link 'zzz', which is not defined",
        ),
    ],
)
def test_malformed_urdf_raises_model_error(text, message):
    with pytest.raises(ModelError, match=message):
        robots.from_urdf_text(text)


def test_missing_urdf_file_raises_model_error(tmp_path):
    with pytest.raises(ModelError, match="cannot read URDF file"):
        robots.from_urdf(tmp_path / "nope.urdf")


def test_unknown_tcp_frame_raises_model_error(tmp_path):
    path = tmp_path / "lever.urdf"
    path.write_text(MIMIC_URDF)
    with pytest.raises(ModelError, match="no frame 'gripper' to use as tcp"):
        robots.from_urdf(path, tcp="gripper")
    assert robots.from_urdf(path).tcp_frame == "tcp"


@pytest.mark.parametrize("tol", [-1e-3, np.nan, np.inf, "0.1", True])
def test_limit_tolerance_must_be_finite_and_non_negative(tol):
    robot = robots.load("ur5")
    with pytest.raises(InvalidInput, match="limit tolerance tol"):
        robot.within_limits(robot.neutral, tol=tol)
    with pytest.raises(InvalidInput, match="limit tolerance tol"):
        robot.limit_violations(robot.neutral, tol=tol)


@pytest.mark.parametrize("seed", [-1, 1.5, "abc", True])
def test_random_q_rejects_bad_seeds_and_counts(seed):
    robot = robots.load("ur5")
    with pytest.raises(InvalidInput, match="seed must be"):
        robot.random_q(3, seed=seed)
    with pytest.raises(InvalidInput, match="positive integer"):
        robot.random_q(True)
    gen = np.random.default_rng(7)
    assert np.array_equal(robot.random_q(4, seed=gen), robot.random_q(4, seed=np.random.default_rng(7)))
