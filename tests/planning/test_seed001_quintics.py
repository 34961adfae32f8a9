"""Seed 001 (AUBO-i3): three quintic segments vs one quintic vs one septic; Table 3."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.papers import SEED001

TIMES = list(SEED001.via_times_s)
# Table 2, joints J1..J6 (rad), points P1..P4.
VIA = SEED001.table2_joints
# Table 3: t (s), J1, J2, J3 (rad) measured on the robot every 0.2 s.
TABLE3 = np.column_stack([SEED001.table3_t_s, SEED001.table3_joints_rad])


def test_table3_within_1e3_rad():
    traj = planning.multi_quintic(TIMES, VIA)
    q = traj.sample(TABLE3[:, 0])[0][:, :3]
    diff = np.abs(q - TABLE3[:, 1:])
    assert diff.max() <= 1e-3
    # Rows off by more than 1e-4 (rounding of the 4-decimal table is 5e-5): t = 2.2 ... 3.0 s,
    # where the robot lags behind the plan on its way into P3 (largest: J2 at 3.0 s, 8e-4 rad).
    off_rows = TABLE3[diff.max(axis=1) > 1e-4, 0]
    np.testing.assert_allclose(off_rows, [2.2, 2.4, 2.6, 2.8, 3.0])
    assert diff.max() == pytest.approx(8.0e-4, abs=1e-6)
    assert np.unravel_index(np.argmax(diff), diff.shape) == (15, 1)
    # Everything else agrees to the table's rounding.
    assert diff[diff.max(axis=1) <= 1e-4].max() <= 0.75e-4


def test_multi_quintic_stops_at_every_via_point():
    traj = planning.multi_quintic(TIMES, VIA)
    q, v, a, _ = traj.sample(TIMES)
    np.testing.assert_allclose(q, VIA, atol=1e-12)
    np.testing.assert_allclose(v, 0.0, atol=1e-12)
    np.testing.assert_allclose(a, 0.0, atol=1e-11)


def test_single_quintic_misses_p2_p3():
    quintic = planning.polynomial([0.0, 4.0], VIA[[0, 3]], degree=5)
    miss = quintic.sample([1.0, 3.0])[0] - VIA[[1, 2]]
    # Joint 1 misses P2 and P3 by 0.3523 rad (20.2 deg) each; the largest miss over all joints.
    assert np.abs(miss).max() == pytest.approx(0.35231, abs=1e-5)
    np.testing.assert_allclose(np.abs(miss[:, 0]), 0.35231, atol=1e-5)
    np.testing.assert_allclose(np.abs(miss[:, 1]), 0.32520, atol=1e-5)
    # It still starts and ends at rest at P1 and P4.
    q, v, a, _ = quintic.sample([0.0, 4.0])
    np.testing.assert_allclose(q, VIA[[0, 3]], atol=1e-12)
    np.testing.assert_allclose(v, 0.0, atol=1e-12)


def test_septic_passes_p2_p3_but_overshoots_near_the_ends():
    septic = planning.polynomial(TIMES, VIA, degree=7)
    np.testing.assert_allclose(septic.sample(TIMES)[0], VIA, atol=1e-12)
    lo, hi = septic.position_range()
    below = VIA.min(axis=0) - lo
    above = hi - VIA.max(axis=0)
    # Joint 1 first moves the wrong way (below P1) and then beyond P4: 0.0713 rad (4.1 deg) each.
    assert below[0] == pytest.approx(0.07129, abs=1e-5)
    assert above[0] == pytest.approx(0.07129, abs=1e-5)
    assert below[1] == pytest.approx(0.06580, abs=1e-5)
    # Where: joint 1's minimum lies within the first second, its maximum within the last.
    t = np.linspace(0.0, 4.0, 40001)
    q1 = septic.sample(t)[0][:, 0]
    assert 0.0 < t[np.argmin(q1)] < 1.0
    assert 3.0 < t[np.argmax(q1)] < 4.0
    # The three-quintic trajectory never leaves the via points' range (no overshoot).
    lo3, hi3 = planning.multi_quintic(TIMES, VIA).position_range()
    assert np.all(lo3 >= VIA.min(axis=0) - 1e-12) and np.all(hi3 <= VIA.max(axis=0) + 1e-12)


def test_peak_velocities_of_the_three_methods():
    three = planning.multi_quintic(TIMES, VIA).peaks().velocity
    quintic = planning.polynomial([0.0, 4.0], VIA[[0, 3]], 5).peaks().velocity
    septic = planning.polynomial(TIMES, VIA, 7).peaks().velocity
    # Joint 1 moves 3.4034 rad in the 2 s middle segment: peak 15/8 * 3.4034 / 2 = 3.1907 rad/s.
    assert three[0] == pytest.approx(15 / 8 * (0.7854 + 2.6180) / 2.0, rel=1e-12)
    assert quintic[0] == pytest.approx(15 / 8 * (0.7854 + 2.6180) / 4.0, rel=1e-12)
    assert quintic[0] < septic[0] < three[0]
    # AUBO-i3 limit quoted by the paper: 210 deg/s = 3.665 rad/s; all three stay below.
    assert three.max() < np.deg2rad(210.0)
