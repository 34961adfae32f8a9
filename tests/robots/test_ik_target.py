"""An IK target checked: poses and positions in, ``(N, 4, 4)`` out, every bad input named."""

import numpy as np
import pytest

from pinarms import robots
from pinarms.errors import InvalidInput
from pinarms.robots.ik_target import check_ik_target


def _pose(angle: float, xyz=(0.3, 0.1, 0.2)) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    T = np.eye(4)
    T[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    T[:3, 3] = xyz
    return T


def test_one_pose_a_batch_and_positions():
    T = _pose(0.3)
    out, single = check_ik_target(T)
    assert single and out.shape == (1, 4, 4) and np.array_equal(out[0], T)
    out, single = check_ik_target([T.tolist(), _pose(1.0).tolist()])  # lists take the numpy path
    assert not single and out.shape == (2, 4, 4) and np.array_equal(out[0], T)
    out, single = check_ik_target(np.array([0.1, 0.2, 0.3]), position_only=True)
    assert single and np.array_equal(out[0], [[1, 0, 0, 0.1], [0, 1, 0, 0.2], [0, 0, 1, 0.3], [0, 0, 0, 1]])
    out, single = check_ik_target(np.zeros((5, 3)), position_only=True)
    assert not single and out.shape == (5, 4, 4)
    assert check_ik_target(np.zeros((0, 4, 4)))[0].shape == (0, 4, 4)


def test_the_fast_path_agrees_with_the_checks():
    # one float64 pose takes the plain-float path; the same pose as a list the numpy one
    for T in (_pose(0.7), _pose(-2.0, (1.0, -2.0, 0.5))):
        assert np.array_equal(check_ik_target(T)[0], check_ik_target(T.tolist())[0])
    mirrored = _pose(0.7)
    mirrored[:3, 0] *= -1.0
    for target in (mirrored, mirrored.tolist()):
        with pytest.raises(InvalidInput, match="IK target 0: its rotation block is not a proper rotation"):
            check_ik_target(target)


@pytest.mark.parametrize(("target", "options", "fragment"), [
    (np.zeros(3), {}, "use Robot.ik\\(position, position_only=True\\)"),
    (np.zeros((3, 3)), {}, "got shape \\(3, 3\\)"),
    (np.zeros((3, 4)), {"position_only": True}, "or a position \\(3,\\)"),
    (np.full((4, 4), np.nan), {}, "non-finite value"),
    (np.eye(4) * 2.0, {}, "not a proper rotation"),
    (np.eye(4) + np.eye(4, k=-3), {}, "last row of a homogeneous transform"),
    (np.eye(4) * 1j, {}, "must be numbers \\(real\\)"),
    ("pose", {}, "must be numbers"),
])
def test_bad_targets_are_named(target, options, fragment):
    with pytest.raises(InvalidInput, match=fragment):
        check_ik_target(target, **options)


def test_the_robot_method_is_the_same_check():
    arm = robots.load("aubo_i3")
    T = arm.fk(arm.neutral)
    out, single = arm.check_target(T)
    assert single and np.array_equal(out, check_ik_target(T)[0])
