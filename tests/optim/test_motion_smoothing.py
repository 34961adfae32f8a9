"""optim.motion.smoothing: the travel bound the spline's proof rests on, and the samples placed on it.

The cell is tests/optim/data/aubo_wall.urdf.xacro (the AUBO-i3 by a wall, as in test_motion.py);
the path a C² joint spline through seeded waypoints. The bound is compared with the travel
measured densely: ``Σ_j ℓ_j ∫ |q_j'(s)| ds`` on 20 000 points of every interval tested.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pinarms import robots
from pinarms.optim.motion import MotionChecker
from pinarms.optim.motion.smoothing import COARSE, _samples, _travel_bound, path_speed_bounds, prove_path
from pinarms.planning import joint_spline

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def checker():
    cell = robots.load_cell(DATA / "aubo_wall.urdf.xacro")
    return MotionChecker(cell, ["aubo"], margin=0.01)


@pytest.fixture(scope="module")
def spline(checker):
    rng = np.random.default_rng(4)
    lo, hi = checker.lower, checker.upper
    W = lo + (hi - lo) * rng.uniform(0.35, 0.65, size=(6, checker.n))
    return joint_spline(W)


def _dense_travel(checker, path, a, b, n=20_000):
    s = np.linspace(a, b, n + 1)
    _, dq, _ = path.sample(s)
    speed = np.abs(dq) @ checker.levers
    return float(np.sum(0.5 * (speed[1:] + speed[:-1]) * np.diff(s)))


def test_the_cumulative_bound_holds_on_any_interval_and_beats_the_piece_peaks(checker, spline):
    nodes, T = _travel_bound(checker, spline)
    rng = np.random.default_rng(9)
    for a, b in np.sort(rng.uniform(0.0, spline.length, size=(40, 2)), axis=1):
        bound = np.interp(b, nodes, T) - np.interp(a, nodes, T)
        assert bound >= _dense_travel(checker, spline, a, b) * (1.0 - 1e-6)
    peaks = float(np.sum((path_speed_bounds(spline) @ checker.levers) * np.diff(spline.breaks)))
    assert _dense_travel(checker, spline, 0.0, spline.length) <= T[-1] < 0.9 * peaks  # tighter than the piece peaks


def test_samples_are_equal_steps_of_the_bound_below_the_coarse_step(checker, spline):
    s, budgets, (nodes, T) = _samples(checker, spline)
    assert s[0] == 0.0 and s[-1] == spline.length and np.all(np.diff(s) > 0.0)
    assert budgets.max() <= checker.step * 2.0 ** COARSE
    np.testing.assert_allclose(budgets.sum(), T[-1], rtol=1e-12)


def test_a_spline_through_the_wall_is_refused_and_a_clear_one_proven(checker):
    # the AUBO's start and goal on either side of the wall (test_motion.py's across), straight through it
    from tests.optim.test_motion import _tool_down

    qa, _ = _tool_down(checker.cell, [0.45, 0.2, 0.80])
    qb, _ = _tool_down(checker.cell, [0.45, -0.2, 0.80])
    through = joint_spline(np.stack([qa, 0.5 * (qa + qb), qb]))
    verdict, piece = prove_path(checker, through)
    assert not verdict.ok and piece in (0, 1)
    near = joint_spline(np.stack([qa, qa + 0.02, qa + 0.03]))
    verdict, piece = prove_path(checker, near)
    assert verdict.ok and piece is None


def test_the_bisection_reads_the_path_and_the_bound_as_the_arrays_do(checker, spline):
    from pinarms.optim.motion.smoothing import _PointEvaluator

    nodes, T = _travel_bound(checker, spline)
    at = _PointEvaluator(spline, nodes, T)
    for s in np.random.default_rng(2).uniform(0.0, spline.length, 50).tolist() + list(spline.breaks):
        np.testing.assert_allclose(at.q(s), spline(s), rtol=0.0, atol=1e-12)
        assert at.bound(s) == pytest.approx(float(np.interp(s, nodes, T)), rel=1e-12, abs=1e-15)


def test_a_focus_first_proves_the_same_path(checker, spline):
    whole, _ = prove_path(checker, spline)
    focused, _ = prove_path(checker, spline, focus=(0.3 * spline.length, 0.6 * spline.length))
    assert whole.ok == focused.ok
