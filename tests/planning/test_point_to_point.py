"""Trapezoidal and double-S rest-to-rest profiles (Biagiotti & Melchiorri, ch. 3)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.planning import JointLimits
from pinarms.planning.point_to_point import double_s_phases, trapezoidal_phases


@pytest.mark.parametrize(
    "distance, vmax, amax, T, vpeak",
    [
        (2.0, 1.0, 2.0, 2.0 / 1.0 + 1.0 / 2.0, 1.0),  # cruise reached: T = d/v + v/a
        (0.2, 1.0, 2.0, 2 * np.sqrt(0.2 / 2.0), np.sqrt(0.2 * 2.0)),  # triangular
    ],
)
def test_trapezoidal_duration_and_peaks(distance, vmax, amax, T, vpeak):
    traj = planning.trapezoidal(0.5, 0.5 + distance, vmax, amax)
    assert traj.duration == pytest.approx(T, rel=1e-12)
    p = traj.peaks()
    assert p.velocity[0] == pytest.approx(vpeak, rel=1e-12)
    assert p.acceleration[0] == pytest.approx(amax, rel=1e-12)
    q, v, _, _ = traj.sample([0.0, T])
    np.testing.assert_allclose(q[:, 0], [0.5, 0.5 + distance], atol=1e-12)
    np.testing.assert_allclose(v[:, 0], 0.0, atol=1e-12)


def test_double_s_reaches_all_limits_on_a_long_move():
    # B&M example 3.9 style numbers: d = 10, vmax 5, amax 10, jmax 30.
    traj = planning.double_s(0.0, 10.0, 5.0, 10.0, 30.0)
    Tj, Ta, Tv = double_s_phases(10.0, 5.0, 10.0, 30.0)
    assert (Tj, Ta) == pytest.approx((1 / 3, 1 / 3 + 0.5))
    assert Tv == pytest.approx(10.0 / 5.0 - Ta)
    assert traj.duration == pytest.approx(2 * Ta + Tv)
    p = traj.peaks()
    np.testing.assert_allclose([p.velocity[0], p.acceleration[0], p.jerk[0]], [5.0, 10.0, 30.0], rtol=1e-12)
    q, v, a, _ = traj.sample([0.0, traj.duration])
    np.testing.assert_allclose(q[:, 0], [0.0, 10.0], atol=1e-12)
    np.testing.assert_allclose(np.r_[v[:, 0], a[:, 0]], 0.0, atol=1e-12)


@pytest.mark.parametrize(
    "distance, vmax, amax, jmax, reached",
    [
        (10.0, 5.0, 10.0, 30.0, (True, True)),
        (1.0, 5.0, 10.0, 30.0, (False, False)),  # short: neither vmax nor amax
        (3.0, 5.0, 2.0, 100.0, (False, True)),  # amax reached, vmax not
        (10.0, 1.0, 10.0, 30.0, (True, False)),  # vmax reached before amax
    ],
)
def test_double_s_cases_respect_the_limits_exactly(distance, vmax, amax, jmax, reached):
    traj = planning.double_s(-1.0, -1.0 - distance, vmax, amax, jmax)
    p = traj.peaks()
    assert traj.check(JointLimits(vmax, amax, jmax)).ok
    assert np.isclose(p.velocity[0], vmax, rtol=1e-9) == reached[0]
    assert np.isclose(p.acceleration[0], amax, rtol=1e-9) == reached[1]
    assert p.jerk[0] == pytest.approx(jmax)
    assert traj.sample(traj.duration)[0][0] == pytest.approx(-1.0 - distance, abs=1e-12)
    # Minimum time: shorter durations would break a limit.
    assert not traj.scaled(0.99).check(JointLimits(vmax, amax, jmax)).ok


def test_synchronised_joints_share_the_slowest_duration():
    q0, q1 = [0.0, 0.0, 1.0], [2.0, 0.5, 1.0]
    traj = planning.trapezoidal(q0, q1, [1.0, 1.0, 1.0], 2.0)
    assert traj.duration == pytest.approx(trapezoidal_phases(2.0, 1.0, 2.0)[1])
    q, v, _, _ = traj.sample([0.0, traj.duration])
    np.testing.assert_allclose(q, [q0, q1], atol=1e-12)
    p = traj.peaks()
    assert p.velocity[1] < 1.0 and p.velocity[2] == 0.0
    # Unsynchronised: joint 1 arrives early and holds.
    free = planning.trapezoidal(q0, q1, 1.0, 2.0, synchronized=False)
    T1 = trapezoidal_phases(0.5, 1.0, 2.0)[1]
    assert free.sample(T1 + 0.01)[0][1] == pytest.approx(0.5)
    assert free.sample(T1 + 0.01)[1][1] == pytest.approx(0.0)
    ds = planning.double_s(q0, q1, 1.0, 2.0, 10.0)
    assert ds.check(JointLimits(1.0, 2.0, 10.0)).ok
    np.testing.assert_allclose(ds.sample(ds.duration)[0], q1, atol=1e-12)


def test_point_to_point_bad_input():
    with pytest.raises(planning.TrajectoryError, match="no motion"):
        planning.trapezoidal([1.0], [1.0], 1.0, 1.0)
    with pytest.raises(planning.TrajectoryError, match="amax must be positive"):
        planning.trapezoidal(0.0, 1.0, 1.0, 0.0)
    with pytest.raises(planning.TrajectoryError, match="same shape"):
        planning.double_s([0.0, 1.0], [1.0], 1.0, 1.0, 1.0)
