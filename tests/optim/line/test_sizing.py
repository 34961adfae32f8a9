"""Sizing: the fewest arms for a flow, by the GA, Monte Carlo over seeds."""

import numpy as np
import pytest

from pinarms.optim.line import ItemType, TaskMap
from pinarms.optim.errors import SettingOutOfRange
from pinarms.optim.line.sizing import SizingProblem, SizingStatus, evaluate_layouts, size_line
from pinarms.errors import InvalidInput


def _map(speed=0.2, cycle_part=1.0):
    du, w = np.linspace(-0.3, 0.3, 13), np.array([-0.15, 0.15])
    return TaskMap("a", du, w, np.full((13, 2), cycle_part), np.full((13, 2), cycle_part), 0.5, 0.1, speed, 0.1)


def test_fewest_arms_meet_the_miss_rate_and_one_fewer_does_not():
    # a 2.6 s cycle: one arm takes about 23 items/min; 50/min needs at least three
    p = SizingProblem({0.2: _map()}, rate=50.0, max_miss=0.02, item=ItemType("x"), seeds=(0, 1), duration=240.0,
                      min_gap=0.7, max_gap=1.2, population=6, generations=2)
    r = size_line(p)
    assert r.status is SizingStatus.OK and r.arms >= 3 and r.status_reason == ""
    assert r.miss_rate <= 0.02
    assert r.arms - 1 in r.tried and r.tried[r.arms - 1] > 0.02  # one arm fewer was tried and misses more
    gaps = np.diff(r.positions)
    assert np.all(gaps >= 0.7 - 1e-12) and np.all(gaps <= 1.2 + 1e-12)
    # the reported miss rate is the mean over the seeds of that layout
    again = evaluate_layouts(p, [(np.array(r.positions), r.speed)])[0]
    assert again[0] == pytest.approx(r.miss_rate, abs=1e-15)


def test_sizing_problem_checks_its_maps():
    with pytest.raises(InvalidInput, match="built for 0.2 m/s"):
        SizingProblem({0.3: _map(0.2)}, rate=10.0)


@pytest.mark.parametrize("field, value, words", [
    ("n_min", 5, "n_min = 5 is outside the range allowed, 1 to 4"),  # more than max_arms: nothing to try
    ("max_arms", 0, "max_arms = 0 is outside"), ("population", 1, "population = 1 is outside"),
    ("generations", 0, "generations = 0 is outside"), ("seed", -1, "seed = -1 is outside"),
    ("rate", float("nan"), "rate must be a finite number > 0"), ("max_miss", 1.5, "max_miss must be a finite number"),
])
def test_sizing_problem_refuses_bad_search_settings_by_name(field, value, words):
    with pytest.raises(SettingOutOfRange, match=words):
        SizingProblem({0.2: _map()}, **{"rate": 10.0, "max_arms": 4, field: value})


def test_a_flow_that_needs_more_arms_than_allowed_is_a_status_not_a_crash():
    # one 2.6 s arm takes about 23 items/min: 200/min needs at least 8, max_arms 3
    r = size_line(SizingProblem({0.2: _map()}, rate=200.0, max_arms=3, seeds=(0,), duration=60.0))
    assert r.status is SizingStatus.NOT_FOUND and r.tried == {} and r.evaluations == 0
    assert "at least 8 arms" in r.status_reason and "max_arms = 3" in r.status_reason


@pytest.mark.slow
def test_serial_and_dask_give_identical_results():
    p = SizingProblem({0.2: _map()}, rate=40.0, item=ItemType("x"), seeds=(0, 1, 2), duration=120.0)
    layouts = [(np.array([0.6, 1.5]), 0.2), (np.array([0.6, 1.8, 2.9]), 0.2)]
    serial = evaluate_layouts(p, layouts)
    dask = evaluate_layouts(p, layouts, scheduler="processes:2")
    assert np.array_equal(serial, dask)


def _half_map(side):
    """Cycle 2.6 s, feasible only on one half of the belt (w >= 0 near side, w <= 0 far side)."""
    du, w = np.linspace(-0.3, 0.3, 13), np.array([-0.15, 0.0, 0.15])
    t = np.full((13, 3), 1.0)
    t[:, 0 if side == 0 else 2] = np.nan
    return TaskMap("a", du, w, t, t.copy(), 0.5, 0.1, 0.2, 0.1)


def test_arms_on_both_sides_when_each_side_reaches_half_the_belt():
    kw = dict(rate=12.0, max_miss=0.05, item=ItemType("x"), seeds=(0, 1), duration=240.0, min_gap=0.7, max_gap=1.2)
    one = size_line(SizingProblem({0.2: _half_map(0)}, **kw, n_min=2, max_arms=3, population=6, generations=2))
    assert one.status is SizingStatus.NOT_FOUND and min(one.tried.values()) > 0.3  # half the items out of reach
    assert one.arms is None and "no line of 2 to 3 arms meets the miss rate 5 %" in one.status_reason
    two = SizingProblem({0.2: _half_map(0)}, far_maps={0.2: _half_map(1)}, **kw, n_min=2, max_arms=3, population=8,
                        generations=3)
    r = size_line(two)
    assert r.status is SizingStatus.OK and set(r.sides) == {0, 1} and len(r.sides) == r.arms
    again = evaluate_layouts(two, [(np.array(r.positions), r.speed, r.sides)])[0]
    assert again[0] == pytest.approx(r.miss_rate, abs=1e-15) and again[0] <= 0.05
    with pytest.raises(InvalidInput, match="far_maps"):
        SizingProblem({0.2: _half_map(0)}, far_maps={0.3: _half_map(1)}, rate=10.0)
