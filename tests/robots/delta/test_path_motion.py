"""A platform path as the motors' motion: exact closed form, proven speed caps that a dense sample never beats."""

import numpy as np
import pytest

from pinarms.robots.delta import DeltaInputError, forward_position
from pinarms.robots.delta.path_motion import PlatformPath, tangent_bound


def test_tangent_bound_is_the_polynomials_largest_norm():
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 1.0, 20001)
    for _ in range(5):
        c = rng.normal(size=(3, 3))
        dense = np.linalg.norm(c[0] + np.outer(t, c[1]) + np.outer(t * t, c[2]), axis=1).max()
        assert dense <= tangent_bound(c) <= dense * (1 + 1e-6)


def test_path_is_the_closed_form_and_its_caps_hold(delta):
    a = forward_position(delta.geometry, [0.1, 0.4, 0.2])
    b = a + [0.35, -0.2, 0.08]
    path = PlatformPath(delta, lambda t: (a + np.outer(t, b - a), np.tile(b - a, (np.size(t), 1))), 1.0,
                        float(np.linalg.norm(b - a)))
    tau = np.linspace(0.0, 1.0, 4001)
    theta, rate = path.sample(tau)
    assert np.allclose(forward_position(delta.geometry, theta[:, :3]), a + np.outer(tau, b - a), atol=1e-9)
    numeric = np.gradient(theta[:, :3], tau, axis=0)
    assert np.allclose(rate[1:-1, :3], numeric[1:-1], atol=1e-4)
    cap = path.peaks().velocity
    assert np.abs(rate[:, :3]).max() <= cap[0] and cap[0] < 5 * np.abs(rate[:, :3]).max()
    assert path.platform_speed == pytest.approx(np.linalg.norm(b - a))


def test_path_leaving_the_motor_range_is_refused(delta):
    a = forward_position(delta.geometry, [0.1, 0.1, 0.1])
    b = a + [0.0, 0.0, 0.35]   # up past the motors' lower limit (-40 deg)
    with pytest.raises(DeltaInputError, match="range"):
        PlatformPath(delta, lambda t: (a + np.outer(t, b - a), np.tile(b - a, (np.size(t), 1))), 1.0, 0.35)
