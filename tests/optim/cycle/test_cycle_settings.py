"""Every setting of cycles, line schedules, layout searches and timings has a stated cap (optim.caps).

A slip such as ``lift_step=1e-7``, ``n_offsets=10**9`` or a grid step of 1e-300 is a
:class:`SettingOutOfRange` naming the setting and its range, raised at once (well under a
second) and before any large allocation (measured with tracemalloc), never a loop that runs
for hours or a MemoryError.
"""

from __future__ import annotations

import math
import time
import tracemalloc

import numpy as np
import pytest

from pinarms import optim, planning, robots
from pinarms.optim import caps
from pinarms.optim.errors import InvalidSettings, SettingOutOfRange
from pinarms.errors import InvalidInput

PICK, PLACE = [0.30, 0.25, 0.10], [-0.20, 0.35, 0.08]
# the packages load their names on first use: load them now, so that no refusal's clock counts an import
LOADED = [getattr(package, name) for package in (optim, planning) for name in package.__all__]


@pytest.fixture(scope="module")
def scara():
    return robots.load("scara_mushroom")


def refused_at_once(fn, *words, seconds=1.0, bytes_=50e6):
    """``fn()`` raises SettingOutOfRange naming ``words`` within ``seconds``, allocating < ``bytes_``."""
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(SettingOutOfRange) as info:
            fn()
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    assert time.perf_counter() - t0 < seconds
    assert peak < bytes_, f"{peak / 1e6:.0f} MB allocated before the refusal"
    for w in words:
        assert w in str(info.value), f"{w!r} not in {info.value}"
    return info.value


def test_the_error_is_both_invalid_settings_and_invalid_input():
    assert issubclass(SettingOutOfRange, InvalidSettings) and issubclass(SettingOutOfRange, InvalidInput)
    with pytest.raises(SettingOutOfRange, match="2 to 1,000"):
        caps.count_setting(10**9, "n", 2, 1000)
    for bad in (math.nan, math.inf, -1.0, "1", None, True):
        with pytest.raises(SettingOutOfRange):
            caps.number_setting(bad, "x", 0.0, unit="m")
    assert caps.number_setting(np.float32(0.5), "x", 0.0, 1.0) == 0.5


@pytest.fixture(scope="module")
def station():
    from pinarms.robots.cell import load_cell

    return load_cell("aubo_food_station")


@pytest.mark.parametrize("lift_step", [1e-7, 0.0, -0.02, math.nan, math.inf, 5.0])
def test_cell_settings_refuse_a_lift_step_outside_its_range(station, lift_step):
    refused_at_once(lambda: optim.CellSettings(station, lift_step=lift_step), "lift_step", "0.001")


@pytest.mark.parametrize("name, value, word", [
    ("margin", 1e-9, "margin"), ("margin", math.nan, "margin"), ("clearance", -0.01, "clearance"),
    ("clearance", math.inf, "clearance")])
def test_cell_settings_refuse_bad_values(station, name, value, word):
    refused_at_once(lambda: optim.CellSettings(station, **{name: value}), word)


@pytest.mark.parametrize("value", [0.0, math.nan])
def test_a_straight_approach_refuses_a_bad_tool_speed(value):
    refused_at_once(lambda: optim.CycleApproach("straight", tool_speed=value), "tool_speed")


@pytest.mark.parametrize("dwell", [math.nan, math.inf, -0.1, 1e9])
def test_a_dwell_is_a_finite_time_up_to_an_hour(dwell):
    refused_at_once(lambda: optim.PickPlace(PICK, PLACE, dwell=dwell), "dwell", "3600")
    assert optim.PickPlace(PICK, PLACE, dwell=caps.MAX_DWELL).dwell == caps.MAX_DWELL


def test_schedule_line_refuses_a_billion_offsets_before_touching_the_cell():
    # the settings are checked before the cell or the cycles are used: placeholders show it
    err = refused_at_once(lambda: optim.schedule_line(None, {"left": None, "right": None}, n_offsets=10**9),
                          "n_offsets", "1,000")
    assert "1,000,000,000" in str(err)
    refused_at_once(lambda: optim.schedule_line(None, {"a": None, "b": None}, margin=0.0), "margin")
    refused_at_once(lambda: optim.schedule_line(None, {"a": None, "b": None}, clearance=math.nan), "clearance")


@pytest.mark.parametrize("axes", [dict(x=(0.0, 1.0, 1e-300), y=0.0), dict(x=(0.0, 1.0, 5e-324), y=0.0),
                                  dict(x=(0.0, 1.0, 0.001), y=(0.0, 1.0, 0.001), z=(0.0, 1.0, 0.001),
                                       yaw=(0.0, 1.0, 0.001))])
def test_layout_grids_are_capped_before_allocation(axes):
    refused_at_once(lambda: optim.grid_candidates(**axes), "1,000,000")


def test_random_placements_are_capped():
    refused_at_once(lambda: optim.random_candidates(10**9, x=(0.0, 1.0), y=0.0), "n (random placements)")


@pytest.mark.parametrize("name, value", [("refine", 10**6), ("refine_evaluations", 10**9),
                                         ("workspace_samples", 10**12), ("chunk_size", 10**12), ("seed", 2**70)])
def test_search_layout_counts_are_capped(scara, name, value):
    cand = optim.grid_candidates(x=0.0, y=0.0)
    refused_at_once(lambda: optim.search_layout(optim.LayoutRequest(scara, PICK, PLACE, cand, **{name: value})), name)


def test_search_layout_caps_the_pairs_of_points(scara):
    picks = np.tile(PICK, (40, 1))
    places = np.tile(PLACE, (40, 1))
    refused_at_once(lambda: optim.search_layout(optim.LayoutRequest(scara, picks, places, np.zeros((1, 4)))), "1,600", "1,000")


def test_time_optimal_grid_and_time_scaled_samples_are_capped():
    path = planning.joint_spline(np.array([[0.0, 0.0], [0.5, 0.2], [1.0, -0.3]]))
    cons = [planning.JointVelocityConstraint(np.array([1.0, 1.0])),
            planning.JointAccelerationConstraint(np.array([4.0, 4.0]))]
    refused_at_once(lambda: optim.time_optimal(path, cons, grid=10**9), "grid", "100,000")
    refused_at_once(lambda: optim.time_optimal(path, cons, max_rounds=10**6), "max_rounds")
    refused_at_once(lambda: optim.time_scaled(path, cons, samples=10**10), "samples")
    # a tiny kappa or rtol once refined the grid 20 or 50 times over (10^8 points and more)
    refused_at_once(lambda: optim.time_optimal(path, cons, kappa=5e-324), "kappa", "0.0001")
    refused_at_once(lambda: optim.time_optimal(path, cons, rtol=1e-300), "rtol", "1e-06")


def test_a_clearance_is_at_most_a_metre(station):
    refused_at_once(lambda: optim.CellSettings(station, clearance=1e300), "clearance", "1 m")
    refused_at_once(lambda: optim.schedule_line(None, {"a": None, "b": None}, clearance=2.0), "clearance")


def test_ga_population_and_generations_are_capped():
    with pytest.raises(InvalidSettings, match="10,000"):
        optim.GASettings(population=10**9)
    with pytest.raises(InvalidSettings, match="1,000,000"):
        optim.GASettings(max_generations=10**12)
    refused_at_once(lambda: optim.run_ga(optim.GARequest(lambda x: x.sum(axis=1), [(0.0, 1.0)], max_generations=10**12)),
                    "max_generations")
