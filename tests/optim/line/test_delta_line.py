"""A delta above the belt: its pick times, its task map (with the item's yaw), the line simulated."""

from dataclasses import replace

import numpy as np
import pytest

from pinarms.optim.errors import InfeasibleProblem
from pinarms.optim.line import Stream, TrackingSpec, run_line
from pinarms.optim.line.delta_maps import build_delta_map
from pinarms.optim.line.map_request import DeltaMapRequest
from pinarms.optim.line.delta_tracking import delta_pick_times, hermite_points, platform_move_time, tool_turn_time
from pinarms.optim.line.tracking import can_yaw
from pinarms.optim.standard_cycle import JointPathRows, delta_path_rows
from pinarms.robots.delta import forward_position, inverse_position, platform_jacobian
from pinarms.studies.delta_line import delta_line
from pinarms.studies.line import ENOKI


@pytest.fixture(scope="module")
def line():
    return delta_line(2, 60.0, item=ENOKI, seeds=(0, 1), duration=120.0)


@pytest.fixture(scope="module")
def small_map(line):
    st = line.stations[0]
    return build_delta_map(DeltaMapRequest(st, line.belt, line.tracking, mass=ENOKI.mass, item_height=ENOKI.size[2],
                                           nu=5, nw=3, n=12)).task_map


def test_tool_turn_time_bang_bang():
    # triangular: 2 sqrt(a / A); trapezoid: a / V + V / A; continuous where they meet (a = V^2 / A)
    assert tool_turn_time(0.5, 20.0, 200.0) == pytest.approx(2 * np.sqrt(0.5 / 200.0), rel=1e-12)
    assert tool_turn_time(3.0, 20.0, 200.0) == pytest.approx(3.0 / 20.0 + 20.0 / 200.0, rel=1e-12)
    assert tool_turn_time(2.0 - 1e-9, 20.0, 200.0) == pytest.approx(tool_turn_time(2.0 + 1e-9, 20.0, 200.0), abs=1e-8)


def test_delta_can_yaw_by_its_fourth_axis(line):
    assert can_yaw(line.stations[0].robot) is True


def test_map_nodes_equal_exact_pick_times(line, small_map):
    m, st = small_map, line.stations[0]
    u0 = float(line.belt.to_belt(st.base_to_world[:3, 3])[0])
    i, j = 2, 1
    a, c = delta_pick_times(st, line.belt, line.tracking, u0 + m.du[i], m.w[j], mass=ENOKI.mass,
                            item_height=ENOKI.size[2], n=12)
    assert (round(a, 6), round(c, 6)) == (round(m.approach[i, j], 6), round(m.leave[i, j], 6))
    # a pick takes about 0.15-0.35 s each way, tracking and release aside (FlexPicker class)
    assert 0.1 < a < 0.4 and 0.1 < c < 0.4


def test_map_measures_the_yaw(small_map):
    m = small_map
    # the fourth axis turns pi/2 in 0.177 s, longer than the platform's fastest moves: the time depends on yaw
    assert m.yaw is not None and m.yaw_spread > 0.005 and not m.warnings()
    i, j = np.argwhere(np.isfinite(m.approach))[0]
    turn = tool_turn_time(np.pi / 2, 20.0, 200.0)
    a_edge = m.yaw_approach[-1, 0, i, j]
    assert round(a_edge, 9) == round(max(m.approach[i, j], turn), 9)
    assert m.yaw_approach[len(m.yaw) // 2, 0, i, j] == m.approach[i, j]


def test_approach_keeps_motor_limits_and_arrives_with_the_belt(line):
    """Re-evaluated independently along the timed approach: motor speeds from the closed-form Jacobian, the
    platform's end velocity equal to the belt's."""
    from pinarms.optim.standard_cycle import time_rows

    st = line.stations[0]
    arm = st.robot
    box = st.world_to_base(st.place.position) - arm.tcp_offset
    pre = st.world_to_base(line.belt.to_world(1.2, 0.05, 0.07)) - arm.tcp_offset
    d = np.array([1.0, 0.0, 0.0])
    L = float(np.linalg.norm(pre - box))
    pts = hermite_points(box, pre, pre - box, L * d, L)
    s = np.linspace(0.0, L, 61)
    rows = JointPathRows(s, *delta_path_rows(arm.delta, s, pts))
    lim = arm.delta.limits
    t = time_rows(rows, lim.velocity, lim.acceleration, lim.torque, sd_end=0.2)
    assert t.duration == pytest.approx(platform_move_time(arm, box, pre, d, 0.2, True, 0.0, 60), rel=1e-12)
    p, dp, _ = pts(t.s)
    sd = t.sd
    theta = inverse_position(arm.delta.geometry, p)
    qdot = np.array([np.linalg.solve(platform_jacobian(arm.delta.geometry, th), v) for th, v in
                     zip(theta, dp * sd[:, None])])
    assert np.abs(qdot).max() <= lim.velocity * (1 + 1e-6)
    assert np.allclose(dp[-1] * sd[-1], [0.2, 0.0, 0.0], atol=1e-6)  # moving with the belt at the rendezvous
    assert np.allclose(forward_position(arm.delta.geometry, theta[-1]), pre, atol=1e-9)


def test_tracking_too_fast_is_infeasible_with_a_remedy(line):
    st = line.stations[0]
    spec = TrackingSpec(descend=0.01)
    with pytest.raises(InfeasibleProblem, match="descend"):
        delta_pick_times(st, line.belt, spec, 1.2, 0.0, mass=ENOKI.mass, item_height=ENOKI.size[2], n=8)


def test_line_one_delta_misses_two_do_not(line, small_map):
    maps = {st.name: (small_map,) for st in line.stations}
    two = run_line(line, maps=maps)
    one = replace(line, stations=line.stations[:1])
    single = run_line(one, maps={"delta 1": (small_map,)})
    assert two.figures.miss_rate < single.figures.miss_rate
    assert single.figures.miss_rate > 0.01 and two.status == "ok"
    sat = run_line(replace(one, stream=Stream("regular", 4.0, 60.0, types=(ENOKI,)), seeds=(0,)),
                   maps={"delta 1": (small_map,)})
    assert 45.0 < sat.figures.picks_per_minute < 75.0  # about one pick a second


def test_demo_rows_scara_or_delta():
    """The demo's rows: deltas needed beside the SCARAs' figures, one delta saturated (a coarse map, short runs)."""
    from pinarms.studies.delta_line import delta_rows

    scara = {"arms": 7, "picks_per_min": 59.8, "miss_rate": 0.0049}
    rows = delta_rows(scara, 60.0, item=ENOKI, seeds=(0, 1), duration=120.0, map_grid=(5, 3), faster=())
    need, sat = rows
    assert need.unit == "arms" and need.pinarms == 2 and "7 SCARAs" in need.note and "0.2 m/s" in need.note
    assert sat.unit == "picks/min" and 45.0 < sat.pinarms < 75.0


def test_map_error_against_exact_timing(line, small_map):
    """Interpolated (du, w, yaw) against exact timing at random points, items at random yaw (a 5 x 3 map)."""
    from pinarms.optim.line.delta_maps import delta_map_error

    err = delta_map_error(small_map, line.stations[0], line.belt, line.tracking, n=6, item_height=ENOKI.size[2],
                          grid=12)
    assert err.relative.size == 6 and np.ptp(err.yaws) > 0.5
    assert err.max < 0.02, err.relative
