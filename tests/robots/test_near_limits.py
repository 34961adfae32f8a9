"""Joint-limit tolerance of the IK, and closed-form solutions a little outside the ranges (seed 004)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.errors import InvalidInput, UnreachableTarget
from pinarms.robots.ik import limit_excess, near_limit_solutions

DEG = np.pi / 180.0


@pytest.fixture(scope="module")
def koji():
    return robots.load("koji_turner")


def _printed_pose() -> np.ndarray:
    """Seed 004's printed FK (1197.3, 250, −929.2) mm, tool level (the base's orientation)."""
    T = np.eye(4)
    T[:3, 3] = [1.1973, 0.25, -0.9292]
    return T


def test_printed_pose_needs_the_shoulder_past_its_range(koji):
    T = _printed_pose()
    assert koji.ik_all(T).shape == (0, 4)
    near = near_limit_solutions(koji, T, within=1.0 * DEG)
    assert len(near) == 1
    s = near[0]
    np.testing.assert_allclose(s.q / DEG, [-90.0, 25.0011, -30.0046, 90.0], atol=1e-4)
    assert s.joints == ("shoulder", "forearm")
    np.testing.assert_allclose(s.excess / DEG, [0.0, 0.00113, -0.00461, 0.0], atol=1e-5)  # above 25°, below −30°
    assert s.worst == pytest.approx(0.00461 * DEG, abs=1e-7)
    assert near_limit_solutions(koji, T, within=0.004 * DEG) == []  # the forearm misses by more


def test_limit_tolerance_accepts_it_unclamped(koji):
    T = _printed_pose()
    q = koji.ik_all(T, limit_tolerance=0.005 * DEG)
    assert q.shape == (1, 4)
    np.testing.assert_allclose(koji.fk(q[0]), T, atol=1e-9)  # meets the pose: not clamped onto the range
    assert q[0, 1] > koji.upper[1] and q[0, 2] < koji.lower[2]
    assert koji.ik_all(T, limit_tolerance=0.004 * DEG).shape == (0, 4)
    with pytest.raises(UnreachableTarget, match="outside its limits"):
        koji.ik(T)
    q1 = koji.ik(T, limit_tolerance=0.005 * DEG)
    np.testing.assert_allclose(q1, q[0], atol=1e-9)
    assert koji.within_limits(q1, tol=0.005 * DEG) and not koji.within_limits(q1)
    for bad in (-1.0, float("nan"), "0.1", True):
        with pytest.raises(InvalidInput, match="limit_tolerance"):
            koji.ik_all(T, limit_tolerance=bad)
        with pytest.raises(InvalidInput, match="limit_tolerance"):
            koji.ik(T, limit_tolerance=bad)


def test_a_configuration_within_the_limits_is_preferred(koji):
    q_in = np.array([-0.5, 0.2, -0.1, 0.4])
    T = koji.fk(q_in)
    strict = koji.ik_all(T)
    np.testing.assert_array_equal(koji.ik_all(T, limit_tolerance=0.01), strict)
    q = koji.ik(T, limit_tolerance=0.01)
    assert koji.within_limits(q)


def test_limit_excess_wraps_revolute_angles():
    ur5 = robots.load("ur5")  # ±2π ranges: every angle is within after wrapping
    q = np.array([7.0, -7.0, 0.0, 0.0, 0.0, 0.0])
    q_w, excess = limit_excess(ur5, q)
    assert np.all(excess == 0.0)
    np.testing.assert_allclose(np.cos(q_w), np.cos(q))
    aubo = robots.load("aubo_i3")  # ±170°
    _, excess = limit_excess(aubo, np.array([175.0, 0, 0, 0, 0, -175.0]) * DEG)
    np.testing.assert_allclose(excess / DEG, [5.0, 0, 0, 0, 0, -5.0], atol=1e-9)
