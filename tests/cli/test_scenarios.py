"""pinarms.scenarios: the paper numbers come from pinarms.papers; seed 002's one representative path."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms import scenarios
from pinarms.robots.conventions import GANTRY_TRANSMISSION_M_PER_RAD
from pinarms.papers import SEED000, SEED001, SEED002


def test_seed000_and_seed001_read_the_papers_module():
    s0 = scenarios.seed000()
    np.testing.assert_array_equal(s0.positions[:, 0], SEED000.path_rad)
    assert s0.vmax[0] == SEED000.vmax_rad_s
    assert s0.paper["total"] == 3.607 and s0.paper["durations"] == [1.086, 1.243, 1.278]
    s1 = scenarios.seed001()
    np.testing.assert_array_equal(s1.positions, SEED001.table2_joints)
    np.testing.assert_allclose(s1.initial_durations, [1.0, 2.0, 1.0])
    np.testing.assert_allclose(s1.vmax, np.radians(210.0))


def test_seed002_path_is_the_axis_path_through_the_transmission():
    s2 = scenarios.seed002()
    assert scenarios.GANTRY_MOTOR_RAD_PER_M == pytest.approx(1.0 / GANTRY_TRANSMISSION_M_PER_RAD, rel=1e-15)
    np.testing.assert_allclose(s2.positions * GANTRY_TRANSMISSION_M_PER_RAD, scenarios.GANTRY_PATH_AXIS_M, atol=1e-15)
    np.testing.assert_array_equal(s2.positions, scenarios.gantry_path_motor_rad())
    assert s2.positions.shape == (SEED002.segments + 1, 3)
    np.testing.assert_array_equal(s2.initial_durations, SEED002.initial_durations_s)
    assert (s2.vmax[0], s2.amax[0], s2.jmax[0]) == SEED002.limits_motor


def test_seed002_path_is_lift_feed_lower_inside_the_gantry_travel():
    path = scenarios.GANTRY_PATH_AXIS_M
    arm = robots.load("gantry_flower")
    assert np.all(arm.within_limits(path))
    z = path[:, 2]
    assert z[0] == z[-1] and np.all(np.diff(z[:5]) >= 0) and np.all(np.diff(z[6:]) <= 0)  # lift ... lower
    assert path[1, 0] == path[0, 0] and path[-2, 0] == path[-1, 0]  # vertical at pick and place
    assert np.all(np.diff(path[:, 0]) >= 0)  # feed in x never reverses


def test_path_is_read_only():
    with pytest.raises(ValueError):
        scenarios.GANTRY_PATH_AXIS_M[0, 0] = 1.0
    fresh = scenarios.gantry_path_motor_rad()
    fresh[0, 0] = -1.0
    assert scenarios.gantry_path_motor_rad()[0, 0] == pytest.approx(10.0)
