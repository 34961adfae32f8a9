"""Tie rules: a choice among values equal up to rounding does not depend on the last bit."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.robots.ties import argmin_tied, argsort_tied, near_max


def test_near_max_lists_every_joint_at_the_limit_in_joint_order():
    # the seed 001 case: two joints at their limit, one larger than the other in the last bit
    ratios = np.array([1.0, 0.923, 0.9994, 1.0 - 2e-16, 0.0, 0.231])
    assert near_max(ratios).tolist() == [0, 3]
    assert near_max(ratios[[3, 1, 2, 0, 4, 5]]).tolist() == [0, 3]  # the same set whichever is larger
    assert near_max([0.5, 1.0, 0.999]).tolist() == [1]  # 1e-3 apart is no tie
    assert near_max([np.nan, np.inf]).tolist() == []


def test_argmin_tied_takes_the_lowest_index_among_equal_values():
    assert argmin_tied([0.3, 0.1 + 1e-17, 0.1, 0.2]) == 1
    assert argmin_tied([0.3, 0.1, 0.1 - 1e-17]) == 1
    assert argmin_tied([0.3, 0.1, 0.1 - 1e-6]) == 2
    with pytest.raises(ValueError):
        argmin_tied([])


def test_argsort_tied_keeps_index_order_within_a_tie():
    d = np.array([2.0, 1.0 + 1e-15, 1.0, 3.0, np.nan, 1.0 - 1e-15])
    assert argsort_tied(d).tolist() == [1, 2, 5, 0, 3, 4]
    assert argsort_tied([]).tolist() == []


def test_timing_where_two_joints_tie_names_both():
    """A constructed timing: joints 0 and 2 have the same |Δq| / v_max, so both end at their limit."""
    from pinarms import optim
    from pinarms import robots
    from pinarms.robots.ties import near_max

    arm = robots.load("aubo_i3")
    v = arm.velocity_limit
    q = np.zeros((2, 6))
    q[1, 0] = 0.7 * v[0]
    q[1, 2] = 0.7 * v[2]  # same ratio as joint 0
    q[1, 1] = 0.3 * v[1]
    best = optim.minimize_time(optim.TimingRequest(q, "multi-quintic", v, method="exact"))
    ratio = best.peaks.velocity / v
    assert np.isclose(ratio[0], 1.0) and np.isclose(ratio[2], 1.0)
    assert near_max(ratio).tolist() == [0, 2]
