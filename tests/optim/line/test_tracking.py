"""Conveyor tracking checked from FK of the planned joint trajectory (independent of the planner)."""

import re

import numpy as np
import pytest

from pinarms import robots
from pinarms.optim.errors import InfeasibleProblem
from pinarms.optim.line.belt import Belt, PlaceBox
from pinarms.optim.line.station import Station, base_pose
from pinarms.optim.line.tracking import TrackingSpec, can_yaw, plan_pick, tool_yaw
from pinarms.errors import InvalidInput


def _tool_world(station, q):
    T = station.robot.fk(q)
    p = T[..., :3, 3] @ station.base_to_world[:3, :3].T + station.base_to_world[:3, 3]
    return p


def _check_rendezvous(station, belt, spec, u_pre, w, height, yaw=0.0):
    plan = plan_pick(station, belt, spec, u_pre, w, item_height=height, mass=0.1, yaw=yaw)
    traj = plan.trajectory
    t_a = plan.times[0]
    g0, g1 = plan.grasp_window
    t = np.linspace(g0, g1, 201)
    q, qd = traj.sample(t)[:2]
    p = _tool_world(station, q)
    item = belt.to_world(u_pre + belt.speed * (t - t_a), w, height)  # the item's grasp point
    assert np.max(np.linalg.norm(p - item, axis=1)) < 1e-3  # tool at the item (< 1 mm) while grasping
    J = station.robot.jacobian(q)[:, :3, :]  # linear part, base frame
    v = np.einsum("nij,nj->ni", J, qd) @ station.base_to_world[:3, :3].T
    rel = np.linalg.norm(v - belt.velocity, axis=1)
    assert np.max(rel) < 0.01 * belt.speed  # moving with the belt (< 1 % of its speed) over the whole dwell
    # the pick ends at rest at the box, the whole trajectory within the joint limits
    qe, qde = traj.sample(traj.end_time)[:2]
    assert np.allclose(qde, 0.0, atol=1e-9)
    assert np.all(traj.peaks().velocity <= station.limits["vmax"] * (1 + 1e-6))
    assert np.all(traj.peaks().acceleration <= station.limits["amax"] * (1 + 1e-6))
    # the approach ends moving as the tracking segment starts: the velocity step is at most the
    # time-optimal timing's dilation (TOPP-RA's dense-check slack, rtol 1e-3 / 2 of the speed)
    qa = plan.approach.trajectory.sample(plan.approach.trajectory.end_time)[1]
    qt = plan.tracking.sample(0.0)[1]
    assert np.max(np.abs(qa - qt)) <= 6e-4 * np.max(np.abs(qt))
    return plan


def test_scara_rendezvous_from_fk(scara_line):
    belt, station = scara_line
    plan = _check_rendezvous(station, belt, TrackingSpec(), 1.05, -0.05, 0.04)
    assert plan.duration == pytest.approx(sum(plan.times))
    assert 0.5 < plan.times[0] < 3.0


def test_gantry_rendezvous_from_fk():
    belt = Belt(origin=(0.0, 0.2, 0.70), speed=0.3, width=0.3, length=2.0)
    station = Station("gantry", robots.load("gantry_flower"), base_pose(0.0, 0.0, 0.65), PlaceBox((0.3, 0.5, 0.90)))
    _check_rendezvous(station, belt, TrackingSpec(), 0.5, 0.05, 0.05)


def _hand_angle(station, q):
    """Tool's x axis angle about the vertical in the world [rad]."""
    R = station.base_to_world[:3, :3] @ station.robot.fk(q)[..., :3, :3]
    return np.arctan2(R[..., 1, 0], R[..., 0, 0])


def test_scara_hand_matches_the_item_yaw_from_fk(scara_line):
    belt, station = scara_line
    spec = TrackingSpec()
    ref = plan_pick(station, belt, spec, 1.05, -0.05, item_height=0.04, mass=0.1)
    a0 = _hand_angle(station, ref.trajectory.sample(np.array([ref.grasp_window[0]]))[0])[0]
    for yaw in (0.6, -1.2, 2.9):  # 2.9 rad: a two-finger gripper takes it at 2.9 - π
        plan = _check_rendezvous(station, belt, spec, 1.05, -0.05, 0.04, yaw=yaw)
        t = np.linspace(*plan.grasp_window, 51)
        turn = _hand_angle(station, plan.trajectory.sample(t)[0]) - a0
        want = (yaw + np.pi / 2) % np.pi - np.pi / 2
        assert tool_yaw(station, spec, yaw) == pytest.approx(want)
        assert np.max(np.abs((turn - want + np.pi) % (2 * np.pi) - np.pi)) < 1e-6  # over the whole dwell


def test_item_yaw_is_a_zero_separable_term_of_the_task_time(scara_line):
    """The map has no yaw coordinate: the hand joint's turn never limits the move. Approach and
    leave are scaled by the joints that move the tool point, so the hand only adds its own
    coordinate to the path; at joint-4 limits of 6 rad/s and 60 rad/s² it never binds: the task
    time is the same at every yaw (to the timing's tolerance), at points on both elbows."""
    belt, station = scara_line
    for u, w, branch in ((1.05, -0.05, None), (0.93, 0.03, 1), (1.2, 0.1, 0)):
        base = plan_pick(station, belt, TrackingSpec(), u, w, mass=0.15, branch=branch).duration
        for yaw in (-np.pi / 2, -0.8, 0.7, np.pi / 2 - 1e-3):
            t = plan_pick(station, belt, TrackingSpec(), u, w, mass=0.15, branch=branch, yaw=yaw).duration
            assert t == pytest.approx(base, rel=1e-3)


def test_gantry_cannot_turn_its_tool():
    station = Station("gantry", robots.load("gantry_flower"), base_pose(0.0, 0.0, 0.65), PlaceBox((0.3, 0.5, 0.90)))
    assert not can_yaw(station.robot) and tool_yaw(station, TrackingSpec(), 1.0) == 0.0
    with pytest.raises(InvalidInput, match="yaw_period"):
        TrackingSpec(yaw_period=0.0)


def _sampled_out_of_limits(robot, traj, dt=1e-3):
    """Largest excursion [rad or m] of the trajectory sampled every ``dt`` s past the position limits."""
    q = np.asarray(traj.sample(np.arange(traj.start_time, traj.end_time, dt))[0])
    return float(np.max(np.maximum(robot.lower - q, q - robot.upper)))


def test_a_pick_beyond_the_position_limits_is_infeasible_and_the_other_branch_is_taken():
    """``mushroom_line``'s left SCARA, pre-grasp point 0.125 m off the belt's centre line at its base:
    on IK branch 0 the approach swings joint 1 past its -140° limit (found by sampling the planned
    trajectory every 1 ms); that branch is infeasible and the default plan is branch 1, within limits."""
    from pinarms.optim.errors import InfeasibleProblem
    from pinarms.optim.line.tracking import PositionLimitError
    from pinarms.robots.cell import load_cell

    cell = load_cell("mushroom_line")
    belt = Belt((-1.0, 0.0, 0.80), speed=0.1, width=0.30, length=2.0)
    st = Station("left", cell.arm("left").robot, cell.arm("left").base_to_world, PlaceBox((0.22, 0.68, 0.93), "box"))
    robot = st.robot
    with pytest.raises(PositionLimitError, match=r"approach move takes joint 1 .*outside its position limits"):
        plan_pick(st, belt, TrackingSpec(), 1.0, 0.125, item_height=0.04, mass=0.15, branch=0)
    assert issubclass(PositionLimitError, InfeasibleProblem)  # the maps' NaN node, as any infeasible pick
    plan = plan_pick(st, belt, TrackingSpec(), 1.0, 0.125, item_height=0.04, mass=0.15)
    assert _sampled_out_of_limits(robot, plan.trajectory) <= 1e-9
    assert plan.approach.trajectory.sample(plan.times[0])[0][1] < 0.0  # elbow the other way (branch 1)


def test_belt_too_fast_says_which_descend_fixes_it():
    """Joint 3 (the SCARA's vertical axis) slowed to 2 m/s²: the default 0.2 s descend needs about 4.3;
    the message names the figures and the descend that fixes it, and that descend plans."""
    belt = Belt(origin=(0.0, 0.0, 0.80), speed=0.2, width=0.3, length=3.0)
    station = Station("scara 1", robots.load("scara_mushroom"), base_pose(1.0, 0.30, 0.78),
                      PlaceBox((0.8, 0.45, 0.93)), amax=[30.0, 30.0, 2.0, 60.0])
    with pytest.raises(InfeasibleProblem) as info:
        plan_pick(station, belt, TrackingSpec(), 1.05, -0.05, item_height=0.04)
    text = str(info.value)
    m = re.search(r"joint 3 \(\w+\) at ([\d.]+) m/s² against its limit 2 m/s².*descend \(TrackingSpec.descend, "
                  r"now 0.2 s\) to ([\d.]+) s.*--speed.*0.2 m/s", text)
    assert m, text
    assert 4.0 < float(m.group(1)) < 4.7
    descend = float(m.group(2))
    assert 0.25 < descend < 0.4
    plan = plan_pick(station, belt, TrackingSpec(descend=descend), 1.05, -0.05, item_height=0.04)
    assert plan.tracking.peaks().acceleration[2] <= 2.0 * (1 + 1e-9)


@pytest.mark.slow
def test_a_continuous_wrist_stays_on_one_turn_through_the_tracking_segment():
    """The Kinova Jaco2 (example-robot-data; joints 1, 4, 6 continuous): its numeric IK returns each
    continuous angle in (-π, π], so a wrist near ±π jumped a whole turn between two samples of the
    tracking segment (joint 6 at 1.31e4 rad/s², the pick infeasible). Each sample now takes the turn
    nearest the previous one: the tracking segment is smooth and within the limits."""
    from pinarms.robots.registry import example_robot_data_share

    share = example_robot_data_share()
    jaco = robots.from_urdf(share / "robots" / "kinova_description" / "robots" / "kinova.urdf",
                            tcp="j2s6s200_end_effector", package_dirs=(str(share.parent),))
    belt = Belt((0.0, 0.0, 0.80), speed=0.1, width=0.3, length=2.0)
    station = Station("jaco", jaco, base_pose(1.0, 0.40, 0.80), PlaceBox((0.9, 0.65, 0.95), "box"))
    plan = plan_pick(station, belt, TrackingSpec(descend=0.6), 1.0, 0.05, item_height=0.04, mass=0.1)
    q = plan.tracking.sample(np.linspace(0.0, plan.tracking.duration, 200))[0]
    assert np.abs(np.diff(q, axis=0)).max() < 0.1  # no jump of a turn between two samples
    assert np.all(plan.tracking.peaks().acceleration <= station.limits["amax"] * (1 + 1e-9))
