"""The Trajectory object: sampling, exact peaks, scaling, concatenation, definitions (checks: test_limit_report)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pinarms import planning
from pinarms.planning import Trajectory
from pinarms.planning.errors import OutOfTimeRange, TrajectoryError


def random_bspline(seed: int, n_seg: int = 6, n_joints: int = 3) -> Trajectory:
    rng = np.random.default_rng(seed)
    t = np.concatenate([[0.0], np.cumsum(rng.uniform(0.1, 0.5, n_seg))])
    q = rng.normal(size=(n_seg + 1, n_joints))
    return planning.quintic_bspline(t, q)


def test_sample_matches_the_stored_polynomials():
    breaks = [0.0, 1.0, 3.0]
    coefs = np.zeros((2, 3, 2))
    coefs[0, :, 0] = [1.0, 2.0, 3.0]  # 1 + 2 tau + 3 tau^2
    coefs[1, :, 0] = [6.0, 8.0, -1.0]
    coefs[0, :, 1] = [0.0, 0.0, 1.0]
    coefs[1, :, 1] = [1.0, 2.0, 0.0]
    traj = Trajectory(breaks, coefs)
    q, v, a, j = traj.sample([0.5, 1.0, 2.0, 3.0])
    np.testing.assert_allclose(q[:, 0], [1 + 1 + 0.75, 6.0, 6 + 8 - 1, 6 + 16 - 4])
    np.testing.assert_allclose(v[:, 0], [2 + 3.0, 8.0, 8 - 2, 8 - 4])
    np.testing.assert_allclose(a[:, 0], [6.0, -2.0, -2.0, -2.0])
    np.testing.assert_allclose(j, 0.0)
    np.testing.assert_allclose(q[:, 1], [0.25, 1.0, 3.0, 5.0])
    assert traj.n_joints == 2 and traj.n_segments == 2 and traj.degree == 2
    assert traj.duration == 3.0
    np.testing.assert_array_equal(traj.knot_times, breaks)


def test_unsorted_instants_give_the_same_samples():
    traj = random_bspline(1)
    t = np.linspace(0.0, traj.duration, 501)
    perm = np.random.default_rng(0).permutation(t.size)
    sorted_out = traj.sample(t)
    shuffled_out = traj.sample(t[perm])
    for a, b in zip(sorted_out, shuffled_out):
        np.testing.assert_array_equal(a[perm], b)


def test_one_joint_input_and_scalar_time():
    traj = planning.multi_quintic([0, 1, 2], [0.0, 1.0, 0.5])
    q, v, a, j = traj.sample(np.array([0.0, 0.5]))
    assert q.shape == (2, 1) and j.shape == (2, 1)
    q0, v0, _, _ = traj.sample(1.0)
    assert q0.shape == (1,) and q0[0] == pytest.approx(1.0)


def test_sampling_outside_the_time_range_is_refused():
    traj = planning.multi_quintic([0, 1, 2], [0.0, 1.0, 0.5])
    with pytest.raises(OutOfTimeRange, match="2.5"):
        traj.sample([0.0, 2.5])
    with pytest.raises(OutOfTimeRange, match="-0.1"):
        traj.sample(-0.1)
    with pytest.raises(TrajectoryError, match="finite"):
        traj.sample([np.nan])
    # Rounding at the end is tolerated and clipped.
    assert traj.sample(2.0 + 1e-14)[0][0] == pytest.approx(0.5)


def test_at_rate_includes_both_ends():
    traj = planning.multi_quintic([0, 0.25, 1.05], [0.0, 1.0, 0.5])
    t, q, v, a, j = traj.at_rate(10.0)
    np.testing.assert_allclose(t[:-1], np.arange(11) * 0.1)
    assert t[-1] == 1.05 and q.shape == (12, 1)
    assert q[-1, 0] == pytest.approx(0.5)
    with pytest.raises(TrajectoryError, match="hz"):
        traj.at_rate(0.0)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), n_seg=st.integers(1, 8))
def test_exact_peaks_bound_and_match_dense_sampling(seed, n_seg):
    traj = random_bspline(seed, n_seg=n_seg, n_joints=2)
    peaks = traj.peaks()
    t = np.linspace(0.0, traj.duration, 4001)
    _, v, a, j = traj.sample(np.concatenate([t, traj.knot_times]))
    for exact, sampled in ((peaks.velocity, v), (peaks.acceleration, a), (peaks.jerk, j)):
        dense = np.abs(sampled).max(axis=0)
        assert np.all(dense <= exact * (1 + 1e-9) + 1e-12)
        np.testing.assert_allclose(dense, exact, rtol=2e-3)


def test_peaks_of_a_known_quintic():
    # Rest-to-rest quintic over distance D in T: vmax = 15 D / (8 T), amax = 10 D / (sqrt(3) T^2), |jerk| max 60 D / T^3.
    D, T = 2.0, 1.5
    traj = planning.polynomial([0.0, T], [0.0, D], 5)
    p = traj.peaks()
    assert p.velocity[0] == pytest.approx(15 * D / (8 * T), rel=1e-12)
    assert p.acceleration[0] == pytest.approx(10 * D / (np.sqrt(3) * T**2), rel=1e-12)
    assert p.jerk[0] == pytest.approx(60 * D / T**3, rel=1e-12)
    assert p.as_dict()["velocity"] == pytest.approx([15 * D / (8 * T)])


def test_peaks_are_found_once_and_each_call_gets_its_own_arrays(monkeypatch):
    traj = planning.polynomial([0.0, 1.5], [0.0, 2.0], 5)
    first = traj.peaks()
    searches = []
    original = Trajectory._extrema
    monkeypatch.setattr(Trajectory, "_extrema", lambda self, *a, **k: searches.append(a) or original(self, *a, **k))
    first.velocity[:] = -1.0  # a caller editing its copy changes nothing for the next one
    again = traj.peaks()
    assert not searches
    assert again.velocity[0] == pytest.approx(15 * 2.0 / (8 * 1.5), rel=1e-12)
    fresh = planning.polynomial([0.0, 1.5], [0.0, 2.0], 5).peaks()
    np.testing.assert_array_equal(again.acceleration, fresh.acceleration)
    assert len(searches) == 1  # the new trajectory searched its own


def test_scaled_divides_derivatives_by_powers_of_the_factor():
    traj = random_bspline(3)
    slow = traj.scaled(2.0)
    assert slow.duration == pytest.approx(2.0 * traj.duration)
    p, ps = traj.peaks(), slow.peaks()
    np.testing.assert_allclose(ps.velocity, p.velocity / 2)
    np.testing.assert_allclose(ps.acceleration, p.acceleration / 4)
    np.testing.assert_allclose(ps.jerk, p.jerk / 8)
    t = np.linspace(0, traj.duration, 7)
    np.testing.assert_allclose(slow.sample(2 * t)[0], traj.sample(t)[0], atol=1e-12)
    with pytest.raises(TrajectoryError, match="positive"):
        traj.scaled(-1.0)


def test_concatenated_shifts_time_and_requires_matching_positions():
    a = planning.multi_quintic([0, 1], [[0.0, 0.0], [1.0, 2.0]])
    b = planning.quintic_bspline([0, 0.5, 2.0], [[1.0, 2.0], [1.5, 1.0], [0.0, 0.0]])
    ab = a.concatenated(b)
    assert ab.duration == pytest.approx(3.0)
    np.testing.assert_allclose(ab.knot_times, [0, 1, 1.5, 3.0])
    np.testing.assert_allclose(ab.sample(2.0)[0], b.sample(1.0)[0])
    np.testing.assert_allclose(ab.sample(0.3)[0], a.sample(0.3)[0])
    with pytest.raises(TrajectoryError, match="joint 0 ends at 1.0"):
        a.concatenated(planning.multi_quintic([0, 1], [[0.5, 2.0], [0.0, 0.0]]))
    with pytest.raises(TrajectoryError, match="3-joint"):
        a.concatenated(planning.multi_quintic([0, 1], np.zeros((2, 3)) + [1.0, 2.0, 0.0]))


def _all_kinds() -> list[Trajectory]:
    t = [0.0, 0.5, 1.2, 2.0]
    q = np.array([[0.0, 1.0], [0.4, 0.8], [1.0, 0.2], [1.2, 0.0]])
    base = [
        planning.polynomial(t, q, 7),
        planning.piecewise_polynomial(t, q, "3-5-3"),
        planning.multi_quintic(t, q),
        planning.multi_quintic(t, q, "heuristic", "continuous"),
        planning.multi_quintic(t, q, velocities=np.ones_like(q) * 0.1),
        planning.quintic_bspline(t, q, start_velocity=[0.1, 0.0]),
        planning.trapezoidal([0.0, 1.0], [1.0, -1.0], 1.0, 2.0),
        planning.double_s([0.0, 1.0], [1.0, -1.0], 1.0, 2.0, 10.0),
        Trajectory([0.0, 1.0], np.ones((1, 2, 2))),
    ]
    base.append(base[2].scaled(1.5))
    base.append(base[2].shifted(3.0))
    base.append(base[6].concatenated(planning.trapezoidal([1.0, -1.0], [0.0, 1.0], 1.0, 2.0)))
    return base


@pytest.mark.parametrize("index", range(12))
def test_definition_round_trip_through_json(index):
    traj = _all_kinds()[index]
    text = json.dumps(traj.definition)
    again = planning.from_definition(json.loads(text))
    assert again.definition == traj.definition
    np.testing.assert_array_equal(again.knot_times, traj.knot_times)
    np.testing.assert_allclose(again.coefficients, traj.coefficients, rtol=0, atol=0)


def test_from_definition_rejects_unknown_kinds():
    with pytest.raises(TrajectoryError, match="unknown trajectory kind 'spline9'"):
        planning.from_definition({"kind": "spline9"})
    with pytest.raises(TrajectoryError, match="lacks the field 'degree'"):
        planning.from_definition({"kind": "polynomial", "times": [0, 1], "positions": [0, 1]})


def test_trajectory_arrays_are_read_only_copies():
    traj = random_bspline(5)
    k = traj.knot_times
    k[0] = 99.0
    assert traj.start_time == 0.0
    c = traj.coefficients
    c[:] = 0.0
    assert np.abs(traj.coefficients).max() > 0
