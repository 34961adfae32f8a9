"""Population evaluation through planning's batched constructors, and the optional GA polish."""

import numpy as np
import pytest

from pinarms import scenarios
from pinarms.optim import GASettings, TimingProblem, TimingRequest, minimize_time
from pinarms.optim.timing.exact import polish_durations
from tests.optim.helpers import dense_peaks

S0 = scenarios.seed000()
S2 = scenarios.seed002()
SEED000_OPTIMUM = 2.608382  # docs/optim.md, tests/optim/test_timing.py


def _problems():
    s1 = scenarios.seed001()
    return [
        TimingProblem(S0.positions, S0.kind, S0.vmax),
        TimingProblem(s1.positions, s1.kind, s1.vmax),
        TimingProblem(s1.positions, s1.kind, s1.vmax,
                      trajectory_options={"velocities": "heuristic", "accelerations": "continuous"}),
        TimingProblem(S2.positions, S2.kind, S2.vmax, S2.amax, S2.jmax),
    ]


@pytest.mark.parametrize("index", range(4))
def test_population_equals_one_trajectory_at_a_time(index):
    p = _problems()[index]
    lo, hi = p.bounds[:, 0], p.bounds[:, 1]
    H = lo + np.random.default_rng(index).random((25, p.n_segments)) * (hi - lo)
    before = p.evaluations
    times, coefs = p.coefficients_batch(H)
    assert p.evaluations - before == 25
    single = [p.trajectory(h) for h in H]
    for k, traj in enumerate(single):
        np.testing.assert_allclose(times[k], traj.knot_times, rtol=0, atol=1e-15)
        ref = traj.coefficients
        np.testing.assert_allclose(coefs[k], ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    pk = p.peaks_batch(H)
    for k, traj in enumerate(single):
        ref = traj.peaks()
        np.testing.assert_allclose(pk[k], np.stack([ref.velocity, ref.acceleration, ref.jerk]), rtol=1e-12)
    # Scaling laws, batched: s*(r) per row equals the one-row call, and durations s*(r) r
    # touch a limit (largest peak / limit is 1).
    ratios = H / H.sum(axis=1, keepdims=True)
    s = p.minimal_scale_batch(H)  # rows need not sum to 1
    np.testing.assert_allclose(s, [p.minimal_scale(r) for r in ratios], rtol=1e-12)
    ratio_max = p.limit_ratios_batch(ratios * s[:, None]).max(axis=1)
    np.testing.assert_allclose(ratio_max, 1.0, rtol=1e-9)


def test_custom_builder_still_evaluated_one_by_one():
    from tests.optim.helpers import build_353

    p = TimingProblem(S0.positions, S0.kind, S0.vmax, builder=build_353)
    H = np.random.default_rng(3).uniform(0.3, 3.0, (6, 3))
    times, coefs = p.coefficients_batch(H)
    assert times.shape == (6, 4) and coefs.shape == (6, 3, 6, 1)
    np.testing.assert_allclose(p.peaks_batch(H), TimingProblem(S0.positions, S0.kind, S0.vmax).peaks_batch(H),
                               rtol=1e-9)


def test_ga_polish_reaches_the_exact_optimum_and_keeps_the_ga_total():
    settings = GASettings.seed000()
    plain = minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, method="ga", settings=settings, seed=4,
                          max_generations=15))
    polished = minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, method="ga", settings=settings, seed=4,
                             max_generations=15, polish=True))
    assert plain.method == "ga" and plain.unpolished_total is None
    assert polished.method == "ga+polish"
    # Same seed, same GA: the polish starts from exactly the plain GA answer.
    assert polished.unpolished_total == pytest.approx(plain.total, rel=1e-12)
    assert polished.raw_total == pytest.approx(plain.raw_total, rel=1e-12)
    assert polished.total <= plain.total
    assert polished.total == pytest.approx(SEED000_OPTIMUM, rel=2e-6)
    assert np.all(dense_peaks(polished.trajectory)[0] <= S0.vmax * (1 + 1e-9))


def test_polish_never_worsens_and_respects_bounds():
    p = TimingProblem(S0.positions, S0.kind, S0.vmax, bounds=[(0.1, 3.0), (1.0, 3.0), (0.1, 3.0)])
    h, ok = polish_durations(p, np.array([2.0, 2.0, 2.0]))
    assert ok and h[1] >= 1.0 - 1e-12 and p.is_feasible(h)
    again, _ = polish_durations(p, h)
    assert again.sum() <= h.sum() * (1 + 1e-12)


@pytest.mark.slow
def test_seed002_ga_with_and_without_polish():
    p = TimingProblem(S2.positions, S2.kind, S2.vmax, S2.amax, S2.jmax)
    exact = minimize_time(TimingRequest(method="exact", problem=p))
    ga = minimize_time(TimingRequest(method="ga", problem=p, seed=0, max_generations=150))
    gp = minimize_time(TimingRequest(method="ga", problem=p, seed=0, max_generations=150, polish=True))
    assert gp.unpolished_total == pytest.approx(ga.total, rel=1e-12)
    assert exact.total * (1 - 1e-9) <= gp.total <= ga.total
    assert gp.total <= exact.total * 1.001  # the polish lands on the exact optimum's basin here
    pk = dense_peaks(gp.trajectory)
    assert np.all(pk <= np.stack([S2.vmax, S2.amax, S2.jmax]) * (1 + 1e-9))
