"""Sampling's fast paths (one piece, row blocks, finite check by a sum) against an independent evaluation."""

import numpy as np
import pytest

from pinarms import planning
from pinarms.planning.errors import TrajectoryError
from pinarms.planning.poly_pieces import GEMM_ONE_THREAD
from pinarms.planning.trajectory import Trajectory


def _reference(traj, t):
    """q..qddd by numpy.polynomial on each piece (ascending coefficients), one instant at a time."""
    b, c = traj.knot_times, traj.coefficients
    out = np.empty((4, t.size, c.shape[2]))
    for i, ti in enumerate(t):
        s = min(max(np.searchsorted(b, ti, side="right") - 1, 0), c.shape[0] - 1)
        for j in range(c.shape[2]):
            p = np.polynomial.Polynomial(c[s, :, j])
            for r in range(4):
                out[r, i, j] = p.deriv(r)(ti - b[s])
    return out


@pytest.mark.parametrize("degree, points", [(5, 2), (7, 4), (3, 2), (9, 2)])
def test_one_piece_sampling_matches_numpy_polynomial(degree, points):
    rng = np.random.default_rng(degree)
    times = np.sort(rng.uniform(0.0, 3.0, points)) + np.arange(points)
    traj = planning.polynomial(times, rng.normal(size=(points, 3)), degree)
    t = np.linspace(traj.start_time, traj.end_time, 57)
    got = traj.sample(t)
    ref = _reference(traj, t)
    for r in range(4):
        np.testing.assert_allclose(got[r], ref[r], rtol=1e-10, atol=1e-10 * np.abs(ref[r]).max())
    # rest at both ends up to the order the degree allows
    for r in range(1, min(3, (degree + 1 - points) // 2) + 1):
        assert np.abs(got[r][[0, -1]]).max() <= 1e-9 * max(1.0, np.abs(got[r]).max())


def test_long_sampling_in_row_blocks_equals_one_product():
    traj = planning.quintic_bspline(np.arange(6.0), np.random.default_rng(1).normal(size=(6, 6)))
    rows = GEMM_ONE_THREAD // (6 * 24)
    t = np.linspace(0.0, 5.0, 3 * rows + 17)  # several blocks per piece
    got = traj.sample(t)
    pick = np.r_[0:5, rows - 2 : rows + 3, t.size - 5 : t.size]
    ref = _reference(traj, t[pick])
    for r in range(4):
        np.testing.assert_allclose(got[r][pick], ref[r], rtol=1e-10, atol=1e-10 * np.abs(ref[r]).max())


def test_overflowing_values_still_raise_and_a_large_finite_sum_does_not():
    huge = Trajectory([0.0, 1e8], np.array([[[1e300], [1e300], [1e300]]]))  # 1e300 · (1e8)² overflows
    with pytest.raises(TrajectoryError, match="overflow"):
        huge.sample(np.array([0.0, 1e8]))
    # entries near the float64 limit whose sum overflows: every entry finite, so no error
    big = Trajectory([0.0, 1.0], np.array([[[1.5e308, 1.5e308], [0.0, 0.0]]]))
    q = big.sample(np.array([0.0, 0.5, 1.0]))[0]
    assert np.all(q == 1.5e308)
