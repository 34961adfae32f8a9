"""A delta's pick as a motion of its actuated angles: the same times as the task map's, the platform on the
belt while tracking, the tool turned to the item's yaw and back, the motors within their limits."""

import numpy as np
import pytest

from pinarms.optim.line.delta_motion import delta_pick_motion, delta_rest
from pinarms.optim.standard_cycle.delta_cycle import turn_angle
from pinarms.optim.line.delta_tracking import delta_pick_times, tool_turn_time
from pinarms.robots.delta import forward_position
from pinarms.studies.delta_line import delta_line
from pinarms.studies.line import ENOKI

YAW = 1.55  # rad (just under the two-finger gripper's pi/2): the tool's turn outlasts the platform's approach


@pytest.fixture(scope="module")
def case():
    line = delta_line(1, 60.0, item=ENOKI, seeds=(0,), duration=30.0)
    st = line.stations[0]
    u = float(st.base_to_world[0, 3]) - 0.25
    motion = delta_pick_motion(st, line.belt, line.tracking, u, 0.05, mass=ENOKI.mass, item_height=ENOKI.size[2],
                               yaw=YAW, hz=500.0)
    return line, st, u, motion


def test_turn_angle_is_the_shortest_turn():
    for angle, v, a in ((0.5, 20.0, 200.0), (3.0, 20.0, 200.0), (-1.0, 5.0, 100.0)):
        total = tool_turn_time(angle, v, a)
        tau = np.linspace(0.0, total, 2001)
        x = turn_angle(angle, v, a, tau)
        assert x[0] == 0.0 and x[-1] == pytest.approx(angle, abs=1e-12)
        speed = np.diff(x) / np.diff(tau)
        assert np.abs(speed).max() <= v * (1 + 1e-9) and np.abs(np.diff(speed) / np.diff(tau)[1:]).max() <= a * 1.01
        assert turn_angle(angle, v, a, np.array([2 * total]))[0] == pytest.approx(angle)


def test_motion_times_are_the_pick_times(case):
    line, st, u, m = case
    a, c = delta_pick_times(st, line.belt, line.tracking, u, 0.05, mass=ENOKI.mass, item_height=ENOKI.size[2])
    turn = tool_turn_time(YAW, st.robot.velocity_limit[-1], st.robot.acceleration_limit[-1])
    assert turn > a  # the tool sets the approach here: the platform waits at the box first
    assert m.times == pytest.approx((max(a, turn), line.tracking.track_time, max(c, turn), line.tracking.release),
                                    abs=1e-12)
    # starts and ends at rest above the box, the tool at 0
    np.testing.assert_allclose(m.actuated[0], delta_rest(st), atol=1e-12)
    np.testing.assert_allclose(m.actuated[-1], delta_rest(st), atol=1e-9)


def test_platform_tracks_the_belt_and_motors_keep_their_limits(case):
    line, st, u, m = case
    geom, lim = st.robot.delta.geometry, st.robot.delta.limits
    p = forward_position(geom, m.actuated[:, :3])  # base frame (the base is not turned)
    t0, t1 = m.times[0], m.times[0] + m.times[1]
    on = (m.t >= t0) & (m.t <= t1)
    # while tracking, the platform moves with the belt along it (the vertical quintic aside)
    along = np.diff(p[on, 0]) / np.diff(m.t[on])
    assert along == pytest.approx(line.belt.speed, abs=1e-6)
    # the pre-grasp point at the start of tracking: lift above the item, at (u, w) on the belt
    tcp0 = p[on][0] + st.robot.tcp_offset + st.base_to_world[:3, 3]
    want = line.belt.to_world(u, 0.05, ENOKI.size[2] + line.tracking.lift)
    np.testing.assert_allclose(tcp0, want, atol=1e-9)
    # the tool holds the item's yaw while tracking
    np.testing.assert_allclose(m.actuated[on, 3], YAW, atol=1e-12)
    # the motors within their range and speed (finite differences at 500 Hz; the profile is time-optimal,
    # so some speed or acceleration reaches its limit: allow 2 % for the differences)
    th = m.actuated[:, :3]
    assert th.min() >= lim.lower - 1e-9 and th.max() <= lim.upper + 1e-9
    speed = np.abs(np.diff(th, axis=0) / np.diff(m.t)[:, None])
    assert speed.max() <= 1.02 * lim.velocity
