"""Minimum-time timing: feasibility by independent dense sampling, errors, paper scenarios."""

import numpy as np
import pytest

from pinarms.optim import (GASettings, InfeasibleProblem, InvalidLimits, TimingProblem, TimingRequest, TimingStatus,
                           minimize_time)
from pinarms import scenarios
from tests.optim.helpers import build_353, dense_peaks

S0 = scenarios.seed000()
#: Exact optimum of seed 000's model (scaling laws + SLSQP + Nelder-Mead; docs/optim.md).
SEED000_OPTIMUM = 2.608382


def _assert_feasible(result, vmax, amax=None, jmax=None):
    pk = dense_peaks(result.trajectory)
    assert np.all(pk[0] <= np.asarray(vmax) * (1 + 1e-9))
    if amax is not None:
        assert np.all(pk[1] <= np.asarray(amax) * (1 + 1e-9))
    if jmax is not None:
        assert np.all(pk[2] <= np.asarray(jmax) * (1 + 1e-9))
    np.testing.assert_allclose(result.total, result.durations.sum())
    np.testing.assert_allclose(result.trajectory.duration, result.total, rtol=1e-12)


@pytest.fixture(scope="module")
def seed000_exact():
    return minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, method="exact"))


def test_seed000_exact_optimum_is_below_paper(seed000_exact):
    r = seed000_exact
    _assert_feasible(r, S0.vmax)
    assert r.total == pytest.approx(SEED000_OPTIMUM, rel=1e-5)
    np.testing.assert_allclose(r.durations, [0.84971, 0.70845, 1.05023], atol=2e-4)
    # The velocity limit is active: the exact answer touches 55 deg/s.
    assert np.degrees(r.peaks.velocity[0]) == pytest.approx(55.0, rel=1e-6)
    # The paper's 3.607 s is 38 % above its own model's optimum.
    assert S0.paper["total"] / r.total - 1 == pytest.approx(0.3829, abs=1e-3)


def test_seed000_paper_times_give_44_deg_s_not_54():
    p = TimingProblem(S0.positions, S0.kind, S0.vmax)
    peak = p.peaks(np.array(S0.paper["durations"]))[0, 0]
    assert np.degrees(peak) == pytest.approx(44.459, abs=1e-3)  # paper prints 54.2
    # Paper's reduction 39.8 % = (6 - 3.607) / 6 (39.88 %, truncated).
    assert (6.0 - S0.paper["total"]) / 6.0 * 100 == pytest.approx(39.8, abs=0.1)


def test_seed000_ga_within_half_percent_of_exact():
    r = minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, method="ga",
                      settings=GASettings.seed000(), seed=0, max_generations=40))
    _assert_feasible(r, S0.vmax)
    assert r.total <= SEED000_OPTIMUM * 1.005
    assert r.total >= SEED000_OPTIMUM * (1 - 1e-6)  # nobody beats the optimum
    assert r.raw_total >= r.total and r.history.best.shape == (41,)  # 40 generations + initial
    assert r.method == "ga" and r.evaluations > 0


def test_planning_353_matches_independent_builder():
    p = TimingProblem(S0.positions, S0.kind, S0.vmax)
    q = TimingProblem(S0.positions, S0.kind, S0.vmax, builder=build_353)
    H = np.random.default_rng(0).uniform(0.3, 3.0, (20, 3))
    np.testing.assert_allclose(p.peaks_batch(H), q.peaks_batch(H), rtol=1e-9)
    # Batched peaks equal one-by-one peaks of planning's own search.
    np.testing.assert_allclose(p.peaks_batch(H), np.stack([p.peaks(h) for h in H]), rtol=1e-12)


def test_seed001_closed_form_rest_to_rest_quintics():
    s = scenarios.seed001()
    r = minimize_time(TimingRequest(s.positions, s.kind, s.vmax, method="exact"))
    # At rest at every via point each quintic peaks at 15/8 * dq / h.
    expected = 1.875 * np.max(np.abs(np.diff(s.positions, axis=0)) / s.vmax, axis=1)
    np.testing.assert_allclose(r.durations, expected, rtol=1e-6)
    _assert_feasible(r, s.vmax)
    g = minimize_time(TimingRequest(s.positions, s.kind, s.vmax, method="ga", seed=1, max_generations=60))
    _assert_feasible(g, s.vmax)
    assert g.total <= r.total * 1.01


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan, np.inf, [1.0, 2.0], "fast"])
def test_invalid_limits_raise(bad):
    with pytest.raises(InvalidLimits):
        TimingRequest(S0.positions, S0.kind, bad)
    with pytest.raises(InvalidLimits):
        TimingRequest(S0.positions, S0.kind, 1.0, amax=bad)


def test_missing_vmax_and_bad_kind():
    with pytest.raises(InvalidLimits, match="vmax is required"):
        TimingRequest(S0.positions, S0.kind, None)
    with pytest.raises(ValueError, match="kind"):
        TimingRequest(S0.positions, "septic", 1.0)


@pytest.mark.parametrize("method", ["ga", "exact"])
def test_no_feasible_timing_within_bounds_says_so(method):
    # Upper bounds sum to 1.5 s < 2.608 s needed: no feasible timing exists.
    with pytest.raises(InfeasibleProblem, match="bounds"):
        minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, method=method, bounds=(0.1, 0.5),
                      max_generations=15))


def test_bounds_respected_when_active():
    r = minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, method="exact",
                      bounds=[(0.1, 3.0), (1.0, 3.0), (0.1, 3.0)]))
    assert r.durations[1] >= 1.0 - 1e-12
    assert r.total > SEED000_OPTIMUM  # the unconstrained optimum has h2 = 0.708 s
    _assert_feasible(r, S0.vmax)


@pytest.mark.slow
def test_seed002_gantry_exact_and_ga_feasible():
    s = scenarios.seed002()
    p = TimingProblem(s.positions, s.kind, s.vmax, s.amax, s.jmax)
    # The paper's initial times break the jerk limit on this path (documented).
    assert p.limit_ratios(s.initial_durations).max() > 1.0
    ex = minimize_time(TimingRequest(method="exact", problem=p))
    _assert_feasible(ex, s.vmax, s.amax, s.jmax)
    assert ex.total == pytest.approx(1.4830, abs=2e-3)
    ga = minimize_time(TimingRequest(method="ga", problem=p, seed=0, max_generations=80))
    _assert_feasible(ga, s.vmax, s.amax, s.jmax)
    assert ex.total <= ga.total * (1 + 1e-6) and ga.total < 1.89


@pytest.mark.parametrize("kind", ["multi-quintic", "quintic-bspline"])
@pytest.mark.parametrize("method", ["ga", "exact"])
def test_single_segment_point_to_point_is_solved(kind, method):
    # One rest-to-rest quintic peaks at 15/8 d/T: with d = 0.8 rad, vmax 2 rad/s the
    # minimum time is 0.75 s. The default bounds used to stop just below it (infeasible).
    r = minimize_time(TimingRequest([0.2, 1.0], kind, 2.0, method=method, seed=0, max_generations=20))
    assert r.total == pytest.approx(15 / 8 * 0.8 / 2.0, rel=1e-8)
    _assert_feasible(r, 2.0)


def test_353_needs_exactly_four_via_points():
    from pinarms.errors import InvalidInput

    for q in ([0.0, 1.0], [0.0, 1.0, 2.0], [0.0, 1.0, 2.0, 3.0, 4.0]):
        with pytest.raises(InvalidInput, match=f"needs 4 via points, got {len(q)}"):
            TimingRequest(q, "3-5-3", 1.0, method="exact")


def test_non_numeric_positions_bounds_and_unknown_options_are_named():
    from pinarms.optim import InvalidSettings
    from pinarms.errors import InvalidInput

    with pytest.raises(InvalidInput, match="positions=.*not numeric"):
        TimingRequest(["a", "b"], "multi-quintic", 1.0)
    with pytest.raises(InvalidSettings, match="bounds='short' are not numeric"):
        TimingRequest(S0.positions, S0.kind, S0.vmax, bounds="short")
    with pytest.raises(InvalidSettings, match=r"\['speed'\] are not options of the 'multi-quintic'"):
        TimingRequest([0.0, 1.0, 2.0], "multi-quintic", 1.0, trajectory_options={"speed": 1})
    # Known options still pass through (heuristic via velocities change the optimum).
    rest = minimize_time(TimingRequest([0.0, 1.0, 2.0], "multi-quintic", 1.0, method="exact"))
    moving = minimize_time(TimingRequest([0.0, 1.0, 2.0], "multi-quintic", 1.0, method="exact",
                           trajectory_options={"velocities": "heuristic"}))
    assert moving.total < rest.total * 0.9


@pytest.mark.parametrize("method", ["ga", "exact"])
def test_bad_seed_is_refused_before_any_work(method):
    from pinarms.optim import InvalidSettings, minimize_time_jerk

    with pytest.raises(InvalidSettings, match="seed=-1"):
        TimingRequest(S0.positions, S0.kind, S0.vmax, method=method, seed=-1)
    with pytest.raises(InvalidSettings, match="time_factor='a'"):
        minimize_time_jerk(TimingRequest(S0.positions, S0.kind, S0.vmax, method=method), time_factor="a")
    with pytest.raises(InvalidSettings, match="k_time='a'"):
        minimize_time_jerk(TimingRequest(S0.positions, S0.kind, S0.vmax, method=method), mode="weighted", k_time="a")


def _scara():
    from pinarms import robots

    return robots.load("scara_mushroom")


def test_a_timing_request_refuses_bad_settings_when_built_and_holds_its_problem():
    from pinarms.optim import InvalidSettings, SettingOutOfRange

    with pytest.raises(InvalidSettings, match="method='fast'"):
        TimingRequest(S0.positions, S0.kind, S0.vmax, method="fast")
    with pytest.raises(SettingOutOfRange, match="max_generations = 0"):
        TimingRequest(S0.positions, S0.kind, S0.vmax, max_generations=0)
    with pytest.raises(InvalidSettings, match="not both"):
        TimingRequest(problem=TimingProblem(S0.positions, S0.kind, S0.vmax), robot=_scara(), torque_limits=True)
    positions = np.array(S0.positions, dtype=float)
    request = TimingRequest(positions, S0.kind, S0.vmax, method="exact")
    assert isinstance(request.problem, TimingProblem) and request.problem.kind == S0.kind
    positions[:] = 0.0  # the request and its problem keep their own read-only copy
    assert not request.positions.flags.writeable
    assert minimize_time(request).total == minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax,
                                                                       method="exact")).total


def test_the_status_says_how_the_optimiser_ended():
    exact = minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, method="exact"))
    assert exact.status is TimingStatus.SOLVED and exact.status_reason == "" and f"{exact.status}" == "solved"
    ga = minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, seed=0, max_generations=3, stall_generations=50))
    assert ga.status is TimingStatus.MAX_GENERATIONS and ga.status == ga.stop_reason == "max_generations"
    stopped = minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, seed=0, max_generations=50),
                            callback=lambda progress: True)
    assert stopped.status is TimingStatus.CALLBACK and "best so far" in stopped.status_reason
    _assert_feasible(stopped, S0.vmax)  # a stopped GA still returns a verified timing
