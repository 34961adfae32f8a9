"""AUBO-i3 (seed 001): manufacturer convention in the model, the paper's modified D-H outside."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.robots.conventions import (
    aubo_flange_from_mdh,
    aubo_fk_mdh,
    aubo_joint_to_mdh,
    aubo_mdh_to_joint,
    deg_to_rad,
    m_to_mm,
)
from pinarms.papers import SEED001

from _descriptions import pin_frame, pin_model, random_q

# Seed 001, table 2: joint columns (rad) and the Cartesian points as printed (mm).
TABLE2_JOINTS = SEED001.table2_joints


def craig_link(alpha, a, d, theta):
    """One modified D-H link transform, written out independently of robots.conventions."""
    rx = np.array([[1, 0, 0, 0], [0, np.cos(alpha), -np.sin(alpha), 0], [0, np.sin(alpha), np.cos(alpha), 0], [0, 0, 0, 1]])
    tx = np.eye(4)
    tx[0, 3] = a
    rz = np.array([[np.cos(theta), -np.sin(theta), 0, 0], [np.sin(theta), np.cos(theta), 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    tz = np.eye(4)
    tz[2, 3] = d
    return rx @ tx @ rz @ tz


def paper_fk(theta):
    """Seed 001 table 1 with the manufacturer's lengths (m): frame 6 in D-H frame 0."""
    rows = [(0, 0, 0.157), (-np.pi / 2, 0, 0.119), (0, 0.266, 0), (0, 0.2565, 0), (np.pi / 2, 0, 0.1025), (-np.pi / 2, 0, 0.094)]
    t = np.eye(4)
    for (alpha, a, d), th in zip(rows, theta):
        t = t @ craig_link(alpha, a, d, th)
    return t


RZ_PI = np.diag([-1.0, -1.0, 1.0, 1.0])


def test_conventions_mdh_fk_matches_an_independent_implementation():
    theta = np.random.default_rng(2).uniform(-np.pi, np.pi, (30, 6))
    batch = aubo_fk_mdh(theta)
    assert batch.shape == (30, 4, 4)
    for th, t in zip(theta, batch):
        np.testing.assert_allclose(t, paper_fk(th), atol=1e-14)
    np.testing.assert_allclose(aubo_fk_mdh(theta[0]), paper_fk(theta[0]), atol=1e-14)


def test_model_flange_is_the_paper_frame_6_with_base_and_flange_turned_by_pi():
    model = pin_model("aubo_i3")
    q = random_q(model, 100, seed=4)
    theta = aubo_joint_to_mdh(q)
    for qi, ti in zip(q, theta):
        expected = RZ_PI @ paper_fk(ti) @ RZ_PI
        np.testing.assert_allclose(pin_frame(model, qi, "flange"), expected, atol=1e-12)
    np.testing.assert_allclose(aubo_flange_from_mdh(theta[:3]), [pin_frame(model, qi, "flange") for qi in q[:3]], atol=1e-12)


def test_round_trip_between_paper_angles_and_joint_values():
    q = np.random.default_rng(8).uniform(-np.pi, np.pi, (1000, 6))
    np.testing.assert_allclose(aubo_mdh_to_joint(aubo_joint_to_mdh(q)), q, atol=1e-12)
    theta = np.random.default_rng(9).uniform(-np.pi, np.pi, (1000, 6))
    np.testing.assert_allclose(aubo_joint_to_mdh(aubo_mdh_to_joint(theta)), theta, atol=1e-12)
    np.testing.assert_allclose(aubo_joint_to_mdh(q[0], wrap=False), [q[0, 0], q[0, 1] - np.pi / 2, -q[0, 2], np.pi / 2 - q[0, 3], q[0, 4], -q[0, 5]])


def test_paper_home_statement_is_the_manufacturer_zero_pose():
    # "theta2 = -90 deg, theta4 = 90 deg, the other joints 0: the model matches the real robot"
    home_theta = deg_to_rad([0, -90, 0, 90, 0, 0])
    np.testing.assert_allclose(aubo_mdh_to_joint(home_theta), np.zeros(6), atol=1e-15)
    flange = pin_frame(pin_model("aubo_i3"), np.zeros(6), "flange")
    # upright: d1 + a2 + a3 + d5 above the base, offset -(d2 + d6) sideways, tool pointing along -y
    np.testing.assert_allclose(flange[:3, 3], [0.0, -0.213, 0.782], atol=1e-12)
    np.testing.assert_allclose(flange[:3, 2], [0.0, -1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(RZ_PI @ paper_fk(home_theta) @ RZ_PI, flange, atol=1e-12)


def test_table2_cartesian_points_vs_fk_of_the_joint_columns():
    """Residuals documented in docs/robots/aubo_i3.md (mm); the paper's points are not fitted."""
    p = m_to_mm(aubo_flange_from_mdh(TABLE2_JOINTS)[:, :3, 3])  # columns read as the paper's theta
    # P1, P2: x, y off by (3.6, 20.6) mm; z agrees to 0.4 mm
    np.testing.assert_allclose(p[0], [398.6, 367.6, 244.4], atol=0.1)
    np.testing.assert_allclose(p[1], [398.6, 367.6, 289.1], atol=0.1)
    np.testing.assert_allclose(p[0] - [395, 347, 244], [3.6, 20.6, 0.4], atol=0.1)
    np.testing.assert_allclose(p[1] - [395, 347, 289], [3.6, 20.6, 0.1], atol=0.1)
    assert np.linalg.norm(p[0] - [395, 347, 244]) == pytest.approx(20.9, abs=0.1)
    # P1 -> P2 lifts by 44.7 mm (printed: 244 -> 289, 45 mm)
    assert p[1, 2] - p[0, 2] == pytest.approx(44.7, abs=0.1)
    # P3, P4 (digits "42222289" / "42222244"): FK gives points nowhere near any reading
    np.testing.assert_allclose(p[2], [199.1, 30.8, 318.3], atol=0.1)
    np.testing.assert_allclose(p[3], [168.0, -0.3, 326.0], atol=0.1)
    assert np.linalg.norm(p[2] - [42, 222, 289]) == pytest.approx(249.2, abs=0.1)
    assert np.linalg.norm(p[3] - [42, 222, 244]) == pytest.approx(268.4, abs=0.1)


def test_table2_columns_read_as_manufacturer_joint_values_fit_worse():
    model = pin_model("aubo_i3")
    p = np.array([m_to_mm(pin_frame(model, q, "flange")[:3, 3]) for q in TABLE2_JOINTS])
    np.testing.assert_allclose(p[0], [-515.3, -160.1, 144.3], atol=0.1)
    assert np.linalg.norm(p[0] - [395, 347, 244]) > 1000


def test_limits_are_the_papers_170_deg_and_210_deg_per_s():
    model = pin_model("aubo_i3")
    np.testing.assert_allclose(model.upperPositionLimit, np.full(6, np.deg2rad(170)), atol=1e-12)
    np.testing.assert_allclose(model.lowerPositionLimit, np.full(6, -np.deg2rad(170)), atol=1e-12)
    np.testing.assert_allclose(model.velocityLimit, np.full(6, np.deg2rad(210)), atol=1e-12)
    # every table 2 / table 3 configuration of the paper lies inside these limits
    assert np.all(np.abs(TABLE2_JOINTS) <= np.deg2rad(170))
