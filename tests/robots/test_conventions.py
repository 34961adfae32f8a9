"""Unit helpers at the edges and the papers' conventions (robots.conventions)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.robots.conventions import (
    GANTRY_TRANSMISSION_M_PER_RAD,
    aubo_joint_to_mdh,
    aubo_mdh_to_joint,
    deg_to_rad,
    gantry_motor_to_axis,
    koji_fk_paper,
    m_to_mm,
    mm_to_m,
    rad_to_deg,
    wrap_angle,
)
from pinarms.errors import InvalidInput


def test_angle_and_length_conversions_on_arrays():
    np.testing.assert_allclose(deg_to_rad([180.0, -90.0, 0.0]), [np.pi, -np.pi / 2, 0.0])
    np.testing.assert_allclose(rad_to_deg(np.array([[np.pi / 4]])), [[45.0]])
    np.testing.assert_allclose(mm_to_m([1197.3, 250.0]), [1.1973, 0.25])
    assert m_to_mm(0.2565) == pytest.approx(256.5)
    x = np.random.default_rng(0).normal(size=(50, 3))
    np.testing.assert_allclose(rad_to_deg(deg_to_rad(x)), x, atol=1e-12)
    np.testing.assert_allclose(m_to_mm(mm_to_m(x)), x, atol=1e-12)
    assert deg_to_rad([1, 2]).dtype == np.float64


def test_conversions_reject_non_numeric_input():
    with pytest.raises(InvalidInput, match="angle_deg"):
        deg_to_rad("ninety")
    with pytest.raises(InvalidInput, match="length_mm"):
        mm_to_m([1.0, "x"])


def test_wrap_angle_range():
    wrapped = wrap_angle([np.pi, -np.pi, 3 * np.pi / 2, 7.0, -7.0])
    np.testing.assert_allclose(wrapped, [-np.pi, -np.pi, -np.pi / 2, 7.0 - 2 * np.pi, -7.0 + 2 * np.pi])
    assert np.all((wrapped >= -np.pi) & (wrapped < np.pi))


def test_aubo_conversion_shapes_and_errors():
    assert aubo_joint_to_mdh(np.zeros(6)).shape == (6,)
    assert aubo_mdh_to_joint(np.zeros((7, 6))).shape == (7, 6)
    with pytest.raises(InvalidInput, match=r"\(6,\) or \(N, 6\)"):
        aubo_joint_to_mdh(np.zeros(5))
    with pytest.raises(InvalidInput, match="theta"):
        aubo_mdh_to_joint(np.zeros((2, 3, 6)))


def test_aubo_conversion_wraps_into_minus_pi_pi():
    theta = aubo_joint_to_mdh([3.0, -3.0, 3.0, -3.0, 3.0, -3.0])
    assert np.all((theta >= -np.pi) & (theta < np.pi))
    np.testing.assert_allclose(theta[1], -3.0 - np.pi / 2 + 2 * np.pi)


def test_koji_fk_paper_batched_and_single():
    theta = deg_to_rad([[-90, 25, -30, 90], [0, 0, 0, 0]])
    t = koji_fk_paper(theta)
    assert t.shape == (2, 4, 4)
    np.testing.assert_allclose(m_to_mm(t[0, :3, 3]), [1197.33, 250.0, -929.17], atol=0.01)
    np.testing.assert_allclose(t[1, :3, 3], [0.0, 1.6, -0.9], atol=1e-15)
    np.testing.assert_allclose(koji_fk_paper(theta[0]), t[0])
    np.testing.assert_allclose(t[0, :3, :3], np.eye(3), atol=1e-15)  # heading theta1 + theta4 = 0
    with pytest.raises(InvalidInput, match="theta"):
        koji_fk_paper([0.0, 0.0, 0.0])


def test_gantry_motor_side_limits_to_axis_side():
    np.testing.assert_allclose(gantry_motor_to_axis([100.0, 1500.0, 20000.0]), [1.0, 15.0, 200.0])
    assert GANTRY_TRANSMISSION_M_PER_RAD == 0.01
    assert gantry_motor_to_axis(100.0, transmission_m_per_rad=0.005) == pytest.approx(0.5)
    with pytest.raises(InvalidInput, match="transmission"):
        gantry_motor_to_axis(1.0, transmission_m_per_rad=0.0)


def test_gantry_urdf_velocity_is_the_paper_motor_limit_through_the_transmission():
    import pinocchio as pin

    from pinarms.robots.urdf_build import URDF_DIR

    model = pin.buildModelFromUrdf(str(URDF_DIR / "gantry_flower.urdf"))
    np.testing.assert_allclose(model.velocityLimit, gantry_motor_to_axis(np.full(3, 100.0)))
