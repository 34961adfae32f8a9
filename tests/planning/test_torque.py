"""Torques along trajectories: samples, refined peaks against brute force, torque limit checks."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning, robots
from pinarms.planning import JointLimits
from pinarms.planning.errors import TrajectoryError


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3").with_payload(3.0)


@pytest.fixture(scope="module")
def move(aubo):
    q = np.array([[0.3, -0.4, 1.2, 0.2, 1.57, 0.0],
                  [0.0, 0.1, 1.6, 0.4, 1.3, 0.3],
                  [-0.8, 0.5, 1.9, 0.6, 1.0, 0.6],
                  [-1.2, 0.3, 1.5, 0.2, 1.57, 0.0]])
    return planning.multi_quintic([0.0, 0.35, 0.8, 1.1], q)


def test_torques_are_the_inverse_dynamics_of_the_samples(aubo, move):
    t = np.linspace(0.0, move.duration, 101)
    q, qd, qdd, _ = move.sample(t)
    np.testing.assert_array_equal(move.torques(aubo, t), aubo.inverse_dynamics(q, qd, qdd))
    assert move.torques(aubo, 0.5).shape == (6,)


def test_refined_peaks_match_a_brute_force_maximum(aubo, move):
    peaks = move.torque_peaks(aubo)
    t = np.linspace(0.0, move.duration, 200_001)
    tau = np.abs(move.torques(aubo, t))
    brute = tau.max(axis=0)
    # never below the dense maximum by more than round-off, never above it by more than the
    # curvature over half a brute-force step
    assert np.all(peaks.torque >= brute * (1.0 - 1e-12))
    np.testing.assert_allclose(peaks.torque, brute, rtol=1e-8)
    np.testing.assert_allclose(peaks.time, t[np.argmax(tau, axis=0)], atol=2e-5)
    np.testing.assert_allclose(np.abs(peaks.signed), peaks.torque)
    # a coarse grid alone is below the refined peak
    coarse = np.abs(move.torques(aubo, np.linspace(0.0, move.duration, 13))).max(axis=0)
    assert np.all(coarse <= peaks.torque * (1.0 + 1e-12))
    assert np.any(coarse < peaks.torque * (1.0 - 1e-4))


def test_torque_check_names_joint_time_and_ratio(aubo, move):
    peaks = move.torque_peaks(aubo)
    limit = peaks.torque.copy() * 1.01
    limit[1] = peaks.torque[1] / 1.25  # the shoulder gets 25 % too little
    lim = JointLimits(velocity=100.0, torque=limit)
    report = move.check(lim, robot=aubo)
    torque = [v for v in report.violations if v.kind == "torque"]
    assert {v.joint for v in torque} == {1}
    worst = max(torque, key=lambda v: v.ratio)
    assert worst.ratio == pytest.approx(1.25, rel=1e-9)
    assert worst.time == pytest.approx(peaks.time[1], abs=1e-9)
    text = str(report)
    assert "joint 1 (upperArm_joint)" in text and "torque" in text and "ratio 1.25" in text
    assert move.check(JointLimits(velocity=100.0, torque=peaks.torque * 1.001), robot=aubo).ok


def test_torque_check_needs_the_robot_and_all_its_joints(aubo, move):
    with pytest.raises(TrajectoryError, match="robot=arm"):
        move.check(JointLimits(velocity=100.0, torque=50.0))
    one = planning.polynomial([0.0, 1.0], [0.0, 1.0], 5)
    with pytest.raises(TrajectoryError, match="has 1 joint.*6"):
        one.torque_peaks(aubo)


def test_limits_from_the_robot_take_the_urdf_efforts(aubo):
    lim = JointLimits.from_robot(aubo, torque=True)
    np.testing.assert_array_equal(lim.torque, aubo.effort_limit)
    assert JointLimits.from_robot(aubo).torque is None
    with pytest.raises(TrajectoryError, match="torque limit must be positive"):
        JointLimits(velocity=1.0, torque=[1.0, 0.0])
