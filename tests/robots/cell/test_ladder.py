"""The Lipschitz ladder on closed forms: excesses that are exact 1-Lipschitz functions of travel."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.robots.cell import ladder
from pinarms.robots.cell.ladder import Intervals, climb, interval_bound


class Line:
    """Samples of an excess ``E(s)`` along a straight motion, travel ``s`` [m] (the rungs of :func:`climb`).

    ``fail_below``: a new sample with ``E`` below it fails the proof (as a screen does)."""

    def __init__(self, E, s, fail_below=None, give_up=False):
        self.E, self.s, self.fail_below, self.stop = E, np.asarray(s, dtype=float), fail_below, give_up
        self.levels = []

    def start(self):
        return self.E(self.s), np.diff(self.s)

    def halve(self, intervals: Intervals):
        sa, sb = self.s[intervals.left], self.s[intervals.right]
        self.mids = 0.5 * (sa + sb)
        self.s = np.concatenate([self.s, self.mids])
        return self.mids - sa, sb - self.mids

    def evaluate(self, excess, intervals, level):
        self.levels.append(level)
        e = self.E(self.mids)
        bad = np.flatnonzero(e < self.fail_below) if self.fail_below is not None else []
        return np.concatenate([excess, e]), (excess.size + int(bad[0]) if len(bad) else -1)

    def give_up(self):
        return self.stop


def v_shape(c, r, slope=1.0):
    """``slope · |s − c| − r``: 1-Lipschitz for ``slope ≤ 1``, smallest ``−r`` at ``s = c``."""
    return lambda s: slope * np.abs(np.asarray(s, dtype=float) - c) - r


def run(rungs, **kwargs):
    e, budgets = rungs.start()
    return climb(e, budgets, rungs, **kwargs)


def test_the_bound_is_the_lipschitz_midpoint_rule():
    assert interval_bound(0.3, 0.5, 0.2) == pytest.approx(0.3, abs=1e-15)
    assert interval_bound(0.1, 0.1, 0.2) == 0.0
    e = np.array([0.0, 0.1, 0.25])
    np.testing.assert_allclose(interval_bound(e, e[::-1], np.full(3, 0.2)), [0.025, 0.0, 0.025], atol=1e-15)


@pytest.mark.parametrize("c", [-0.3, 0.0, 0.37, 0.5, 1.0, 1.4])
def test_a_tight_v_is_proven_at_once_exactly_when_its_minimum_keeps_zero(c):
    s = np.linspace(0.0, 1.0, 5)
    for r in (-0.01, 0.0):
        result = run(Line(v_shape(c, r + max(0.0, -c, c - 1.0)), s), finest=6)
        assert result.proven and result.level == 0 and not result.unresolved
        assert result.lower_bound == pytest.approx(-r, abs=1e-12)
    result = run(Line(v_shape(c, 0.01 + max(0.0, -c, c - 1.0)), s), finest=6)
    assert not result.proven and result.unresolved and result.level == 6
    assert result.lower_bound <= -0.01 + 1e-12


def test_levels_are_counted_down_to_the_first_that_proves():
    # E = |s − 0.5| / 2 + m on [0, 1]: the intervals next to 0.5 need a width <= 4 m
    for m, levels in ((0.25, 0), (0.125, 1), (1 / 64, 4), (1 / 256, 6)):
        rungs = Line(v_shape(0.5, -m, slope=0.5), [0.0, 1.0])
        result = run(rungs, finest=10)
        assert result.proven and result.level == levels
        assert rungs.levels == list(range(1, levels + 1))  # one batched evaluation per level
        assert 0.0 <= result.lower_bound <= m + 1e-15


def test_a_proof_stopped_at_the_finest_level_names_the_first_open_interval():
    result = run(Line(v_shape(0.5, -1 / 64, slope=0.5), [0.0, 1.0]), finest=3)
    assert not result.proven and result.unresolved and result.level == 3
    assert (result.source, result.fa, result.fb) == (0, 0.375, 0.5)
    given_up = run(Line(v_shape(0.5, -1 / 64, slope=0.5), [0.0, 0.5, 1.0], give_up=True), finest=10)
    assert given_up.unresolved and given_up.level == 0 and (given_up.source, given_up.fa, given_up.fb) == (0, 0.0, 1.0)


def test_a_failing_midpoint_ends_the_proof_at_its_interval():
    rungs = Line(v_shape(0.8, 0.05), [0.0, 0.4, 1.2], fail_below=0.0)
    result = run(rungs, finest=10)
    assert not result.proven and not result.unresolved and result.level == 1
    assert result.sample == 3  # the midpoint 0.8 of the second interval, the first new sample
    assert (result.source, result.fa, result.fb) == (1, 0.0, 0.5)


def test_touching_samples_and_targets_decide_without_halving():
    # contact at 0: an interval with a sample at or below it is decided (its lower end counted)
    rungs = Line(v_shape(0.5, 0.1), [0.0, 0.5, 1.0])
    result = run(rungs, finest=6, contact=0.0)
    assert not result.proven and not result.unresolved and result.level == 0 and rungs.levels == []
    assert result.lower_bound == pytest.approx(-0.1)
    # a target of 0.05: the bound of (0, 1) with E = |s - 0.5| + 0.06 is 0.06
    assert run(Line(v_shape(0.5, -0.06), [0.0, 1.0]), finest=6, target=lambda low: np.full(low.size, 0.05)).proven
    assert not run(Line(v_shape(0.5, -0.04), [0.0, 1.0]), finest=6, target=lambda low: np.full(low.size, 0.05)).proven


def random_lipschitz(rng):
    """A random piecewise-linear excess with slopes in [−1, 1] on [0, 1], and its exact minimum."""
    knots = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0.0, 1.0, 6)]))
    values = np.concatenate([[rng.uniform(-0.05, 0.3)], rng.uniform(-1.0, 1.0, knots.size - 1) * np.diff(knots)])
    values = np.cumsum(values)
    return (lambda s: np.interp(s, knots, values)), float(values.min())


def test_random_excesses_never_contradict_the_proof():
    rng = np.random.default_rng(25)
    proven = refused = 0
    for _ in range(200):
        E, minimum = random_lipschitz(rng)
        s = np.linspace(0.0, 1.0, int(rng.integers(2, 6)))
        result = run(Line(E, s), finest=8)
        assert result.lower_bound <= minimum + 1e-12  # a proven bound never exceeds the truth
        touching = run(Line(E, s), finest=8, contact=0.0)  # the same verdict, sooner where a sample touches
        assert touching.proven == result.proven and touching.level <= result.level
        if result.proven:
            assert minimum >= 0.0 and touching.lower_bound == result.lower_bound
            proven += 1
        if minimum < 0.0:
            assert not result.proven
            refused += 1
    assert proven >= 20 and refused >= 20


def test_the_compiled_rule_counts_the_budget_with_its_slack():
    proven = ladder.interval_proven
    assert proven(0.5, 0.5 + 2e-9, 1.0) and not proven(0.5, 0.5, 1.0)
    assert proven(0.0, 0.3, 0.2) and not proven(0.0, 0.1, 0.2)
    e = np.random.default_rng(3).uniform(0.0, 1.0, (200, 3))
    for a, b, B in e:
        assert proven(a, b, B) == bool(interval_bound(a, b, B * (1.0 + ladder.RELATIVE_SLACK)) >= 0.0)
