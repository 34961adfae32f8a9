"""One cycle request in, one call, one result with a status: ``plan_cycle(CycleRequest(...))``.

The request's groups check their values when built, the request checks what needs the robot
(limits per joint, torque limits with the payload), and ``plan_cycle`` takes nothing else.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from pinarms import robots
from pinarms.optim.cycle import (CellSettings, CycleApproach, CycleLoad, CycleRequest, CycleStatus, CycleTiming,
                                 PickPlace, plan_cycle)
from pinarms.optim.errors import InvalidLimits, InvalidSettings, SettingOutOfRange
from pinarms.errors import InvalidInput

PICK, PLACE = [0.30, 0.25, 0.10], [-0.20, 0.35, 0.08]


@pytest.fixture(scope="module")
def scara():
    return robots.load("scara_mushroom")


@pytest.fixture(scope="module")
def spec():
    return PickPlace(PICK, PLACE, lift=0.04, dwell=0.1)


def test_the_request_plans_the_cycle_with_a_status(scara, spec):
    request = CycleRequest(scara, spec, timing=CycleTiming("quintic-bspline", amax=8.0))
    by_request = plan_cycle(request)
    assert by_request.status is CycleStatus.OK and by_request.as_dict()["status"] == "ok"
    assert [s.value for s in CycleStatus] == ["ok", "re-planned", "transfer planned", "unreachable", "limits not met",
                                              "in collision"]
    assert by_request.solved and by_request.raise_for_status() is by_request and by_request.reason == ""
    # the limits the request resolved are those the result was timed under
    np.testing.assert_array_equal(by_request.vmax, np.asarray(scara.velocity_limit, dtype=float))
    np.testing.assert_array_equal(request.amax, np.full(scara.nq, 8.0))
    assert request.jmax is None and request.torque is None


def test_a_request_with_torque_limits_carries_the_payload(scara, spec):
    request = CycleRequest(scara, spec, load=CycleLoad(payload=0.5, torque_limits=True))
    assert request.torque is not None and request.torque.robot.payload.mass == pytest.approx(0.5)
    np.testing.assert_array_equal(request.torque.limit, np.asarray(scara.effort_limit, dtype=float))
    result = plan_cycle(request)
    assert result.payload.mass == pytest.approx(0.5) and result.torque_ratios.max() <= 1.0 + 1e-6


@pytest.mark.parametrize("make, error, words", [
    (lambda: CycleTiming(kind="cubic"), InvalidInput, "cycle trajectory family"),
    (lambda: CycleTiming(method="bfgs"), InvalidSettings, "method='bfgs'"),
    (lambda: CycleLoad(payload=1.0), InvalidSettings, "torque_limits=True"),
    (lambda: CycleApproach("sideways"), InvalidInput, "approach='sideways'"),
    (lambda: CycleApproach("straight", tool_speed=0.0), SettingOutOfRange, "tool_speed"),
    (lambda: CellSettings(None), InvalidInput, "robots.cell.Cell"),
])
def test_each_group_checks_its_values_when_built(make, error, words):
    with pytest.raises(error, match=words):
        make()


@pytest.fixture(scope="module")
def station():
    from pinarms.robots.cell import load_cell

    return load_cell("aubo_food_station")


@pytest.mark.parametrize("name, value, word", [("lift_step", 1e-7, "lift_step"), ("margin", 1e-9, "margin"),
                                               ("clearance", math.inf, "clearance")])
def test_cell_settings_are_capped(station, name, value, word):
    cell = station
    with pytest.raises(SettingOutOfRange, match=word):
        CellSettings(cell, **{name: value})
    settings = CellSettings(cell, clearance=np.float32(0.01))
    assert isinstance(settings.clearance, float) and settings.clearance == pytest.approx(0.01)


def test_the_request_checks_what_needs_the_robot(scara, spec):
    with pytest.raises(InvalidInput, match="spec must be a PickPlace, got dict"):
        CycleRequest(scara, {"pick": PICK})
    with pytest.raises(InvalidInput, match="timing must be a CycleTiming"):
        CycleRequest(scara, spec, timing={"amax": 1.0})
    with pytest.raises(InvalidInput, match="3-5-3"):
        CycleRequest(scara, PickPlace(PICK, PLACE, via=[(0.1, 0.4, 0.2)]), timing=CycleTiming("3-5-3"))
    with pytest.raises(InvalidLimits, match="amax"):
        CycleRequest(scara, spec, timing=CycleTiming(amax=[1.0, 2.0]))
    with pytest.raises(InvalidLimits, match="vmax"):
        CycleRequest(scara, spec, timing=CycleTiming(vmax=-1.0))


def test_a_request_is_frozen_and_plan_cycle_takes_it_alone(scara, spec):
    request = CycleRequest(scara, spec)
    with pytest.raises(dataclasses.FrozenInstanceError):
        request.spec = spec
    with pytest.raises(InvalidInput, match="plan_cycle takes one CycleRequest, got Robot"):
        plan_cycle(scara)
    with pytest.raises(TypeError):  # the former keyword form is gone
        plan_cycle(request, amax=1.0)
    # a request re-built for another spec re-checks and keeps its settings
    other = dataclasses.replace(request, spec=PickPlace(PICK, PLACE, lift=0.06))
    assert other.spec.lift == 0.06 and other.timing is request.timing
