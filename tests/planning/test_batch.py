"""Batched constructors and peaks: equal to the single-trajectory ones, and checked input."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import make_interp_spline

from pinarms import planning
from pinarms.planning.errors import ConditionCountError, TrajectoryError

RNG = np.random.default_rng(20240605)


def _times(rng: np.random.Generator, P: int, m: int, low: float = 0.05, high: float = 2.0) -> np.ndarray:
    """(P, m+1) knot times with log-uniform durations in [low, high] s and a random start."""
    h = np.exp(rng.uniform(np.log(low), np.log(high), (P, m)))
    start = rng.uniform(-1.0, 1.0, (P, 1))
    return np.concatenate([start, start + np.cumsum(h, axis=1)], axis=1)


def _close(batch: np.ndarray, single: np.ndarray, rtol: float = 1e-12) -> None:
    np.testing.assert_allclose(batch, single, rtol=rtol, atol=rtol * np.abs(single).max())


@pytest.mark.parametrize(
    "degrees, options",
    [((3, 5, 3), {}), ((4, 3, 4), {}), ((5,), {}), ((5, 5, 5, 5), {"continuity": 4}),
     ((3, 3), {"continuity": 2, "end_order": 1})],
)
def test_piecewise_batch_equals_single(degrees, options):
    m = len(degrees)
    t = _times(RNG, 40, m)
    q = RNG.normal(size=(m + 1, 4))
    coefs = planning.piecewise_polynomial_batch(t, q, degrees, **options)
    assert coefs.shape == (40, m, max(degrees) + 1, 4)
    single = np.stack([planning.piecewise_polynomial(row, q, degrees, **options).coefficients for row in t])
    _close(coefs, single)
    # The solution interpolates: every row passes its via points at its own times.
    traj = planning.Trajectory(t[7], coefs[7])
    np.testing.assert_allclose(traj(t[7]), q, atol=1e-12 * np.abs(q).max())


@pytest.mark.parametrize(
    "velocities, accelerations",
    [(None, None), ("heuristic", None), ("heuristic", "continuous"), ("zero", "continuous"),
     ("given", "given")],
)
def test_multi_quintic_batch_equals_single(velocities, accelerations):
    m = 6
    t = _times(RNG, 30, m)
    q = RNG.normal(size=(m + 1, 3))
    v = RNG.normal(size=(m + 1, 3)) if velocities == "given" else velocities
    a = RNG.normal(size=(m + 1, 3)) if accelerations == "given" else accelerations
    coefs = planning.multi_quintic_batch(t, q, v, a)
    assert coefs.shape == (30, m, 6, 3)
    single = np.stack([planning.multi_quintic(row, q, v, a).coefficients for row in t])
    _close(coefs, single)


def test_quintic_bspline_batch_equals_single_and_scipy():
    m = 10
    # Durations spread over a factor 400 (wider than the optimisers' default bounds allow).
    t = _times(RNG, 25, m, low=0.005, high=2.0)
    q = RNG.normal(size=(m + 1, 3)) * 50.0
    v0, a1 = np.array([1.0, -2.0, 0.5]), np.array([0.0, 30.0, -10.0])
    coefs = planning.quintic_bspline_batch(t, q, start_velocity=v0, end_acceleration=a1)
    single = np.stack([planning.quintic_bspline(row, q, start_velocity=v0, end_acceleration=a1).coefficients
                       for row in t])
    _close(coefs, single)
    zero = np.zeros(3)
    for p in range(t.shape[0]):
        ref = make_interp_spline(t[p], q, k=5, bc_type=([(1, v0), (2, zero)], [(1, zero), (2, a1)]))
        traj = planning.Trajectory(t[p], coefs[p])
        s = np.linspace(t[p, 0], t[p, -1], 400)
        out = traj.sample(s)
        for nu in range(4):
            expected = ref(s, nu)
            np.testing.assert_allclose(out[nu], expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())


def test_peaks_batch_equals_trajectory_peaks_per_row_and_piece():
    m = 10
    t = _times(RNG, 20, m)
    q = RNG.normal(size=(m + 1, 3))
    coefs = planning.quintic_bspline_batch(t, q)
    per_piece = planning.piece_peaks_batch(t, coefs)
    whole = planning.peaks_batch(t, coefs)
    assert per_piece.shape == (20, 3, m, 3) and whole.shape == (20, 3, 3)
    for p in range(t.shape[0]):
        pk = planning.Trajectory(t[p], coefs[p]).peaks()
        _close(whole[p], np.stack([pk.velocity, pk.acceleration, pk.jerk]))
        # Piece by piece: a one-piece trajectory of piece i has the same peaks.
        for i in (0, m // 2, m - 1):
            pi = planning.Trajectory(t[p, i : i + 2], coefs[p, i : i + 1]).peaks()
            _close(per_piece[p, :, i], np.stack([pi.velocity, pi.acceleration, pi.jerk]))
    # 3-5-3 (degree 5 padded cubics, a degree-6 pattern would use the eigenvalue path).
    t3 = _times(RNG, 15, 3)
    c3 = planning.piecewise_polynomial_batch(t3, RNG.normal(size=(4, 2)))
    pk3 = planning.peaks_batch(t3, c3)
    for p in range(t3.shape[0]):
        pk = planning.Trajectory(t3[p], c3[p]).peaks()
        _close(pk3[p], np.stack([pk.velocity, pk.acceleration, pk.jerk]))


def test_peaks_batch_on_septics_uses_the_eigenvalue_path():
    t = _times(RNG, 12, 1)
    coefs = RNG.normal(size=(12, 1, 8, 2))
    whole = planning.peaks_batch(t, coefs)
    for p in range(12):
        pk = planning.Trajectory(t[p], coefs[p]).peaks()
        _close(whole[p], np.stack([pk.velocity, pk.acceleration, pk.jerk]))
        dense = planning.Trajectory(t[p], coefs[p]).sample(np.linspace(t[p, 0], t[p, 1], 20001))
        assert np.all(np.abs(dense[1]).max(axis=0) <= whole[p, 0] * (1 + 1e-12))
        assert np.all(np.abs(dense[1]).max(axis=0) >= whole[p, 0] * (1 - 1e-6))


def test_empty_population_gives_empty_arrays():
    t = np.zeros((0, 4))
    q = np.arange(4.0)
    assert planning.piecewise_polynomial_batch(t, q).shape == (0, 3, 6, 1)
    assert planning.quintic_bspline_batch(t, q).shape == (0, 3, 6, 1)
    assert planning.multi_quintic_batch(t, q).shape == (0, 3, 6, 1)
    assert planning.peaks_batch(t, np.zeros((0, 3, 6, 1))).shape == (0, 3, 1)


@pytest.mark.parametrize(
    "build",
    [planning.piecewise_polynomial_batch, planning.multi_quintic_batch, planning.quintic_bspline_batch],
)
def test_batch_input_errors_name_the_offending_value(build):
    q = [0.0, 1.0, 2.0, 3.0]
    with pytest.raises(TrajectoryError, match=r"2-D array .*got shape \(4,\)"):
        build([0.0, 1.0, 2.0, 3.0], q)
    with pytest.raises(TrajectoryError, match=r"times\[1, 2\] = 1.0 does not come after times\[1, 1\] = 1.0"):
        build([[0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 1.0, 3.0]], q)
    with pytest.raises(TrajectoryError, match=r"times must be finite; entry \(0, 3\) is nan"):
        build([[0.0, 1.0, 2.0, np.nan]], q)
    with pytest.raises(TrajectoryError, match="positions has 3 points but there are 4 times"):
        build([[0.0, 1.0, 2.0, 3.0]], q[:3])
    with pytest.raises(TrajectoryError, match="at least 2 instants per row"):
        build([[0.0]], [0.0])


def test_batch_option_errors():
    t = np.array([[0.0, 1.0, 2.0, 3.0]])
    with pytest.raises(ConditionCountError, match="18 coefficients but there are 14"):
        planning.piecewise_polynomial_batch(t, np.arange(4.0), (5, 5, 5))
    with pytest.raises(TrajectoryError, match="3 segment degrees"):
        planning.piecewise_polynomial_batch(t[:, :3], np.arange(3.0), "3-5-3")
    with pytest.raises(TrajectoryError, match="velocities must be None, 'zero', 'heuristic'"):
        planning.multi_quintic_batch(t, np.arange(4.0), velocities="smooth")
    with pytest.raises(TrajectoryError, match=r"start_velocity must be a scalar or have 2 entries"):
        planning.quintic_bspline_batch(t, np.ones((4, 2)), start_velocity=[1.0, 2.0, 3.0])
    with pytest.raises(TrajectoryError, match=r"coefficients must have shape \(1, 3, degree\+1, n_joints\)"):
        planning.peaks_batch(t, np.zeros((1, 2, 6, 1)))
    with pytest.raises(TrajectoryError, match="coefficients must be finite"):
        planning.peaks_batch(t, np.full((1, 3, 6, 1), np.inf))
