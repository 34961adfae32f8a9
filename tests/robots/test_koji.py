"""Koji-turning arm (seed 004): the parallelogram as mimic joints, and the paper's FK examples.

Printed examples (θ in degrees → tcp in mm); docs/robots/koji_turner.md explains each
difference asserted here.
"""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.robots.conventions import deg_to_rad, koji_fk_paper, m_to_mm

from _descriptions import pin_frame, pin_model, random_q

MM = 0.5  # reproduction tolerance (mm)


def tcp_mm(theta_deg) -> np.ndarray:
    return m_to_mm(pin_frame(pin_model("koji_turner"), deg_to_rad(theta_deg), "tcp")[:3, 3])


def test_example_1_reproduced_to_half_a_millimetre():
    # (-90, 25, -30, 90) -> (1197.3, 250.0, -929.2)
    np.testing.assert_allclose(tcp_mm([-90, 25, -30, 90]), [1197.3, 250.0, -929.2], atol=MM)


def test_example_2_x_y_reproduced_z_is_a_printing_error():
    # (-19.8, 5.5, -6.6, 19.8) -> printed (455.1, 1513.3, -970.5)
    p = tcp_mm([-19.8, 5.5, -6.6, 19.8])
    np.testing.assert_allclose(p[:2], [455.1, 1513.3], atol=MM)
    # z = -900 + 700 sin 5.5 deg - 650 sin 6.6 deg = -907.6 mm: the printed -970.5 differs by
    # 62.9 mm (transposed digits, "907" -> "970"); the paper's simulation repeats it (-970.6).
    assert p[2] == pytest.approx(-907.62, abs=0.05)
    assert -970.5 - p[2] == pytest.approx(-62.9, abs=0.1)


def test_example_3_z_reproduced_x_y_documented():
    # (-49.5, 13.625, -16.35, theta4 not printed) -> printed (985.7, 1005.1, -918.1);
    # the simulation reads (985.7, 1105, -918.1).
    p = tcp_mm([-49.5, 13.625, -16.35, 49.5])  # theta4 = -theta1 as in examples 1 and 2
    assert p[2] == pytest.approx(-918.1, abs=MM)
    assert p[0] - 985.7 == pytest.approx(5.9, abs=0.1)
    assert p[1] - 1005.1 == pytest.approx(91.8, abs=0.1)
    assert p[1] - 1105.0 == pytest.approx(-8.1, abs=0.1)
    # The simulation moves the joints at -9, 2.5, -3, 9 deg/s: theta2 = 13.625 and
    # theta3 = -16.35 are t = 5.45 s, where theta1 = -49.05 (not -49.5) and theta4 = 49.05.
    q = tcp_mm([-49.05, 13.625, -16.35, 49.05])
    assert q[1] == pytest.approx(1105.0, abs=MM)  # the simulated y
    assert q[0] - 985.7 == pytest.approx(-0.8, abs=0.1)
    assert q[2] == pytest.approx(-918.1, abs=MM)


def test_model_equals_the_paper_closed_form_everywhere():
    model = pin_model("koji_turner")
    q = random_q(model, 50, seed=11)
    expected = koji_fk_paper(q)
    for qi, ti in zip(q, expected):
        np.testing.assert_allclose(pin_frame(model, qi, "tcp"), ti, atol=1e-12)


def test_flange_stays_level_and_turns_with_waist_plus_wrist():
    model = pin_model("koji_turner")
    for q in random_q(model, 50, seed=5):
        rotation = pin_frame(model, q, "flange")[:3, :3]
        np.testing.assert_allclose(rotation[:, 2], [0.0, 0.0, 1.0], atol=1e-12)  # tool axis vertical
        heading = q[0] + q[3]
        np.testing.assert_allclose(rotation[:2, :2], [[np.cos(heading), -np.sin(heading)], [np.sin(heading), np.cos(heading)]], atol=1e-12)


def test_joint_meaning_raise_and_absolute_forearm():
    model = pin_model("koji_turner")
    base = pin_frame(model, np.zeros(4), "tcp")[:3, 3]
    np.testing.assert_allclose(base, [0.0, 1.6, -0.9], atol=1e-12)  # arm stretched along +y
    raised = pin_frame(model, [0.0, 0.2, 0.0, 0.0], "tcp")[:3, 3]
    assert raised[2] == pytest.approx(-0.9 + 0.7 * np.sin(0.2), abs=1e-12)  # theta2 > 0 raises
    # the forearm's pitch is absolute: changing theta2 leaves the forearm direction unchanged
    a = pin_frame(model, [0.0, 0.0, 0.3, 0.0], "tcp")[:3, 3] - pin_frame(model, [0.0, 0.0, 0.3, 0.0], "flange")[:3, 3]
    b = pin_frame(model, [0.0, 0.4, 0.3, 0.0], "tcp")[:3, 3] - pin_frame(model, [0.0, 0.4, 0.3, 0.0], "flange")[:3, 3]
    np.testing.assert_allclose(a, b, atol=1e-12)
    elbow_to_wrist = (
        pin_frame(model, [0.0, 0.4, 0.3, 0.0], "flange")[:3, 3] - np.array([0.0, 0.7 * np.cos(0.4), -0.9 + 0.7 * np.sin(0.4)])
    )
    np.testing.assert_allclose(elbow_to_wrist, [0.0, 0.65 * np.cos(0.3), 0.65 * np.sin(0.3)], atol=1e-12)


def test_joint_ranges_are_the_papers():
    model = pin_model("koji_turner")
    np.testing.assert_allclose(np.rad2deg(model.lowerPositionLimit), [-180, 0, -30, -180], atol=1e-9)
    np.testing.assert_allclose(np.rad2deg(model.upperPositionLimit), [180, 25, 25, 180], atol=1e-9)
