"""Robot.ik: one configuration within limits meeting the target to tol, or UnreachableTarget saying why."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robots
from robots.errors import InvalidInput, UnreachableTarget
from robots.ik import NumericalIK

ALL_ARMS = ["scara_mushroom", "gantry_flower", "koji_turner", "koji_turner_rail", "aubo_i3", "ur5", "panda"]


@pytest.fixture(scope="module", params=ALL_ARMS)
def arm(request):
    return robots.load(request.param)


def _errors(robot, q, T):
    F = robot.fk(q)
    angle = np.linalg.norm(pin.log3(F[:3, :3].T @ T[:3, :3]))
    return np.linalg.norm(F[:3, 3] - T[:3, 3]), angle


def test_round_trip_every_arm(arm):
    q_true = arm.random_q(8, seed=21)
    seeds = arm.random_q(8, seed=22)
    for q, s in zip(q_true, seeds):
        T = arm.fk(q)
        sol = arm.ik(T, s)
        pe, re = _errors(arm, sol, T)
        assert pe <= 1e-10 and re <= 1e-10
        assert arm.within_limits(sol, tol=1e-12)


def test_numerical_solver_alone_on_every_arm(arm):
    """The DLS solver without the closed form (mimic koji and 7-DoF panda included)."""
    solver = NumericalIK(arm)
    q_true = arm.random_q(10, seed=5)
    seeds = arm.random_q(10, seed=6)
    for q, s in zip(q_true, seeds):
        res = solver.solve(arm.fk(q), s, tol=1e-10, seed=1)
        assert res.success
        assert res.position_error <= 1e-10 and res.rotation_error <= 1e-10
        assert arm.within_limits(res.q, tol=1e-12)


def test_position_only(arm):
    q = arm.random_q(3, seed=9)
    for qk in q:
        p = arm.position(qk)
        sol = arm.ik(p, position_only=True)
        assert np.linalg.norm(arm.position(sol) - p) <= 1e-10
        assert arm.within_limits(sol)


def test_seeded_restarts_are_reproducible():
    panda = robots.load("panda")
    T = panda.fk(panda.random_q(1, seed=4)[0])
    a = panda.ik(T, seed=3)
    b = panda.ik(T, seed=3)
    np.testing.assert_array_equal(a, b)


def test_ik_prefers_the_analytic_solution_nearest_the_seed():
    aubo = robots.load("aubo_i3")
    q = np.array([0.4, -0.3, 1.0, 0.2, 0.9, -0.5])
    sol = aubo.ik(aubo.fk(q), q + 0.05)
    np.testing.assert_allclose(sol, q, atol=1e-9)


@pytest.mark.parametrize("name", ["aubo_i3", "panda", "koji_turner"])
def test_pose_ten_metres_away_is_out_of_reach(name):
    robot = robots.load(name)
    T = robot.fk(robot.neutral)
    T[0, 3] += 10.0
    with pytest.raises(UnreachableTarget, match="out of reach") as info:
        robot.ik(T, max_restarts=5)
    assert "position error" in str(info.value)


def test_pose_needing_an_out_of_limit_joint_names_it():
    gantry = robots.load("gantry_flower")
    T = gantry.fk(np.array([1.0, 0.3, -0.1]))
    T[0, 3] = 1.5
    with pytest.raises(UnreachableTarget, match=r"outside its limits.*x = 1\.5"):
        gantry.ik(T)


def test_numerical_only_arm_needing_an_out_of_limit_rail_names_it():
    rail = robots.load("koji_turner_rail")
    q = np.array([0.5, 2.0, 0.3, 0.2, 0.1, 0.4])
    T = rail.fk(q)
    T[0, 3] -= 3.0  # 2.5 m behind the rail's start: the rail would have to go below 0
    with pytest.raises(UnreachableTarget, match="outside its limits.*rail_x") as info:
        rail.ik(T, max_restarts=10)
    assert "out of reach" not in str(info.value)


def test_aubo_pose_needing_an_out_of_limit_joint():
    aubo = robots.load("aubo_i3")
    # shoulder_joint at -176° (range ±170°); no other branch of this pose is within limits
    q = np.array([-3.072, -2.285, 1.614, -0.423, 1.649, -2.45])
    T = aubo.fk(q)
    sols_free = aubo._analytic_ik.candidates(T[None], respect_limits=False)[1]
    assert sols_free.shape[0] == 4 and aubo.ik_all(T).shape[0] == 0
    with pytest.raises(UnreachableTarget, match="outside its limits.*shoulder_joint") as info:
        aubo.ik(T, max_restarts=5)
    assert "out of reach" not in str(info.value)


def test_unreachable_orientation_of_a_scara():
    scara = robots.load("scara_mushroom")
    T = scara.fk(np.array([0.3, 0.5, 0.05, 0.1]))
    T[:3, :3] = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]]) @ T[:3, :3]
    with pytest.raises(UnreachableTarget, match="orientation"):
        scara.ik(T, max_restarts=3)


@pytest.mark.parametrize("bad", [np.eye(3), np.full((4, 4), np.inf), np.diag([1.0, -1.0, 1.0, 1.0]), "pose"])
def test_invalid_targets(bad):
    with pytest.raises(InvalidInput):
        robots.load("ur5").ik(bad)


def test_invalid_tol_and_seed_shape():
    ur5 = robots.load("ur5")
    with pytest.raises(InvalidInput):
        ur5.ik(np.eye(4), tol=0.0)
    with pytest.raises(InvalidInput):
        ur5.ik(ur5.fk(ur5.neutral), q_seed=np.zeros(3))


def test_wrist_singular_pose():
    """θ5 = 0: θ4 and θ6 trade off; ik_all keeps q_ref's θ6, ik() solves either way."""
    aubo = robots.load("aubo_i3")
    q = np.array([0.1, 0.2, 0.5, 0.1, 0.0, 0.3])
    T = aubo.fk(q)
    sols = aubo.ik_all(T, q_ref=q)
    np.testing.assert_allclose(sols[0], q, atol=1e-8)
    q_stretched = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.3])  # wrist singular and arm stretched
    sol = aubo.ik(aubo.fk(q_stretched))
    pe, re = _errors(aubo, sol, aubo.fk(q_stretched))
    assert pe <= 1e-10 and re <= 1e-10
