"""optim.motion.proof.LadderProof: how the ladder of batched screens ends, for given samples and midpoints.

The midpoints come from the caller (:meth:`LadderProof.prove`'s ``midpoint``): here chosen
states of the mushroom line's left SCARA, so each way a proof ends is reached on purpose.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from pinarms.optim.motion.checker import MotionChecker
from pinarms.optim.motion.proof import Verdict
from pinarms.robots.cell import load_cell


@pytest.fixture(scope="module")
def checker():
    return MotionChecker(load_cell("mushroom_line"), ["left"], margin=0.01)


#: The samples' level: budgets up to ``step · 2^6`` between them, screens raised by ``s_L = step / 2^(L+1)``.
TOP = -6
#: Excess [m] of the clear test states: they pass the screens of levels -3 on (raised 0.04 m), not coarser ones.
EXCESS = (0.05, 0.07)


@pytest.fixture(scope="module")
def states(checker):
    """Two states that keep the margin by 5 to 7 cm and one too close to something, all within the limits."""
    rng = np.random.default_rng(25)
    clear, close = [], None
    while len(clear) < 2 or close is None:
        x = rng.uniform(checker.lower, checker.upper)
        if not checker.state_valid(x):
            close = x if close is None else close
        elif EXCESS[0] < checker.closest(x)[0] < EXCESS[1] and len(clear) < 2:
            clear.append(x)
    return clear[0], clear[1], close


def midpoints(x, other=None):
    """A ``midpoint`` giving state ``x`` (in interval 1: ``other``, if given) and half the budget to each half."""
    return lambda i, a, b, B: (other if (i == 1 and other is not None) else x, 0.5 * B, 0.5 * B)


def prove(checker, states, budgets, midpoint):
    xa, xb, _ = states
    X = np.stack([xa, xb, xa][: len(budgets) + 1])
    return checker.prove(X, np.asarray(budgets, dtype=float), midpoint, top=TOP)


def test_samples_passing_the_screen_of_their_level_are_proven_at_once(checker, states):
    xa, xb, _ = states
    budget = checker.step * 2.0 ** 3  # level -3: screens raised by 0.04 m, which the states pass
    assert checker.prove(np.stack([xa, xb]), np.array([budget]), midpoints(xa), top=-3) == Verdict(True)


def test_the_ladder_halves_down_to_the_level_whose_screens_the_samples_pass(checker, states):
    budget = checker.step * 2.0 ** -TOP
    assert prove(checker, states, [budget, budget], midpoints(states[0])) == Verdict(True, exact=-3)


def test_a_midpoint_outside_the_limits_fails_where_it_lies(checker, states):
    budget = checker.step * 2.0 ** -TOP
    verdict = prove(checker, states, [budget, budget], midpoints(states[0], checker.upper + 0.1))
    assert verdict == Verdict(False, 1, 0.5, TOP + 1)


def test_a_midpoint_too_close_fails_from_its_intervals_start(checker, states):
    budget = checker.step * 2.0 ** -TOP
    verdict = prove(checker, states, [budget, budget], midpoints(states[0], states[2]))
    assert verdict == Verdict(False, 1, 0.0, TOP + 1)


def test_a_proof_past_its_deadline_is_not_valid(checker, states):
    def late(i, a, b, B):
        checker.deadline = time.perf_counter() - 1.0
        return states[0], 0.5 * B, 0.5 * B

    before = checker.counts["timeouts"]
    try:
        verdict = prove(checker, states, [checker.step * 2.0 ** -TOP], late)
    finally:
        checker.deadline = None
    assert not verdict.ok and checker.counts["timeouts"] > before


def test_a_timed_motion_passing_a_joint_limit_between_samples_is_refused(checker, states):
    """A joint rising to its upper limit and back: 1e-6 below it the timed proof runs (and proves it),
    1e-6 beyond it the motion is refused at its exact extremes, whatever the samples."""
    from pinarms.planning import Trajectory

    xa = states[0]
    j = int(np.argmax(checker.upper - checker.lower))
    T = 1.0
    verdicts = []
    for beyond in (-1e-6, 1e-6):
        start = xa.copy()
        start[j] = checker.upper[j] - 0.01
        k = 4.0 * (checker.upper[j] + beyond - start[j]) / T ** 2
        coefs = np.zeros((1, 3, xa.size))
        coefs[0, 0] = start
        coefs[0, 1, j], coefs[0, 2, j] = k * T, -k
        tr = Trajectory([0.0, T], coefs)
        assert tr.position_range()[1][j] == pytest.approx(checker.upper[j] + beyond, abs=1e-12)
        verdicts.append(checker.trajectory_valid(tr).ok)
    assert verdicts == [True, False]
