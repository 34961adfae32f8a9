"""The platform Jacobian (closed form and from Pinocchio's constraint Jacobians) and both singularities."""

from __future__ import annotations

import numpy as np

from pinarms.robots.delta import forward_position
from pinarms.robots.delta.jacobian import platform_jacobian, platform_jacobian_pinocchio
from pinarms.robots.delta.singularities import singularities


def test_jacobian_from_constraints_equals_closed_form_and_finite_differences(delta):
    g = delta.geometry
    theta = np.random.default_rng(11).uniform(delta.limits.lower, delta.limits.upper, size=(40, 3))
    closed = platform_jacobian(g, theta)
    h = 1e-6
    fd = np.stack([(forward_position(g, theta + h * np.eye(3)[k]) - forward_position(g, theta - h * np.eye(3)[k]))
                   / (2 * h) for k in range(3)], axis=2)
    assert np.abs(closed - fd).max() <= 1e-7
    q = delta.configuration(theta)
    from_pin = np.stack([platform_jacobian_pinocchio(delta, qn) for qn in q])
    assert np.abs(from_pin - closed).max() <= 1e-12


def _bisect(f, a: float, b: float) -> float:
    """The boundary between f true at a and false at b."""
    for _ in range(80):
        m = 0.5 * (a + b)
        a, b = (m, b) if f(m) else (a, m)
    return a


def test_parallel_singularity_where_the_assembly_modes_meet(delta):
    g = delta.geometry
    t3 = _bisect(lambda t: not np.isnan(forward_position(g, np.array([[0.0, 0.0, t]]))).any(), 0.0, 3.0)
    report = singularities(g, np.array([[0.0, 0.0, t3], [0.3, 0.3, 0.3]]))
    assert report.parallel[0] < 1e-6 and report.parallel[1] > 0.5
    assert report.parallel_singular.tolist() == [True, False]
    assert "parallel singularity" in report.describe(0) and report.describe(1).startswith("regular")
    lower = forward_position(g, [0.0, 0.0, t3])
    upper = forward_position(g, [0.0, 0.0, t3], assembly="upper")
    assert np.linalg.norm(lower - upper) < 1e-5          # the two assembly modes coincide there


def test_serial_singularity_where_a_legs_branches_meet(delta):
    g = delta.geometry
    from pinarms.robots.delta import inverse_position_branches
    z = _bisect(lambda z: inverse_position_branches(g, [0.0, 0.0, z])[1][0], -1.0, -2.0)  # lowest point on the axis
    theta = inverse_position_branches(g, [0.0, 0.0, z])[0][0]
    report = singularities(g, theta)
    assert report.serial[0].max() < 1e-4                  # all three legs stretched
    assert report.serial_singular[0]
    assert "serial singularity of leg 1, 2, 3" in report.describe(0)
    assert not singularities(g, [0.3, 0.3, 0.3]).serial_singular[0]
