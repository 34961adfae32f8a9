"""Limit checks of a trajectory: one violation per joint, kind and piece, at the worst instant."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.planning import JointLimits


def test_check_names_joint_time_kind_of_each_violation():
    D, T = 2.0, 1.5
    traj = planning.polynomial([0.0, T], np.column_stack([[0.0, D], [0.0, 0.1]]), 5)
    vpeak = 15 * D / (8 * T)
    report = traj.check(JointLimits(velocity=[vpeak * 0.9, 10.0], acceleration=100.0))
    assert not report.ok and not bool(report)
    assert len(report.violations) == 1
    v = report.violations[0]
    assert (v.joint, v.kind) == (0, "velocity")
    assert v.time == pytest.approx(T / 2, abs=1e-9)  # peak velocity at mid-time
    assert v.value == pytest.approx(vpeak) and v.limit == pytest.approx(vpeak * 0.9)
    assert "joint 0" in str(report)
    # A limit equal to the exact peak passes.
    assert traj.check(JointLimits(velocity=vpeak)).ok
    # Position limits: joint 1 goes to 0.1 > 0.05.
    report = traj.check(JointLimits(velocity=10.0, lower=-1.0, upper=[3.0, 0.05]))
    assert [(v.joint, v.kind) for v in report.violations] == [(1, "position_upper")]
    assert report.violations[0].time == pytest.approx(T)


def test_check_reports_every_piece_with_a_violation():
    traj = planning.multi_quintic([0, 1, 2, 3], [0.0, 1.0, 0.0, 1.0])
    report = traj.check(JointLimits(velocity=1.0, acceleration=1e3, jerk=1e5))
    assert [v.kind for v in report.violations] == ["velocity"] * 3
    np.testing.assert_allclose([v.time for v in report.violations], [0.5, 1.5, 2.5], atol=1e-9)
    assert all(v.value == pytest.approx(15 / 8) for v in report.violations)
