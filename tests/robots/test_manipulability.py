"""Yoshikawa's manipulability of a frame Jacobian against its definition, one Jacobian and batched."""

import numpy as np
import pytest

from pinarms import robots
from pinarms.errors import InvalidInput
from pinarms.robots.manipulability import PARTS, manipulability_of_jacobian


def test_one_jacobian_and_a_batch_agree_with_the_determinant():
    rng = np.random.default_rng(3)
    J = rng.standard_normal((5, 6, 4))  # fewer joints than rows: sqrt(det(Jᵀ J)) for the full rows
    for part, rows in PARTS.items():
        Jp = J[:, rows, :]
        G = Jp @ np.swapaxes(Jp, 1, 2) if Jp.shape[1] <= Jp.shape[2] else np.swapaxes(Jp, 1, 2) @ Jp
        expect = np.sqrt(np.linalg.det(G))
        np.testing.assert_allclose(manipulability_of_jacobian(J, part), expect, rtol=1e-12)
        one = manipulability_of_jacobian(J[0], part)
        assert isinstance(one, float) and one == pytest.approx(expect[0], rel=1e-12)


def test_a_singular_jacobian_has_zero_manipulability():
    J = np.zeros((6, 6))
    J[:3, :3] = np.eye(3)
    assert manipulability_of_jacobian(J) == 0.0
    assert manipulability_of_jacobian(J, "position") == pytest.approx(1.0, rel=1e-15)
    assert manipulability_of_jacobian(J[None], "orientation")[0] == 0.0
    with pytest.raises(InvalidInput, match=r"part must be one of \['full', 'orientation', 'position'\], got 'xyz'"):
        manipulability_of_jacobian(J, "xyz")


def test_the_robot_method_is_this_measure_of_its_jacobian():
    arm = robots.load("aubo_i3")
    q = arm.random_q(30, seed=1)
    assert np.array_equal(arm.manipulability(q, part="position"),
                          manipulability_of_jacobian(arm.jacobian(q), "position"))
    assert arm.manipulability(q[0]) == manipulability_of_jacobian(arm.jacobian(q[0]))
