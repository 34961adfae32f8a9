"""Placing in trays on a second moving belt, checked from FK of the planned joints."""

import numpy as np
import pytest

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.tracking import TrackingSpec
from pinarms.optim.line.tracking import PickRequest
from pinarms.optim.line.trays import TrayBelt, TrayPickRequest, plan_pick_to_tray
from pinarms.errors import InvalidInput


def _tool(station, q):
    T = station.robot.fk(q)
    return T[..., :3, 3] @ station.base_to_world[:3, :3].T + station.base_to_world[:3, 3]


def _velocity(station, q, qd):
    J = station.robot.jacobian(q)[:, :3, :]
    return np.einsum("nij,nj->ni", J, qd) @ station.base_to_world[:3, :3].T


@pytest.mark.parametrize("direction", [(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0)])
def test_place_in_a_moving_tray_from_fk(scara_line, direction):
    belt, station = scara_line
    tray_belt = Belt((0.0 if direction[0] > 0 else 3.0, 0.52, 0.82), direction=direction, speed=0.1, width=0.2,
                     length=3.0)
    trays = TrayBelt(tray_belt, pitch=0.3, w=0.0, height=0.02)
    u_place = 0.9 if direction[0] > 0 else 2.1  # world x 0.9 either way, beside the arm
    spec = TrackingSpec()
    plan = plan_pick_to_tray(TrayPickRequest(PickRequest(station, belt, spec, 1.05, -0.05, mass=0.1, yaw=0.4), trays,
            u_place))
    traj = plan.trajectory
    assert plan.duration == pytest.approx(traj.end_time - traj.start_time, abs=1e-6)
    # the pick is still a rendezvous with the item
    g = np.linspace(*plan.grasp_window, 101)
    q, qd = traj.sample(g)[:2]
    item = belt.to_world(1.05 + belt.speed * (g - plan.times[0]), -0.05, 0.04)
    assert np.max(np.linalg.norm(_tool(station, q) - item, axis=1)) < 1e-3
    # the place: tool at the tray's place point and moving with the tray over the whole release dwell
    r = np.linspace(*plan.release_window, 101)
    q, qd = traj.sample(r)[:2]
    t_place = sum(plan.times[:3])  # the pre-place rendezvous
    target = tray_belt.to_world(u_place + tray_belt.speed * (r - t_place), trays.w, trays.height)
    assert np.max(np.linalg.norm(_tool(station, q) - target, axis=1)) < 1e-3
    rel = np.linalg.norm(_velocity(station, q, qd) - tray_belt.velocity, axis=1)
    assert np.max(rel) < 0.01 * tray_belt.speed
    # ends at rest at home, within the joint limits
    assert np.allclose(traj.sample(np.array([traj.end_time]))[1], 0.0, atol=1e-9)
    assert np.all(traj.peaks().velocity <= station.limits["vmax"] * (1 + 1e-6))


def test_tray_belt_input():
    b = Belt((0.0, 0.5, 0.8), speed=0.1, width=0.2)
    assert TrayBelt(b, pitch=0.3, phase=0.1).tray_u(2, 1.0) == pytest.approx(0.1 - 0.6 + 0.1)
    for bad in (dict(pitch=0.0), dict(capacity=0), dict(w=0.2), dict(pitch=float("nan"))):
        with pytest.raises(InvalidInput):
            TrayBelt(b, **bad)


def test_place_hand_takes_the_short_turn_home():
    # the CLI's tray scene: beside w = 0.0625 m the nearest-solution IK put the place's hand a whole
    # turn away (q4 -3.40 against 2.88 rad, the same pose) and the return home took 1.12 s against
    # 0.34 s; now both points end within half a turn of home and return alike. (That place, 0.391 m
    # upstream, is now infeasible: its transfer takes joint 1 past its limit; 0.35 m is checked.)
    from pinarms.optim.line.tracking import rest_configuration
    from pinarms.optim.line.trays import _hand_turn, plan_pick_to_tray, trays_beside
    from pinarms.studies.line import scara_line

    spec = scara_line(1, 10.0)
    st, belt = spec.stations[0], spec.belt
    trays = trays_beside(belt, st.place.position, 0.3, 0.1, 2)
    u0 = float(belt.to_belt(st.base_to_world[:3, 3])[0])
    q_rest = rest_configuration(st)
    back, q4 = [], []
    for w in (0.0625, 0.125):
        p = plan_pick_to_tray(TrayPickRequest(PickRequest(st, belt, spec.tracking, u0 + 0.07, w, item_height=0.04,
                mass=0.1, q_rest=q_rest), trays, u0 - 0.35, place_branch=0))
        back.append(p.times[4])
        q4.append(p.pieces[3].sample(np.array([p.pieces[3].end_time]))[0][0, 3])
    assert back[1] == pytest.approx(back[0], rel=0.05)
    assert max(abs(x - q_rest[3]) for x in q4) <= np.pi
    # a 2π step inside a segment is unwrapped, and the turn stays within the joint's limits
    q = np.tile(q_rest, (5, 1))
    q[:, 3] = [3.0, 3.1, 3.2 - 2 * np.pi, 3.3 - 2 * np.pi, 3.4 - 2 * np.pi]
    out = _hand_turn(st, q, q_rest, q_rest)
    assert np.max(np.abs(np.diff(out[:, 3]))) < 0.2
    assert np.allclose(out[:, 3], [3.0, 3.1, 3.2, 3.3, 3.4])
    assert np.array_equal(out[:, :3], q[:, :3])


def test_place_time_has_no_jump_where_the_hand_turn_switches():
    # the CLI's tray scene at du 0.038, w -0.02 m: between dv 0.19 and 0.21 m the hand's shorter
    # travel switches a whole turn (q4 4.42 -> -1.75 rad); taking it alone, transfer + return
    # jumped 1.883 -> 1.792 s; with both turns planned and the faster kept the time is continuous
    from pinarms.optim.line.tracking import rest_configuration
    from pinarms.optim.line.trays import plan_pick_to_tray, trays_beside
    from pinarms.studies.line import scara_line

    spec = scara_line(1, 10.0)
    st, belt = spec.stations[0], spec.belt
    trays = trays_beside(belt, st.place.position, 0.3, 0.1, 2)
    u0 = float(belt.to_belt(st.base_to_world[:3, 3])[0])
    q_rest = rest_configuration(st)
    t = [sum(plan_pick_to_tray(TrayPickRequest(PickRequest(st, belt, spec.tracking, u0 + 0.038, -0.02,
            item_height=0.04, mass=0.1, q_rest=q_rest), trays, u0 + dv, place_branch=0)).times[2::2]) for dv in (0.19,
            0.2, 0.21)]
    assert abs(t[1] - t[0]) < 0.03 and abs(t[2] - t[1]) < 0.03


def test_a_tray_place_whose_transfer_leaves_the_joint_limits_is_infeasible():
    # the CLI's tray scene, place 0.391 m upstream: the transfer's cubic Hermite swings joint 1 to
    # 2.517 rad against its 2.443 rad limit (found at the trajectory's exact extrema); no clamping
    from pinarms.optim.line.tracking import PositionLimitError, rest_configuration
    from pinarms.optim.line.trays import plan_pick_to_tray, trays_beside
    from pinarms.studies.line import scara_line

    spec = scara_line(1, 10.0)
    st, belt = spec.stations[0], spec.belt
    trays = trays_beside(belt, st.place.position, 0.3, 0.1, 2)
    u0 = float(belt.to_belt(st.base_to_world[:3, 3])[0])
    with pytest.raises(PositionLimitError, match=r"transfer to the tray takes joint 1 .* outside its position limits"):
        plan_pick_to_tray(TrayPickRequest(PickRequest(st, belt, spec.tracking, u0 + 0.07, 0.0625, item_height=0.04,
                mass=0.1, q_rest=rest_configuration(st)), trays, u0 - 0.391, place_branch=0))
    ok = plan_pick_to_tray(TrayPickRequest(PickRequest(st, belt, spec.tracking, u0 + 0.07, 0.0625, item_height=0.04,
            mass=0.1, q_rest=rest_configuration(st)), trays, u0 - 0.35, place_branch=0))
    t = np.linspace(ok.pieces[2].start_time, ok.pieces[2].end_time, 2001)
    q = ok.pieces[2].sample(t)[0]
    assert np.all(q >= st.robot.lower - 1e-9) and np.all(q <= st.robot.upper + 1e-9)
