"""Branch and bound over a layout search's candidates: the same best placement, refinement starts
and planned outcomes as the exhaustive search, and a bound no planned cycle beats."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.optim.layout.bound import _travel, cycle_lower_bounds, threshold
from pinarms.optim.layout.search import LayoutRequest, search_layout

PICK, PLACE = np.array([-0.2, 0.0, 0.14]), np.array([0.2, 0.0, 0.14])


@pytest.fixture(scope="module")
def scara():
    return robots.load("scara_mushroom")


@pytest.fixture(scope="module")
def candidates():
    """Bases from 50 to 400 mm beside the pick and the place (the nearer, the longer the swing), seeded jitter."""
    rng = np.random.default_rng(7)
    y = np.linspace(0.05, 0.40, 8)
    return np.column_stack([rng.uniform(-0.01, 0.01, 8), y, np.zeros(8), -np.pi / 2 + rng.uniform(-0.1, 0.1, 8)])


def test_the_bounded_search_agrees_with_the_exhaustive_one(scara, candidates):
    kw = dict(lift=0.02, dwell=0.05, refine=2, refine_evaluations=2, workspace_samples=2000)
    full = search_layout(LayoutRequest(scara, PICK, PLACE, candidates, **kw))
    fast = search_layout(LayoutRequest(scara, PICK, PLACE, candidates, bound=True, **kw))
    planned = [i for i, f in enumerate(fast.failure) if f != "outranked"]
    assert fast.failure.count("outranked") >= 1  # something was skipped: the test can tell the routes apart
    assert "not planned" in fast.reason[fast.failure.index("outranked")]
    # every candidate planned: the outcome of the exhaustive search, bit for bit
    assert [fast.failure[i] for i in planned] == [full.failure[i] for i in planned]
    assert np.array_equal(fast.cycle_time[planned], full.cycle_time[planned], equal_nan=True)
    # the same ranking among them, the same best placement and refinement starts
    assert [i for i in fast.order if i in planned] == [i for i in full.order if i in planned]
    assert np.array_equal(fast.best_placement, full.best_placement)
    assert fast.best_picks_per_minute == full.best_picks_per_minute
    assert np.array_equal(fast.refinement.starts, full.refinement.starts)
    # the bound: below every cycle of the exhaustive search, above every skipped candidate's limit
    ok = np.array([not f for f in full.failure])
    assert np.all(fast.lower_bound[ok] <= full.cycle_time[ok])
    second = np.sort(full.cycle_time[ok])[1]
    skipped = [i for i, f in enumerate(fast.failure) if f == "outranked"]
    assert np.all(fast.lower_bound[skipped] > second)
    assert full.lower_bound is None and set(fast.seconds) == {"screen", "cycles", "refine", "best"}


def test_the_bound_measures_joint_travel_at_the_velocity_limits(scara):
    # a joint spanning a full turn is measured the short way round; one that does not, as it is
    two_pi = 2.0 * np.pi
    assert _travel(np.array([3.0]), np.array([-3.0]), np.array([-two_pi]), np.array([two_pi]))[0] == \
        pytest.approx(two_pi - 6.0, abs=1e-12)
    assert _travel(np.array([3.0]), np.array([-3.0]), np.array([-3.1]), np.array([3.1]))[0] == 6.0
    # the base at the origin: 2 dwells and twice the slowest joint's travel from pick to place
    T = np.tile(np.eye(4), (1, 2, 1, 1))
    T[0, 0, :3, 3], T[0, 1, :3, 3] = PICK, PLACE
    got = cycle_lower_bounds(scara, T, 1, 0.1, None)[0]
    qa, qb = scara.ik_all(T[0, 0]), scara.ik_all(T[0, 1])
    travel = _travel(qa[:, None], qb[None], scara.lower, scara.upper) / scara.velocity_limit
    assert got == pytest.approx(0.2 + 2.0 * travel.max(axis=-1).min(), rel=1e-12)
    assert threshold([3.0, 1.0, 2.0], 2) == 2.0 and threshold([3.0], 2) == float("inf")


def test_with_an_acceleration_limit_the_bound_is_the_bang_bang_time_and_still_below_every_cycle(scara, candidates):
    from pinarms.optim.layout.bound import rest_to_rest_time
    from pinarms.planning.point_to_point import trapezoidal_phases

    d, v, a = np.array([0.0, 0.05, 0.8, 3.0]), np.array([1.0, 2.0, 1.0, 1.5]), np.array([2.0, 4.0, 1.0, 0.5])
    assert np.allclose(rest_to_rest_time(d, v, a), [trapezoidal_phases(*x)[1] for x in zip(d, v, a)], rtol=1e-14)
    assert np.array_equal(rest_to_rest_time(d, v, None), d / v)
    kw = dict(lift=0.02, dwell=0.05, refine=1, refine_evaluations=1, workspace_samples=2000, amax=4.0)
    full = search_layout(LayoutRequest(scara, PICK, PLACE, candidates[:5], **kw))
    fast = search_layout(LayoutRequest(scara, PICK, PLACE, candidates[:5], bound=True, **kw))
    ok = np.array([not f for f in full.failure])
    velocity_only = cycle_lower_bounds(scara, _targets(scara, candidates[:5]), 1, 0.05, None)
    assert np.all(fast.lower_bound[ok] <= full.cycle_time[ok])
    assert np.all(fast.lower_bound >= velocity_only) and np.any(fast.lower_bound > velocity_only * 1.05)
    assert np.array_equal(fast.best_placement, full.best_placement)


def _targets(robot, cand):
    """The tcp poses (M, 2, 4, 4) of the pick and the place in each candidate's base frame (the screen's)."""
    from pinarms.optim.layout.search import points_in_base_frame
    from pinarms.robots.reach.layout import default_orientation

    T = np.tile(np.eye(4), (cand.shape[0], 2, 1, 1))
    T[:, :, :3, :3] = default_orientation(robot)
    T[:, :, :3, 3] = points_in_base_frame(np.stack([PICK, PLACE]), cand)
    return T
