"""GA operators: bounds respected, probabilities honoured, selection pressure as designed."""

import numpy as np
import pytest

from pinarms.optim.ga import adaptive, crossover, mutation, selection
from pinarms.optim.ga.constraints import AdaptivePenalty, rank_feasibility_rules, rank_penalty, violation

LOWER = np.array([0.0, -1.0, 10.0])
UPPER = np.array([1.0, 1.0, 20.0])


def _pop(rng, n=400):
    return LOWER + rng.random((n, 3)) * (UPPER - LOWER)


@pytest.mark.parametrize("op", ["sbx", "arithmetic", "blend"])
def test_crossover_children_stay_in_bounds_and_p0_copies(op):
    rng = np.random.default_rng(1)
    a, b = _pop(rng), _pop(rng)
    args = {"sbx": (15.0,), "arithmetic": (), "blend": (0.5,)}[op]
    fn = getattr(crossover, op)
    c1, c2 = fn(a, b, LOWER, UPPER, 1.0, *args, rng)
    for c in (c1, c2):
        assert np.all(c >= LOWER) and np.all(c <= UPPER)
    assert not np.allclose(c1, a)
    c1, c2 = fn(a, b, LOWER, UPPER, 0.0, *args, rng)
    assert np.array_equal(c1, a) and np.array_equal(c2, b)


def test_arithmetic_crossover_preserves_pair_sum():
    rng = np.random.default_rng(2)
    a, b = _pop(rng), _pop(rng)
    c1, c2 = crossover.arithmetic(a, b, LOWER, UPPER, 1.0, rng)
    np.testing.assert_allclose(c1 + c2, a + b, atol=1e-12)


def test_sbx_children_centred_on_parents():
    rng = np.random.default_rng(3)
    a = np.full((20000, 3), 0.4) * (UPPER - LOWER) + LOWER
    b = np.full((20000, 3), 0.6) * (UPPER - LOWER) + LOWER
    c1, c2 = crossover.sbx(a, b, LOWER, UPPER, 1.0, 15.0, rng)
    centre = (c1 + c2).mean(0) / 2
    assert np.all(np.abs(centre - (a[0] + b[0]) / 2) < 0.01 * (UPPER - LOWER))
    spread = np.abs(c1 - c2).mean(0)  # eta = 15: children near the parents, not collapsed
    assert np.all(spread > 0.05 * (UPPER - LOWER)) and np.all(spread < 0.3 * (UPPER - LOWER))


def test_non_uniform_mutation_shrinks_to_zero_at_last_generation():
    rng = np.random.default_rng(4)
    x = _pop(rng)
    early = mutation.non_uniform(x, LOWER, UPPER, 1.0, 0, 100, 2.0, rng)
    late = mutation.non_uniform(x, LOWER, UPPER, 1.0, 100, 100, 2.0, rng)
    assert np.all(early >= LOWER) and np.all(early <= UPPER)
    assert np.abs(early - x).mean() > 0.1 * np.abs(UPPER - LOWER).mean() / 3
    np.testing.assert_array_equal(late, x)  # (1 - g/G)^c = 0 -> r^0 = 1 -> no step
    mid = mutation.non_uniform(x, LOWER, UPPER, 1.0, 90, 100, 2.0, rng)
    assert np.abs(mid - x).mean() < np.abs(early - x).mean()


def test_mutation_rate_per_gene_and_per_individual():
    rng = np.random.default_rng(5)
    x = _pop(rng, 20000)
    y = mutation.polynomial(x, LOWER, UPPER, 0.1, 20.0, rng)
    assert np.all(y >= LOWER) and np.all(y <= UPPER)
    assert abs(np.mean(y != x) - 0.1) < 0.01
    p = np.where(np.arange(20000) < 10000, 0.0, 1.0)
    y = mutation.non_uniform(x, LOWER, UPPER, p, 0, 10, 2.0, rng)
    assert np.all(y[:10000] == x[:10000]) and np.mean(y[10000:] != x[10000:]) > 0.99


def test_tournament_prefers_good_ranks():
    rng = np.random.default_rng(6)
    rank = np.arange(50)
    picks = selection.tournament(rank, 100000, 2, rng)
    # Binary tournament: P(pick rank i) = (2 (N - i) - 1) / N^2 -> best ~ 99/2500.
    assert abs(np.mean(picks == 0) - 99 / 2500) < 0.003
    assert np.mean(picks == 49) < 0.002


def test_rank_sus_gives_expected_copies():
    rng = np.random.default_rng(7)
    rank = rng.permutation(50)
    picks = selection.rank_sus(rank, 50, 2.0, rng)
    counts = np.bincount(picks, minlength=50)
    expected = selection.linear_rank_fitness(rank, 2.0)
    assert np.all(np.abs(counts - expected) < 1.0 + 1e-12)  # SUS: floor or ceil
    assert counts[rank == 49].sum() == 0 and counts[rank == 0].sum() == 2


def test_adaptive_probabilities_srinivas_patnaik():
    f = np.array([1.0, 2.0, 3.0, 4.0])
    pm = adaptive.adaptive_mutation_probability(f, f_max=4.0, f_avg=2.5, pm1=0.1, pm2=0.001)
    np.testing.assert_allclose(pm, [0.1, 0.1, 0.1 - 0.099 / 3, 0.001])
    pc = adaptive.adaptive_crossover_probability(np.array([1.0, 3.25]), np.array([4.0, 1.0]),
                                                 4.0, 2.5, 0.9, 0.6)
    np.testing.assert_allclose(pc, [0.6, 0.75])
    assert np.all(adaptive.adaptive_probability(f, 3.0, 3.0, 0.9, 0.6) == 0.9)


def test_feasibility_rules_and_penalty_ranking():
    f = np.array([5.0, 1.0, 3.0, 0.5])
    g = np.array([[-1.0, -2.0], [0.5, -1.0], [-0.1, -0.1], [2.0, 1.0]])
    v = violation(g, 4)
    np.testing.assert_allclose(v, [0.0, 0.5, 0.0, 3.0])
    rank, fit = rank_feasibility_rules(f, v)
    assert rank.tolist() == [1, 2, 0, 3]  # feasible by f, then infeasible by violation
    assert fit[2] == fit.max()
    rank, fit = rank_penalty(f, v, lam=1.0)  # scores 5, 1.5, 3, 3.5
    assert rank.tolist() == [3, 0, 1, 2]
    np.testing.assert_allclose(fit, 1.0 / np.array([5.0, 1.5, 3.0, 3.5]))


def test_adaptive_penalty_factor_moves_with_best_feasibility():
    p = AdaptivePenalty(lam=10.0, increase=2.0, decrease=1.5, window=3)
    for _ in range(3):
        p.update(False)
    assert p.lam == 20.0
    p.update(True)
    assert p.lam == 20.0  # mixed window: unchanged
    p.update(True), p.update(True)
    assert p.lam == pytest.approx(20.0 / 1.5)
