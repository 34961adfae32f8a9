"""Checks of a path timing: the dilation each row needs, the ratios per constraint, exact joint peaks."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.optim.topp.dense_check import Peaked, dilation_needed, ratios
from pinarms.planning import PathRows, quintic_bspline


def rows():
    """Two points, two rows: an acceleration-like row on u (|u| <= 2) and a speed row on x (x <= 4)."""
    a = np.array([[1.0, 0.0], [1.0, 0.0]])
    b = np.array([[0.0, 1.0], [0.0, 1.0]])
    return PathRows(a, b, np.array([[-2.0, -np.inf]] * 2), np.array([[2.0, 4.0]] * 2))


def test_dilation_needed_is_the_squared_factor_each_row_asks_for():
    need = dilation_needed(rows(), np.array([1.0, -3.0]), np.array([9.0, 2.0]))
    # point 0: u within, x = 9 > 4 -> f² = 9/4; point 1: u = -3 < -2 -> f² = 1.5, x within
    np.testing.assert_allclose(need, [[1.0, 2.25], [1.5, 1.0]], rtol=1e-15)
    bad = PathRows(np.array([[1.0]]), np.array([[0.0]]), np.array([[0.5]]), np.array([[2.0]]))  # u >= 0.5: not at rest
    assert np.isinf(dilation_needed(bad, np.array([0.0]), np.array([0.0]))[0, 0])


def test_ratios_per_constraint_name_speeds_for_rows_without_u():
    r = ratios(rows(), np.array([1.0, -1.5]), np.array([1.0, 2.56]), ["acc", "speed"])
    assert r["acc"] == pytest.approx(0.75, rel=1e-15)  # |-1.5| / 2
    assert r["speed"] == pytest.approx(0.8, rel=1e-15)  # sqrt(2.56 / 4): a ratio of speeds


def test_peaked_gives_the_trajectory_exact_peaks_once_per_order():
    traj = quintic_bspline([0.0, 1.0, 2.5], np.array([[0.0, 0.0], [1.0, -0.5], [0.3, 0.4]]))
    peaked = Peaked(traj)
    exact = traj.peaks()
    np.testing.assert_array_equal(peaked.velocity, exact.velocity)
    np.testing.assert_array_equal(peaked.acceleration, exact.acceleration)
    assert peaked.peaks() is peaked and peaked.n_joints == 2
    assert 3 not in peaked._peaks_of_order  # jerk not asked for: never computed


def test_exact_peaks_skip_only_pieces_that_cannot_hold_the_peak():
    """The pruned peaks equal the extrema of every piece, bit for bit, on many short pieces."""
    from pinarms.optim.topp.dense_check import _exact_peaks
    from pinarms.planning.extrema import normalised_pieces, piece_extrema

    rng = np.random.default_rng(3)
    knots = np.cumsum(rng.uniform(0.05, 0.3, 41))
    traj = quintic_bspline(knots - knots[0], rng.normal(size=(41, 3)))
    h = traj.segment_durations
    nz = normalised_pieces(traj.coefficients, h)
    for r in (1, 2, 3):
        values, _ = piece_extrema(nz, h, (r,))
        np.testing.assert_array_equal(_exact_peaks(nz, h, r), np.abs(values[0]).max(axis=(0, 2)))
