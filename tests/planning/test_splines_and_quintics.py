"""Quintic B-spline (seed 002) and multi-segment quintics with chosen via velocities."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import make_interp_spline

from pinarms import planning
from pinarms.papers import SEED002

# Seed 002's initial segment times (s) and a representative lift-feed-lower path (m).
SEED002_H = SEED002.initial_durations_s
TIMES = np.concatenate([[0.0], np.cumsum(SEED002_H)])
PATH = np.column_stack(
    [
        [0.00, 0.00, 0.02, 0.08, 0.16, 0.25, 0.34, 0.42, 0.48, 0.50, 0.50],
        [0.00, 0.00, 0.01, 0.04, 0.08, 0.12, 0.16, 0.20, 0.23, 0.25, 0.25],
        [0.00, 0.03, 0.08, 0.10, 0.10, 0.10, 0.10, 0.10, 0.07, 0.02, 0.00],
    ]
)


def test_bspline_interpolates_with_rest_ends():
    traj = planning.quintic_bspline(TIMES, PATH)
    q, v, a, _ = traj.sample(TIMES)
    np.testing.assert_allclose(q, PATH, atol=1e-12)
    np.testing.assert_allclose(v[[0, -1]], 0.0, atol=1e-10)
    np.testing.assert_allclose(a[[0, -1]], 0.0, atol=1e-8)
    assert traj.n_segments == 10 and traj.degree == 5


def test_bspline_is_c4_so_jerk_is_continuous():
    traj = planning.quintic_bspline(TIMES, PATH)
    eps = 1e-7
    inner = TIMES[1:-1]
    left = traj.sample(inner - eps)
    right = traj.sample(inner + eps)
    jerk_scale = traj.peaks().jerk
    for r in (1, 2, 3):
        assert np.all(np.abs(left[r] - right[r]) <= 1e-5 * (1 + jerk_scale))
    # The exact piece coefficients agree too: snap (4th derivative) continuous at the knots.
    c = traj.coefficients
    h = np.diff(TIMES)[:, None]
    snap_end = 24 * c[:-1, 4] + 120 * c[:-1, 5] * h[:-1]
    snap_start = 24 * c[1:, 4]
    np.testing.assert_allclose(snap_end, snap_start, rtol=1e-7, atol=1e-6 * np.abs(snap_start).max())
    # Contrast: the stop-at-every-point multi-quintic has jerk steps at its knots.
    mq = planning.multi_quintic(TIMES, PATH)
    steps = np.abs(mq.sample(inner - eps)[3] - mq.sample(inner + eps)[3])
    assert steps.max() > 1.0


def test_bspline_agrees_with_plain_scipy_and_given_end_derivatives():
    v0 = np.array([0.1, -0.2, 0.0])
    a1 = np.array([0.0, 0.5, -1.0])
    traj = planning.quintic_bspline(TIMES, PATH, start_velocity=v0, end_acceleration=a1)
    ref = make_interp_spline(
        TIMES, PATH, k=5, bc_type=([(1, v0), (2, np.zeros(3))], [(1, np.zeros(3)), (2, a1)])
    )
    t = np.linspace(0.0, TIMES[-1], 777)
    out = traj.sample(t)
    for nu in range(4):
        np.testing.assert_allclose(out[nu], ref(t, nu), rtol=1e-9, atol=1e-9 * np.abs(ref(t, nu)).max())
    np.testing.assert_allclose(traj.sample(0.0)[1], v0, atol=1e-12)
    np.testing.assert_allclose(traj.sample(TIMES[-1])[2], a1, atol=1e-8)


def test_bspline_two_points_is_the_rest_to_rest_quintic():
    traj = planning.quintic_bspline([0.0, 2.0], [0.0, 1.0])
    ref = planning.polynomial([0.0, 2.0], [0.0, 1.0], 5)
    np.testing.assert_allclose(traj.coefficients, ref.coefficients, atol=1e-12)


def test_heuristic_velocities_rule():
    t = np.array([0.0, 1.0, 2.0, 4.0, 5.0])
    q = np.array([0.0, 1.0, 3.0, 2.0, 2.0])
    v = planning.heuristic_velocities(t, q[:, None])[:, 0]
    # slopes 1, 2, -0.5, 0: same sign -> mean; sign change or zero slope -> 0; ends 0.
    np.testing.assert_allclose(v, [0.0, 1.5, 0.0, 0.0, 0.0])
    traj = planning.multi_quintic(t, q, velocities="heuristic")
    np.testing.assert_allclose(traj.sample(t)[1][:, 0], v, atol=1e-12)


def test_continuous_accelerations_make_the_jerk_continuous():
    traj = planning.multi_quintic(TIMES, PATH, velocities="heuristic", accelerations="continuous")
    eps = 1e-7
    inner = TIMES[1:-1]
    left, right = traj.sample(inner - eps), traj.sample(inner + eps)
    assert np.abs(left[3] - right[3]).max() <= 1e-4 * (1 + traj.peaks().jerk.max())
    q, v, a, _ = traj.sample(TIMES)
    np.testing.assert_allclose(q, PATH, atol=1e-12)
    np.testing.assert_allclose(a[[0, -1]], 0.0, atol=1e-9)
    # Without the solve (zero via accelerations) the jerk jumps at the knots.
    plain = planning.multi_quintic(TIMES, PATH, velocities="heuristic")
    assert np.abs(plain.sample(inner - eps)[3] - plain.sample(inner + eps)[3]).max() > 1.0


def test_given_via_velocities_and_accelerations_are_met():
    t = [0.0, 1.0, 2.5]
    q = [0.0, 1.0, 0.0]
    v = [0.0, 0.3, 0.0]
    a = [0.0, -2.0, 0.0]
    traj = planning.multi_quintic(t, q, velocities=v, accelerations=a)
    _, vs, as_, _ = traj.sample(t)
    np.testing.assert_allclose(vs[:, 0], v, atol=1e-12)
    np.testing.assert_allclose(as_[:, 0], a, atol=1e-11)
    with pytest.raises(planning.TrajectoryError, match="velocities must have shape"):
        planning.multi_quintic(t, np.zeros((3, 2)), velocities=[0.0, 1.0, 0.0])
    with pytest.raises(planning.TrajectoryError, match="'heuristic'"):
        planning.multi_quintic(t, q, velocities="smooth")
