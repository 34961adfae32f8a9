"""The standard pick cycle (25/305/25 mm), time-optimal under the motor limits with payload."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.optim.errors import InvalidSettings
from pinarms.optim.standard_cycle import (StandardCycle, delta_gate_rows, delta_standard_cycle, gate_length,
                                          gate_points, serial_standard_cycle)
from pinarms.papers import IRB360_1600
from pinarms.robots.delta import closed_chain_state, motor_torques, platform_jacobian
from pinarms.studies.delta_cycle import DELTA_CYCLE_START_M, delta_cycle_rows

CYCLE = StandardCycle(start=DELTA_CYCLE_START_M, payload=1.0)


def test_the_gate_is_25_up_305_across_25_down_with_rounded_corners():
    s = np.linspace(0.0, gate_length(CYCLE), 3001)
    p, dp, ddp = gate_points(CYCLE, s)
    assert np.allclose(p[0], DELTA_CYCLE_START_M) and np.allclose(p[-1], (0.1525, 0.0, -1.0))
    assert np.isclose(p[:, 2].max(), -0.975) and np.isclose(np.ptp(p[:, 0]), 0.305)
    assert np.abs(np.linalg.norm(dp, axis=1) - 1.0).max() < 1e-12        # arc length
    h = 1e-6
    fd = (gate_points(CYCLE, s[5:-5] + h)[0] - gate_points(CYCLE, s[5:-5] - h)[0]) / (2 * h)
    assert np.abs(fd - dp[5:-5]).max() < 1e-8
    assert np.isclose(np.linalg.norm(ddp, axis=1).max(), 1.0 / 0.025)     # the corners' curvature
    with pytest.raises(InvalidSettings, match="horizontal"):
        StandardCycle(start=(0, 0, 0), direction=(0, 0, 1))
    with pytest.raises(InvalidSettings, match="corner_radius"):
        StandardCycle(start=(0, 0, 0), corner_radius=0.03)


@pytest.fixture(scope="module")
def timed(delta):
    return delta_standard_cycle(delta, CYCLE, n=150)


def test_the_time_optimal_move_keeps_every_motor_limit_and_reaches_one(delta, timed):
    """Re-checked independently of the rows: motor speeds through the closed-form Jacobian, torques
    through the closed-chain inverse dynamics of the platform's motion along the profile."""
    lim = delta.limits
    p, dp, ddp = gate_points(CYCLE, timed.s)
    sdd = np.append(timed.sdd, timed.sdd[-1])
    pd, pdd = dp * timed.sd[:, None], ddp * timed.sd[:, None] ** 2 + dp * sdd[:, None]
    loaded = delta.with_payload(1.0)
    state = closed_chain_state(loaded, p, pd, pdd)
    theta_dot = state.v[:, loaded.motor_q]
    jac = platform_jacobian(loaded.geometry, state.q[:, loaded.motor_q])
    assert np.abs(np.einsum("nij,nj->ni", jac, theta_dot) - pd).max() < 1e-9
    assert np.abs(theta_dot).max() <= lim.velocity * (1 + 1e-9)
    tau, _ = motor_torques(loaded, state)
    assert np.abs(tau).max() <= lim.torque * (1 + 1e-6)
    assert max(timed.usage.values()) > 0.999                       # time-optimal: some limit is reached
    assert 0.14 < timed.duration < 0.18


def test_grid_refinement_changes_the_time_by_under_one_percent(delta, timed):
    finer = delta_standard_cycle(delta, CYCLE, n=300)
    assert abs(finer.duration / timed.duration - 1.0) < 0.01


def test_more_payload_is_slower(delta, timed):
    heavy = delta_standard_cycle(delta, StandardCycle(start=DELTA_CYCLE_START_M, payload=6.0), n=150)
    assert heavy.duration > timed.duration * 1.1
    assert heavy.usage["torque"] > 0.999


def test_rows_of_the_cycle_have_both_ends_of_each_segment(delta):
    rows = delta_gate_rows(delta, CYCLE, n=60)
    assert rows.dq.shape == (len(rows.s), 6)   # left and right rows of the 3 motors
    # away from the segment ends, left and right rows are the same point's
    assert np.abs(rows.dq[:, :3] - rows.dq[:, 3:]).max() < 1e-9


@pytest.mark.slow
def test_the_study_rows_compare_with_the_datasheet_and_time_the_scara():
    rows = delta_cycle_rows(quick=True)
    assert [r.paper for r in rows[:3]] == [round(c, 4) for c in IRB360_1600.cycle_s]
    assert IRB360_1600.cycle_s[0] == pytest.approx(60.0 / 140.0)
    assert all(0.3 < r.pinarms < 0.7 for r in rows[:3])
    assert rows[0].pinarms < rows[1].pinarms < rows[2].pinarms
    assert rows[3].paper is None and rows[3].pinarms > rows[0].pinarms   # the SCARA, with its own limits


def test_the_scara_of_seed_000_runs_the_same_cycle():
    from pinarms import robots

    scara = robots.load("scara_mushroom")
    cycle = StandardCycle(start=(0.30, -0.1525, 0.09), direction=(0.0, 1.0, 0.0), payload=1.0)
    timing = serial_standard_cycle(scara, cycle, np.array([-0.5, 1.0, 0.10, 0.0]), n=80)
    assert 0.7 < timing.duration < 1.1 and max(timing.usage.values()) > 0.999
