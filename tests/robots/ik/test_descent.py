"""The interpreted Levenberg–Marquardt descent (robots/ik/descent.py): Newton's convergence near a solution."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinarms import robots
from pinarms.robots.ik import NumericalIK

ALL_ARMS = ["scara_mushroom", "gantry_flower", "koji_turner", "koji_turner_rail", "aubo_i3", "ur5", "panda"]


@pytest.fixture(scope="module", params=ALL_ARMS)
def arm(request):
    return robots.load(request.param)


def _fk_errors(robot, q, T):
    F = robot.fk(q)
    return np.linalg.norm(F[:3, 3] - T[:3, 3]), np.linalg.norm(pin.log3(F[:3, :3].T @ T[:3, :3]))


@pytest.mark.parametrize("position_only", [False, True])
def test_newton_steps_converge_quadratically(arm, position_only):
    """From 1e-4 rad/m off a solution, 1e-12 within 3 steps: the error Jacobian Jlog6(D⁻¹)·J_local
    (position only: the 3 linear rows and the damped 3×3 system) is exact."""
    solver = NumericalIK(arm)
    rng = np.random.default_rng(3)
    for q in arm.random_q(5, seed=13):
        T = arm.fk(q)
        q_off = q + 1e-4 * rng.standard_normal(arm.nq)
        q2, pe, re, its = solver.attempt(q_off, T, position_only, 1e-12, limits=False)
        assert pe <= 1e-12 and re <= 1e-12 and its <= 3
        pe_fk, re_fk = _fk_errors(arm, q2, T)
        assert pe_fk <= 1e-12 and (position_only or re_fk <= 1e-12)
