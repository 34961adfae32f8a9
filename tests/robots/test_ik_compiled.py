"""The compiled IK solver: its chain kinematics against Pinocchio, batch rows against single solves."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinarms import robots
from pinarms.robots.ik import NumericalIK
from pinarms.robots.ik import _chain as chain

ARMS = ["scara_mushroom", "gantry_flower", "koji_turner", "koji_turner_rail", "aubo_i3", "ur5", "panda"]


@pytest.mark.parametrize("name", ARMS)
def test_compiled_chain_pose_and_jacobian_match_pinocchio(name):
    """FK and frame Jacobian (base axes at the tcp) of the compiled chain vs Pinocchio, mimic joints included."""
    robot = robots.load(name)
    solver = NumericalIK(robot)
    _, C, _, _, _ = solver._compiled()
    qi, sc, of, rev, LR, Lp, fR, fp = C
    m = qi.shape[0]
    R, p, Z, O, J = np.empty((3, 3)), np.empty(3), np.empty((m, 3)), np.empty((m, 3)), np.empty((6, robot.nq))
    data = robot.model.createData()
    for q in robot.random_q(20, seed=5):
        chain.fk(q, qi, sc, of, rev, LR, Lp, fR, fp, R, p, Z, O)
        chain.jacobian(qi, sc, rev, Z, O, p, J)
        qp = robot._tree.coordinates.to_pin(q)
        pin.forwardKinematics(robot.model, data, qp)
        M = pin.updateFramePlacement(robot.model, data, solver.frame_id)
        J_ref = pin.computeFrameJacobian(robot.model, data, qp, solver.frame_id, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(R, M.rotation, atol=1e-12)
        np.testing.assert_allclose(p, M.translation, atol=1e-12)
        np.testing.assert_allclose(J, J_ref, atol=1e-12)


@pytest.mark.parametrize("name", ["panda", "ur5", "koji_turner"])
def test_batch_row_k_is_the_single_solve_with_seed_plus_k(name):
    robot = robots.load(name)
    T = robot.fk(robot.random_q(60, seed=21))
    Q = robot.ik(T, seed=7)
    for k in range(T.shape[0]):
        np.testing.assert_array_equal(Q[k], robot.ik(T[k], seed=7 + k))
    seeds = robot.random_q(60, seed=22)  # seeded: each row the 2π equivalents nearest its seed, as one by one
    Q = robot.ik(T, seeds, seed=3)
    for k in range(0, T.shape[0], 7):
        np.testing.assert_array_equal(Q[k], robot.ik(T[k], seeds[k], seed=3 + k))


def test_batch_of_panda_targets_all_solved_within_limits():
    """The narrow-limit redundant arm: every target met to 1e-10 within the limits (checked by Pinocchio)."""
    panda = robots.load("panda")
    T = panda.fk(panda.random_q(400, seed=31))
    res = NumericalIK(panda).solve_batch(T, seed=1)
    assert res.success.all()
    assert panda.within_limits(res.q, tol=0.0).all()
    data = panda.model.createData()
    fid = panda.frame_id("tcp")
    for q, Tk in zip(res.q, T):
        pin.forwardKinematics(panda.model, data, q)
        M = pin.updateFramePlacement(panda.model, data, fid)
        assert np.linalg.norm(M.translation - Tk[:3, 3]) <= 1e-10
        assert np.linalg.norm(pin.log3(M.rotation.T @ Tk[:3, :3])) <= 1e-10
    assert res.iterations > 400  # every target took steps (the table start never meets 1e-10)


def test_position_only_batch_and_single_agree():
    koji = robots.load("koji_turner")
    p = koji.position(koji.random_q(30, seed=4))
    Q = koji.ik(p, position_only=True, seed=2)
    assert np.abs(koji.position(Q) - p).max() <= 1e-10
    for k in (0, 13, 29):
        np.testing.assert_array_equal(Q[k], koji.ik(p[k], position_only=True, seed=2 + k))
