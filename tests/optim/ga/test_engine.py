"""The GA engine on test functions with known optima, reproducibility and stopping rules."""

import numpy as np
import pytest

from pinarms.optim import GARequest, GASettings, GAStop, InvalidSettings, run_ga

PRESETS = {
    "default": GASettings(),
    "seed000": GASettings.seed000(),
    "seed002": GASettings.seed002(),
}


def sphere(x):
    return np.sum((x - 0.3) ** 2, axis=1)


@pytest.mark.parametrize("name", list(PRESETS))
def test_sphere_minimum_found(name):
    r = run_ga(GARequest(sphere, [(-5.0, 5.0)] * 4, PRESETS[name], seed=0, max_generations=150))
    assert r.feasible
    np.testing.assert_allclose(r.x, 0.3, atol=1e-2)
    assert r.f < 1e-4
    s = PRESETS[name]  # elites are not evaluated again
    assert r.evaluations == s.population + r.generations * (s.population - s.elitism)


def _g08(x):
    """CEC 2006 g08: optimum f = -0.0958250415 at (1.2279713, 4.2453733)."""
    x1, x2 = x[:, 0], x[:, 1]
    return -np.sin(2 * np.pi * x1) ** 3 * np.sin(2 * np.pi * x2) / (x1**3 * (x1 + x2))


def _g08_con(x):
    x1, x2 = x[:, 0], x[:, 1]
    return np.stack([x1**2 - x2 + 1.0, 1.0 - x1 + (x2 - 4.0) ** 2], axis=1)


@pytest.mark.parametrize("handling", ["adaptive-penalty", "feasibility-rules"])
def test_g08_constrained_optimum(handling):
    s = GASettings(constraint_handling=handling)
    r = run_ga(GARequest(_g08, [(0.1, 10.0), (0.1, 10.0)], s, constraints=_g08_con, seed=3,
               max_generations=150))
    assert r.feasible and np.all(_g08_con(r.x[None]) <= 0.0)
    assert r.f == pytest.approx(-0.0958250415, rel=1e-3)
    np.testing.assert_allclose(r.x, [1.2279713, 4.2453733], atol=2e-3)


@pytest.mark.parametrize("name", list(PRESETS))
def test_active_constraint_analytic_optimum(name):
    """min x + y s.t. x y >= 1: optimum 2 at (1, 1), on the constraint."""
    r = run_ga(GARequest(lambda x: x.sum(axis=1), [(0.1, 5.0), (0.1, 5.0)], PRESETS[name],
               constraints=lambda x: (1.0 - x[:, 0] * x[:, 1])[:, None], seed=1,
               max_generations=200))
    assert r.feasible and r.x[0] * r.x[1] >= 1.0
    assert r.f == pytest.approx(2.0, rel=5e-3)


def test_same_seed_same_result_and_generator_accepted():
    s = GASettings.seed002()
    a = run_ga(GARequest(sphere, [(-5, 5)] * 3, s, seed=42, max_generations=30))
    b = run_ga(GARequest(sphere, [(-5, 5)] * 3, s, seed=42, max_generations=30))
    c = run_ga(GARequest(sphere, [(-5, 5)] * 3, s, seed=43, max_generations=30))
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.history.best, b.history.best)
    assert not np.array_equal(a.x, c.x)
    d = run_ga(GARequest(sphere, [(-5, 5)] * 3, s, seed=np.random.default_rng(42), max_generations=30))
    np.testing.assert_array_equal(a.x, d.x)


def test_history_is_monotone_and_sized():
    r = run_ga(GARequest(sphere, [(-5, 5)] * 3, GASettings(), seed=0, max_generations=40,
               stall_generations=1000))
    assert r.generations == 40 and r.stop_reason == "max_generations"
    for arr in (r.history.best, r.history.mean, r.history.feasible_share):
        assert arr.shape == (41,)
    assert np.all(np.diff(r.history.best) <= 0.0)
    assert np.all(r.history.mean >= r.history.best)
    assert set(r.history.as_dict()) == {"best", "mean", "feasible_share", "best_violation", "feasible_mean"}
    np.testing.assert_array_equal(r.history.feasible_mean, r.history.mean)  # unconstrained: all feasible


def test_feasible_mean_never_dips_below_the_best_where_the_population_mean_does():
    """Seed 002's GA (the demo's plot): with few feasible individuals the whole population's
    mean counts infeasible ones, faster than the limits allow, and falls below the best."""
    from pinarms import optim
    from pinarms.demo import BOUNDS_002_S
    from pinarms.papers import SEED002
    from pinarms.scenarios import gantry_path_motor_rad

    v, a, j = SEED002.limits_motor
    r = optim.minimize_time(optim.TimingRequest(gantry_path_motor_rad(), "quintic-bspline", v, a, j, method="ga", seed=0,
                            settings=GASettings.seed002(), max_generations=150,
                            initial=SEED002.initial_durations_s[None, :], bounds=BOUNDS_002_S))
    h = r.history
    dips = np.flatnonzero(h.mean < h.best)
    # measured: generations 107-110, 0-2 % of the population feasible
    assert dips.size > 0 and np.all(h.feasible_share[dips] <= 0.05)
    finite = np.isfinite(h.feasible_mean)  # inf: a generation without any feasible individual
    assert finite.sum() > 0.9 * finite.size
    assert np.all(h.feasible_mean[finite] >= h.best[finite])


def test_stall_time_limit_and_callback_stop():
    flat = run_ga(GARequest(lambda x: np.ones(x.shape[0]), [(0, 1)] * 2, GASettings(), seed=0,
                  max_generations=500, stall_generations=7))
    assert flat.stop_reason == "stall" and flat.generations == 7
    slow = run_ga(GARequest(sphere, [(-5, 5)] * 2, GASettings(), seed=0, max_generations=10**6,
                  stall_generations=10**6, time_limit=0.2))
    assert slow.stop_reason == "time_limit" and slow.wall_time < 2.0
    seen = []

    def stop_at_5(progress):
        seen.append(progress.generation)
        return progress.generation >= 5

    cb = run_ga(GARequest(sphere, [(-5, 5)] * 2, GASettings(), seed=0), callback=stop_at_5)
    assert cb.stop_reason == "callback" and seen == [1, 2, 3, 4, 5]


def test_initial_population_drawn_feasible_and_seeded():
    # Feasible only in a thin shell: x^2 + y^2 within [0.9, 1.0] inside [-1, 1]^2 (~15 %).
    con = lambda x: np.stack([np.sum(x**2, 1) - 1.0, 0.9 - np.sum(x**2, 1)], axis=1)
    r = run_ga(GARequest(sphere, [(-1, 1), (-1, 1)], GASettings(), constraints=con, seed=0,
               max_generations=0))
    assert r.history.feasible_share[0] > 0.9
    given = np.array([[0.3, 0.3]])
    r = run_ga(GARequest(sphere, [(-1, 1), (-1, 1)], GASettings(), seed=0, max_generations=0,
               initial=given))
    np.testing.assert_array_equal(r.x, given[0])


def test_no_feasible_point_is_reported():
    r = run_ga(GARequest(sphere, [(0, 1)], GASettings(), constraints=lambda x: 2.0 - x, seed=0,
               max_generations=20))
    assert not r.feasible and r.violation == pytest.approx(1.0, abs=1e-6)


def test_bad_bounds_and_settings_raise():
    with pytest.raises(InvalidSettings, match="lower > upper"):
        GARequest(sphere, [(1.0, 0.0)], GASettings())
    with pytest.raises(InvalidSettings, match="finite"):
        GARequest(sphere, [(0.0, np.inf)], GASettings())
    with pytest.raises(InvalidSettings, match="population"):
        GASettings(population=2)
    with pytest.raises(InvalidSettings, match="pc1 >= pc2"):
        GASettings(pc1=0.5, pc2=0.9)
    with pytest.raises(InvalidSettings, match="selection"):
        GASettings(selection="roulette")


def test_presets_match_papers():
    s0 = GASettings.seed000()
    assert (s0.population, s0.crossover_probability, s0.mutation_probability) == (50, 0.7, 0.1)
    assert s0.selection == "rank-sus"
    s2 = GASettings.seed002()
    assert s2.adaptive and s2.selection == "tournament" and s2.elitism >= 1
    assert s2.mutation == "non-uniform" and s2.nonuniform_shape == 2.0
    assert s2.constraint_handling == "adaptive-penalty"


@pytest.mark.parametrize("kwargs, message", [
    ({"seed": -1}, "seed=-1"),
    ({"seed": 1.5}, "seed=1.5"),
    ({"seed": "a"}, "seed='a'"),
    ({"time_limit": float("nan")}, "time_limit=nan"),
    ({"time_limit": -1.0}, "time_limit=-1.0"),
    ({"stall_generations": 0}, "stall_generations=0"),
    ({"max_generations": 2.5}, "max_generations=2.5"),
    ({"initial": [[0.1, float("nan")]]}, "NaN or inf"),
    ({"initial": "x"}, "initial='x' is not numeric"),
    ({"settings": "fast"}, "settings must be an optim.GASettings"),
])
def test_bad_run_options_raise_named_errors(kwargs, message):
    # A NaN time limit used to be ignored silently (elapsed >= nan is never true).
    with pytest.raises(InvalidSettings, match=message.replace("(", r"\(").replace(".", r"\.")):
        GARequest(sphere, [(-1, 1), (-1, 1)], **{"settings": GASettings(), **kwargs})


@pytest.mark.parametrize("field", ["population", "crossover_probability", "elitism"])
def test_settings_with_non_numbers_raise_named_errors(field):
    with pytest.raises(InvalidSettings, match=f"'{field}': None"):
        GASettings(**{field: None})


def test_a_ga_request_is_checked_when_built_and_the_stop_is_an_enum():
    with pytest.raises(InvalidSettings, match="objective must be callable"):
        GARequest("sphere", [(0.0, 1.0)])
    with pytest.raises(InvalidSettings, match="initial of shape"):
        GARequest(sphere, [(0.0, 1.0)] * 2, initial=[[0.5, 0.5, 0.5]])
    bounds = np.array([[-5.0, 5.0]] * 2)
    request = GARequest(sphere, bounds, seed=0, max_generations=3, stall_generations=100)
    bounds[0, 0] = 0.0  # the request keeps its own read-only copy
    assert request.bounds[0, 0] == -5.0 and not request.bounds.flags.writeable
    r = run_ga(request)
    assert r.stop_reason is GAStop.MAX_GENERATIONS and f"{r.stop_reason}" == "max_generations"
