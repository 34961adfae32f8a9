"""Time laws s(t): the profile as a law, its smoothing under a jerk limit, uniform slowing, cuts at path breaks."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.optim.topp.time_law import bang_bang, law_eval, scaled_law, smoothed, split_at_breaks


@pytest.fixture()
def law():
    """Rest to rest over s in [0, 1]: s̈ = +1 on [0, 0.5], −1 on [0.5, 1] (a triangle of speeds)."""
    grid = np.array([0.0, 0.5, 1.0])
    x = np.array([0.0, 1.0, 0.0])  # ṡ² at the grid points: 2 · 1 · 0.5
    u = np.array([1.0, -1.0])
    return bang_bang(grid, x, u, 1.0)


def test_bang_bang_is_the_profile_in_time(law):
    tb, C = law
    np.testing.assert_allclose(tb, [0.0, 1.0, 2.0], rtol=1e-15)
    s, sd, sdd = law_eval(tb, C, np.array([0.0, 0.5, 1.0, 1.5, 2.0]))
    np.testing.assert_allclose(s, [0.0, 0.125, 0.5, 0.875, 1.0], atol=1e-15)
    np.testing.assert_allclose(sd, [0.0, 0.5, 1.0, 0.5, 0.0], atol=1e-15)
    np.testing.assert_allclose(sdd, [1.0, 1.0, -1.0, -1.0, -1.0], atol=1e-15)


def test_smoothing_keeps_both_ends_at_rest_and_makes_the_acceleration_continuous(law):
    tb, C = law
    tau = 0.25
    ntb, nC = smoothed(tb, C, tau)
    assert ntb[0] == tb[0] and ntb[-1] == pytest.approx(tb[-1] + tau, rel=1e-15)
    s, sd, sdd = law_eval(ntb, nC, ntb[[0, -1]])
    np.testing.assert_allclose(s, [0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(sd, [0.0, 0.0], atol=1e-12)
    # s̈ continuous at every inner break: the jumps of the bang-bang law are spread over τ
    eps = 1e-9
    left = law_eval(ntb, nC, ntb[1:-1] - eps)[2]
    right = law_eval(ntb, nC, ntb[1:-1] + eps)[2]
    assert np.abs(left - right).max() < 1e-6
    assert np.abs(law_eval(ntb, nC, np.linspace(ntb[0], ntb[-1], 401))[2]).max() <= 1.0 + 1e-12


def test_scaled_law_slows_uniformly(law):
    tb, C = law
    stb, sC = scaled_law(tb, C, 2.0)
    t = np.linspace(0.0, 2.0, 9)
    s, sd, sdd = law_eval(tb, C, t)
    s2, sd2, sdd2 = law_eval(stb, sC, 2.0 * t)
    np.testing.assert_allclose(s2, s, atol=1e-15)
    np.testing.assert_allclose(sd2, sd / 2.0, atol=1e-15)
    np.testing.assert_allclose(sdd2, sdd / 4.0, atol=1e-15)


def test_split_at_breaks_cuts_where_the_law_crosses_a_path_break(law):
    tb, C = law
    ntb, nC = split_at_breaks(tb, C, np.array([0.125, 0.875]))
    np.testing.assert_allclose(ntb, [0.0, 0.5, 1.0, 1.5, 2.0], atol=1e-12)
    t = np.linspace(0.0, 2.0, 17)
    np.testing.assert_allclose(law_eval(ntb, nC, t)[0], law_eval(tb, C, t)[0], atol=1e-14)
    assert split_at_breaks(tb, C, np.array([0.5]))[0] is tb  # on a break already: nothing to cut
