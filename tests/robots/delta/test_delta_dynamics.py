"""Motor torques with the closed chain (Pinocchio) against virtual work on the closed form."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.robots.delta import DeltaUnreachable, platform_jacobian
from pinarms.robots.delta.dynamics import check_with_constraint_dynamics, closed_chain_state, motor_torques
from pinarms.robots.delta.virtual_work import body_frames, virtual_work_torques

W = 2.0 * np.pi * 1.5        # a brisk motion: 1.5 Hz, up to 18 m/s^2 at the platform


def _p(t):
    return np.stack([0.2 * np.sin(W * t), 0.1 * np.cos(W * t), -1.0 + 0.05 * np.sin(2 * W * t)], axis=1)


def _pd(t):
    return np.stack([0.2 * W * np.cos(W * t), -0.1 * W * np.sin(W * t), 0.1 * W * np.cos(2 * W * t)], axis=1)


def _pdd(t):
    return np.stack([-0.2 * W**2 * np.sin(W * t), -0.1 * W**2 * np.cos(W * t), -0.2 * W**2 * np.sin(2 * W * t)], axis=1)


@pytest.fixture(scope="module")
def loaded(delta):
    return delta.with_payload(1.0)


def test_closed_chain_torques_equal_virtual_work_with_payload(loaded):
    t = np.linspace(0.0, 2.0 / 3.0, 9)
    state = closed_chain_state(loaded, _p(t), _pd(t), _pdd(t))
    tau, _ = motor_torques(loaded, state)
    reference = virtual_work_torques(loaded, _p, t)
    assert np.abs(tau).max() > 10.0                       # not a trivial motion
    assert np.abs(tau - reference).max() <= 1e-4          # N m (measured 2e-6)


def test_pinocchio_constraint_dynamics_reproduces_the_motion_from_the_torques(loaded):
    t = np.linspace(0.0, 0.5, 4)
    state = closed_chain_state(loaded, _p(t), _pd(t), _pdd(t))
    tau, _ = motor_torques(loaded, state)
    acc = check_with_constraint_dynamics(loaded, state, tau)
    assert np.abs(acc[:, loaded.platform_q] - _pdd(t)).max() <= 1e-9
    assert np.abs(acc - state.a).max() <= 1e-9


def test_state_satisfies_the_closures_and_the_closed_form_jacobian(loaded):
    t = np.linspace(0.0, 0.5, 5)
    state = closed_chain_state(loaded, _p(t), _pd(t), _pdd(t))
    for q, v in zip(state.q, state.v):
        assert np.abs(loaded.constraint_jacobian(q) @ v).max() <= 1e-12
    jac = platform_jacobian(loaded.geometry, state.q[:, loaded.motor_q])
    assert np.abs(np.einsum("nij,nj->ni", jac, state.v[:, loaded.motor_q]) - _pd(t)).max() <= 1e-12


def test_payload_adds_its_weight_through_the_jacobian(delta, loaded):
    """At rest, 1 kg more at the tcp asks tau = m g J[z, :] more of the motors (virtual work)."""
    p = np.array([[0.1, -0.2, -1.0], [0.0, 0.0, -1.2]])
    rest = np.zeros_like(p)
    light, _ = motor_torques(delta, closed_chain_state(delta, p, rest, rest))
    heavy, _ = motor_torques(loaded, closed_chain_state(loaded, p, rest, rest))
    jac = platform_jacobian(delta.geometry, closed_chain_state(delta, p, rest, rest).q[:, delta.motor_q])
    assert np.abs((heavy - light) - 1.0 * 9.81 * jac[:, 2, :]).max() <= 1e-9


def test_body_frames_of_the_closed_form_are_pinocchios(delta):
    import pinocchio as pin
    theta = np.array([[0.2, 0.7, -0.1]])
    q = delta.configuration(theta[0])
    data = delta.model.createData()
    pin.forwardKinematics(delta.model, data, q)
    for name, (rot, origin) in body_frames(delta, theta).items():
        placement = data.oMi[delta.model.getJointId(name)]
        assert np.abs(placement.rotation - rot[0]).max() < 1e-12 and np.abs(placement.translation - origin[0]).max() < 1e-12


def test_an_unreachable_sample_is_named(delta):
    zero = np.zeros((1, 3))
    with pytest.raises(DeltaUnreachable, match="out of the delta's reach"):
        closed_chain_state(delta, [[0.0, 0.0, -3.0]], zero, zero)


def test_pinocchio_constraint_dynamics_derivatives_invert_the_closed_chain_torques(loaded):
    """At rest, the platform acceleration per motor torque (Pinocchio's computeConstraintDynamicsDerivatives)
    is the inverse of the torque per platform acceleration that motor_torques gives (its linear part)."""
    import pinocchio as pin

    p, zero = np.array([[0.1, -0.1, -1.1]]), np.zeros((1, 3))
    gravity, _ = motor_torques(loaded, closed_chain_state(loaded, p, zero, zero))
    per_acc = np.stack([motor_torques(loaded, closed_chain_state(loaded, p, zero, np.eye(3)[k][None]))[0][0]
                        - gravity[0] for k in range(3)], axis=1)            # d tau / d p_ddot, (3, 3)
    model, data = loaded.model, loaded.model.createData()
    cdatas = [cm.createData() for cm in loaded.constraint_models]
    pin.initConstraintDynamics(model, data, loaded.constraint_models, cdatas)
    q = closed_chain_state(loaded, p, zero, zero).q[0]
    pin.constraintDynamics(model, data, q, np.zeros(model.nv), np.zeros(model.nv), loaded.constraint_models, cdatas)
    pin.computeConstraintDynamicsDerivatives(model, data, loaded.constraint_models, cdatas)
    acc_per_tau = data.ddq_dtau[np.ix_(loaded.platform_q, loaded.motor_q)]
    assert np.abs(acc_per_tau @ per_acc - np.eye(3)).max() <= 1e-9
