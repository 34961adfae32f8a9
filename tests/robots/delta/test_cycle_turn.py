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


def test_the_demo_page_runs_the_cycle_with_its_turn():
    """The delta study's session (the demo's html/delta.html): the platform on the gate (closed-form FK of the
    stored motor angles against the gate's points), at the pick and the place during the air dwells, the tool
    at 90 deg at the place and back at 0 at the pick; the cycle as long as the 1 kg row says."""
    from pinarms.optim.standard_cycle import gate_length, gate_points
    from pinarms.papers import IRB360_1600
    from pinarms.robots.delta import forward_position
    from pinarms.studies.delta_cycle import PAGE_BASE_HEIGHT_M, cycle_session

    s = cycle_session(1.0, quick=True, hz=100.0)
    rec = s.deltas["delta_flexpicker"]
    delta = s.delta("delta_flexpicker")
    cycle = StandardCycle(start=DELTA_CYCLE_START_M, payload=1.0)
    way = delta_cycle_time(delta, cycle, np.pi / 2, n=80)
    air = IRB360_1600.air_activation_s
    assert rec.duration == pytest.approx(2 * way.one_way_s + 2 * air, abs=1e-12)
    assert rec.base_to_world[2, 3] == PAGE_BASE_HEIGHT_M
    p = forward_position(delta.geometry, rec.theta)
    # every sample on the gate: its nearest point of a fine sampling of the gate within 0.2 mm
    gate = gate_points(cycle, np.linspace(0.0, gate_length(cycle), 4001))[0]
    nearest = np.min(np.linalg.norm(p[:, None, :] - gate[None], axis=2), axis=1)
    assert nearest.max() < 2e-4
    at_place = (rec.t > way.one_way_s + 1e-9) & (rec.t < way.one_way_s + air - 1e-9)
    np.testing.assert_allclose(p[at_place], np.broadcast_to(gate[-1], p[at_place].shape), atol=1e-9)
    np.testing.assert_allclose(rec.tool[at_place], np.pi / 2, atol=1e-12)
    np.testing.assert_allclose(p[-1], gate[0], atol=1e-9)
    assert rec.tool[0] == 0.0 and rec.tool[-1] == pytest.approx(0.0, abs=1e-12)
