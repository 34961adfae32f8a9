"""The fourth axis in the standard cycle: the tool's turn loads no arm motor, so a way takes the longer of the
platform's time-optimal move and the tool's shortest rest-to-rest turn (ABB's "90 degrees rotation of axis 4")."""

import numpy as np
import pytest

from pinarms.optim.errors import InvalidSettings
from pinarms.optim.standard_cycle import StandardCycle
from pinarms.optim.standard_cycle.delta_cycle import (TOOL_ACCELERATION_FACTOR, delta_cycle_time, tool_turn_limits,
                                                      tool_turn_time)
from pinarms.robots.delta import ClosedChainState, closed_chain_state, load_delta, motor_torques
from pinarms.studies.delta_cycle import DELTA_CYCLE_START_M


@pytest.fixture(scope="module")
def delta():
    return load_delta("delta_flexpicker").with_payload(1.0)


def test_the_tool_turn_loads_no_arm_motor(delta):
    """Closed-chain torques of the three arm motors along a platform motion, the tool at rest and then turning
    (angle, speed 20 rad/s, acceleration 200 rad/s^2): the same within 1e-9 N m."""
    rng = np.random.default_rng(38)
    p = np.array([0.05, -0.1, -1.0]) + 0.1 * rng.standard_normal((8, 3))
    pd, pdd = 2.0 * rng.standard_normal((8, 3)), 30.0 * rng.standard_normal((8, 3))
    still = closed_chain_state(delta, p, pd, pdd)
    q, v, a = still.q.copy(), still.v.copy(), still.a.copy()
    q[:, delta.tool_q], v[:, delta.tool_q], a[:, delta.tool_q] = 1.3, 20.0, 200.0
    tau_still = motor_torques(delta, still)[0]
    tau_turn = motor_torques(delta, ClosedChainState(q, v, a))[0]
    assert np.abs(tau_still[:, :3]).max() > 1.0  # the motors do work here
    np.testing.assert_allclose(tau_turn[:, :3], tau_still[:, :3], atol=1e-9)


def test_a_way_takes_the_longer_of_move_and_turn(delta):
    plain = load_delta("delta_flexpicker")
    v, a = tool_turn_limits(plain)
    assert (v, a) == (float(plain.model.velocityLimit[plain.tool_q]), TOOL_ACCELERATION_FACTOR * v)
    quarter = tool_turn_time(np.pi / 2, v, a)
    assert quarter == pytest.approx(2.0 * np.sqrt((np.pi / 2) / a), rel=1e-12)  # bang-bang: no cruise at 20 rad/s
    light = delta_cycle_time(plain, StandardCycle(start=DELTA_CYCLE_START_M, payload=1.0), np.pi / 2, n=80)
    heavy = delta_cycle_time(plain, StandardCycle(start=DELTA_CYCLE_START_M, payload=6.0), np.pi / 2, n=80)
    none = delta_cycle_time(plain, StandardCycle(start=DELTA_CYCLE_START_M, payload=1.0), 0.0, n=80)
    assert none.turn_s == 0.0 and none.one_way_s == none.move.duration
    # at 1 kg the platform is faster than the quarter turn: the turn sets the way; at 6 kg the platform does
    assert light.move.duration < quarter and light.one_way_s == quarter and light.binding == "tool turn"
    assert heavy.move.duration > quarter and heavy.one_way_s == heavy.move.duration and "torque" in heavy.binding
    assert light.move.duration == none.move.duration


def test_a_turn_needs_a_fourth_axis():
    class NoTool:
        name, tool_q = "three axes", None

    with pytest.raises(InvalidSettings, match="no fourth axis"):
        tool_turn_limits(NoTool())
