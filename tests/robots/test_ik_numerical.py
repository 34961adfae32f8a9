"""Robot.ik: one configuration within limits meeting the target to tol, or UnreachableTarget saying why."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinarms import robots
from pinarms.errors import InvalidInput, UnreachableTarget
from pinarms.robots.ik import NumericalIK
from pinarms.robots.ik.attempts import IKAttempts

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


# ---------------------------------------------------------------- solver internals seen from outside


def _fk_errors(robot, q, T):
    F = robot.fk(q)
    return np.linalg.norm(F[:3, 3] - T[:3, 3]), np.linalg.norm(pin.log3(F[:3, :3].T @ T[:3, :3]))


@pytest.mark.parametrize("name", ["aubo_i3", "ur5", "panda"])
def test_random_reachable_poses_all_solved_from_random_starts(name):
    """The benchmark's setting at a small size: every pose solved at 1e-10, checked with the batched FK."""
    robot = robots.load(name)
    solver = NumericalIK(robot)
    q_true = robot.random_q(150, seed=41)
    starts = robot.random_q(150, seed=42)
    T = robot.fk(q_true)
    attempts = []
    for k in range(150):
        res = solver.solve(T[k], starts[k], seed=k)
        assert res.success
        pe, re = _fk_errors(robot, res.q, T[k])
        assert pe <= 1e-10 and re <= 1e-10
        assert robot.within_limits(res.q, tol=0.0)
        assert abs(pe - res.position_error) <= 1e-12 and abs(re - res.rotation_error) <= 1e-12
        attempts.append(res.attempts)
    assert np.mean(attempts) <= 2.5  # measured 1.25 (ur5) to 1.76 (panda) per pose


def test_a_free_descent_ending_outside_the_limits_is_never_returned():
    aubo = robots.load("aubo_i3")
    solver = NumericalIK(aubo)
    T = aubo.fk(aubo.random_q(60, seed=11)[8])
    start = aubo.random_q(60, seed=12)[8]
    q_free, pe, re, _ = solver.attempt(start, T, False, 1e-10, limits=False)
    assert pe <= 1e-10 and re <= 1e-10
    assert any("upperArm_joint" in v for v in aubo.limit_violations(aubo._wrapped_to_range(q_free)))  # ≈ −3.10 rad
    # interpreted path: the projected descent from there does not recover, a restart does
    res = solver.solve_checked(T, start, IKAttempts(tol=1e-10, max_restarts=40, compiled=False))
    assert res.success and res.attempts >= 2
    for res in (res, solver.solve(T, start, seed=0)):  # and the compiled path (solve's default)
        assert res.success and aubo.within_limits(res.q, tol=0.0)
        pe, re = _fk_errors(aubo, res.q, T)
        assert pe <= 1e-10 and re <= 1e-10


def test_redundant_arm_slides_back_into_its_limits_in_one_attempt():
    """Panda: the free descent meets the pose with joint 5 beyond its limit; the projected descent fixes it."""
    panda = robots.load("panda")
    solver = NumericalIK(panda)
    T = panda.fk(panda.random_q(40, seed=11)[8])
    start = panda.random_q(40, seed=12)[8]
    q_free, pe, re, _ = solver.attempt(start, T, False, 1e-10, limits=False)
    assert pe <= 1e-10 and re <= 1e-10
    assert any("panda_joint5" in v for v in panda.limit_violations(panda._wrapped_to_range(q_free)))
    res = solver.solve(T, start, max_restarts=0)
    assert res.success and res.attempts == 1
    assert panda.within_limits(res.q, tol=0.0)


def test_failed_solve_returns_the_closest_configuration_within_limits():
    aubo = robots.load("aubo_i3")
    T = aubo.fk(aubo.neutral)
    T[0, 3] += 10.0
    res = NumericalIK(aubo).solve(T, max_restarts=5)
    assert not res.success
    assert aubo.within_limits(res.q, tol=0.0)
    pe, re = _fk_errors(aubo, res.q, T)
    assert abs(pe - res.position_error) <= 1e-9 and abs(re - res.rotation_error) <= 1e-9
    assert 9.0 < res.position_error < 10.0  # the arm stretches towards the target (reach ≈ 0.6 m)


def test_same_generator_state_gives_the_same_solution():
    panda = robots.load("panda")
    solver = NumericalIK(panda)
    T = panda.fk(panda.random_q(1, seed=7)[0])
    a = solver.solve(T, seed=np.random.default_rng(5))
    b = solver.solve(T, seed=np.random.default_rng(5))
    assert a.success and a.attempts == b.attempts
    np.testing.assert_array_equal(a.q, b.q)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"tol": np.inf}, "tol"),
        ({"tol": np.nan}, "tol"),
        ({"tol": -1e-6}, "tol"),
        ({"max_restarts": -1}, "max_restarts"),
        ({"max_restarts": 2.5}, "max_restarts"),
        ({"seed": -3}, "seed must be"),
        ({"seed": "abc"}, "seed must be"),
    ],
)
def test_invalid_solver_settings_are_named(kwargs, message):
    """An infinite tol would accept any configuration; bad counts and seeds are named, not ignored."""
    panda = robots.load("panda")
    with pytest.raises(InvalidInput, match=message):
        panda.ik(panda.fk(panda.neutral), **kwargs)


def test_numpy_float_tolerance_is_accepted():
    ur5 = robots.load("ur5")
    q = np.array([0.3, -1.2, 1.1, -0.5, 0.8, -0.6])
    sol = ur5.ik(ur5.fk(q), q_seed=q, tol=np.float32(1e-6))
    assert np.linalg.norm(ur5.position(sol) - ur5.position(q)) <= 1e-6


@pytest.mark.parametrize(
    "args, kwargs, message",
    [
        ((np.eye(3),), {}, "pose of shape"),
        ((np.full((4, 4), np.nan),), {}, "non-finite"),
        ((np.eye(4), np.zeros(3)), {}, r"shape \(6,\)"),
        ((np.eye(4), np.full(6, np.inf)), {}, "non-finite"),
        ((np.eye(4),), {"tol": -1.0}, "tol"),
        ((np.eye(4),), {"max_restarts": -2}, "max_restarts"),
        ((np.eye(4),), {"seed": 0.5}, "seed must be"),
        ((np.stack([np.eye(4)] * 2),), {}, "one target"),
    ],
)
def test_numerical_solver_names_bad_input(args, kwargs, message):
    """The public solver class checks its input like Robot.ik (no NaN result, no Pinocchio traceback)."""
    with pytest.raises(InvalidInput, match=message):
        NumericalIK(robots.load("ur5")).solve(*args, **kwargs)


def test_numerical_solver_accepts_a_position_when_position_only():
    ur5 = robots.load("ur5")
    p = ur5.position(np.array([0.3, -1.2, 1.1, -0.5, 0.8, -0.6]))
    res = NumericalIK(ur5).solve(p, position_only=True)
    assert res.success and np.linalg.norm(ur5.position(res.q) - p) <= 1e-10
