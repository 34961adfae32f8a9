"""Time-jerk timing and the time-optimal references."""

import numpy as np
import pytest

from pinarms.optim import (InvalidSettings, TimingRequest, jerk_integral, minimize_time, minimize_time_jerk,
                   path_velocity_limit, ruckig_limit, double_s_limit, toppra_limit)
from pinarms import scenarios
from tests.optim.helpers import dense_peaks

S1 = scenarios.seed001()
S0 = scenarios.seed000()


def test_jerk_integral_is_exact():
    traj = minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, method="exact")).trajectory
    # Independent: fine trapezoid per piece (jerk is discontinuous at the knots).
    total = 0.0
    for a, b in zip(traj.knot_times[:-1], traj.knot_times[1:]):
        t = np.linspace(a + 1e-12, b - 1e-12, 200001)
        total += np.trapezoid(np.sum(traj.sample(t)[3] ** 2, axis=1), t)
    assert jerk_integral(traj) == pytest.approx(total, rel=1e-6)


@pytest.mark.parametrize("method", ["exact", pytest.param("ga", marks=pytest.mark.slow)])
def test_two_stage_holds_time_cap_and_lowers_jerk(method):
    r = minimize_time_jerk(TimingRequest(S0.positions, S0.kind, S0.vmax, method=method, max_generations=40),
                           mode="two-stage", time_factor=1.1)
    assert r.total <= 1.1 * r.time_optimal_total * (1 + 1e-9)
    fastest = minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, method="exact"))
    assert r.jerk_integral < jerk_integral(fastest.trajectory)
    assert np.all(dense_peaks(r.trajectory)[0] <= S0.vmax * (1 + 1e-9))


def test_weighted_exact_closed_form_scale_and_ga_agree():
    kw = dict(mode="weighted", k_time=1.0, k_jerk=1e-3)
    ex = minimize_time_jerk(TimingRequest(S1.positions, S1.kind, S1.vmax, method="exact"), **kw)
    ga = minimize_time_jerk(TimingRequest(S1.positions, S1.kind, S1.vmax, method="ga", seed=0, max_generations=80),
                            **kw)
    assert ex.objective <= ga.objective * (1 + 1e-6)
    assert ga.objective <= ex.objective * 1.02
    assert ex.objective == pytest.approx(ex.total + 1e-3 * ex.jerk_integral)
    assert np.all(dense_peaks(ex.trajectory)[0] <= S1.vmax * (1 + 1e-9))


def test_time_jerk_arguments_checked():
    with pytest.raises(InvalidSettings):
        minimize_time_jerk(TimingRequest(S0.positions, S0.kind, S0.vmax), time_factor=0.9)
    with pytest.raises(InvalidSettings):
        minimize_time_jerk(TimingRequest(S0.positions, S0.kind, S0.vmax), mode="pareto")


def test_references_bound_the_polynomial_timing():
    r = minimize_time(TimingRequest(S0.positions, S0.kind, S0.vmax, method="exact"))
    # Monotone single-joint path at 55 deg/s: 69 deg / 55 deg/s.
    assert path_velocity_limit(r.trajectory, S0.vmax) == pytest.approx(69.0 / 55.0, rel=1e-6)
    a = 4.0
    t_toppra = toppra_limit(r.trajectory, S0.vmax, a)
    assert 69.0 / 55.0 < t_toppra < r.total * 1.05
    q0, q1 = S1.positions[0], S1.positions[-1]
    t_ruckig = ruckig_limit(q0, q1, S1.vmax, 10.0, 100.0)
    assert t_ruckig == pytest.approx(double_s_limit(q0, q1, S1.vmax, 10.0, 100.0), rel=1e-6)
