"""The pick-and-place cycle (optim.cycle): waypoints, IK branch, limits, cycle time, errors."""

from __future__ import annotations

import re

import numpy as np
import pytest

from pinarms import robots
from pinarms.optim.cycle import (LINE_NAMES, CycleApproach, CycleLoad, CycleRequest, CycleStatus, CycleTiming, PickPlace,
                                 plan_cycle)
from pinarms.optim.errors import InvalidLimits
from pinarms.planning import JointLimits
from pinarms.errors import InvalidInput, UnreachableTarget

# pick / place points inside each arm's working region (base frame, m)
POINTS = {
    "scara_mushroom": ([0.30, 0.25, 0.10], [-0.20, 0.35, 0.08]),
    "aubo_i3": ([0.35, 0.20, 0.15], [-0.10, 0.40, 0.10]),
}


@pytest.fixture(scope="module", params=sorted(POINTS))
def planned(request):
    arm = robots.load(request.param)
    pick, place = POINTS[request.param]
    spec = PickPlace(pick, place, lift=0.05, dwell=0.2)
    limits = {"vmax": arm.velocity_limit, "amax": 4.0 * arm.velocity_limit, "jmax": 40.0 * arm.velocity_limit}
    return arm, spec, limits, plan_cycle(CycleRequest(arm, spec, timing=CycleTiming(**limits)))


def test_waypoints_are_the_cycle_and_met_by_fk_of_the_joint_via_points(planned):
    arm, spec, _, res = planned
    assert res.names == ("pick", "above pick", "above place", "place", "above place", "above pick", "pick")
    P = res.waypoints[:, :3, 3]
    np.testing.assert_allclose(P[0], spec.pick, atol=1e-12)
    np.testing.assert_allclose(P[3], spec.place, atol=1e-12)
    np.testing.assert_allclose(P[1] - P[0], [0.0, 0.0, 0.05], atol=1e-12)
    np.testing.assert_allclose(P[2] - P[3], [0.0, 0.0, 0.05], atol=1e-12)
    T = arm.fk(res.q_via)
    np.testing.assert_allclose(T, res.waypoints, atol=1e-9)
    assert np.all(arm.within_limits(res.q_via))
    # the trajectory passes the via points at the knots and closes the cycle
    q0, qd0 = res.trajectory.sample(res.trajectory.start_time)[:2]
    q1, qd1 = res.trajectory.sample(res.trajectory.end_time)[:2]
    np.testing.assert_allclose(q0, res.q_via[0], atol=1e-12)
    np.testing.assert_allclose(q1, res.q_via[0], atol=1e-12)
    assert np.abs(qd0).max() < 1e-12 and np.abs(qd1).max() < 1e-12


def test_all_waypoints_on_one_ik_branch(planned):
    arm, _, _, res = planned
    labels = []
    for pose, q in zip(res.waypoints, res.q_via):
        sols, branch = arm.ik_branches(pose, q_ref=q)
        k = int(np.argmin(np.linalg.norm(sols - q, axis=1)))
        assert np.linalg.norm(sols[k] - q) < 1e-9
        labels.append(int(branch[k]))
    assert len(set(labels)) == 1, labels
    assert res.one_branch and res.branches.tolist() == labels


def test_timing_respects_the_limits_by_dense_sampling(planned):
    _, spec, limits, res = planned
    traj = res.trajectory
    t = np.linspace(traj.start_time, traj.end_time, 40_001)
    _, qd, qdd, qddd = traj.sample(t)
    for values, name in ((qd, "vmax"), (qdd, "amax"), (qddd, "jmax")):
        assert np.all(np.abs(values).max(axis=0) <= limits[name] * (1 + 1e-6)), name
    # time-optimal: some limit is reached (within the sampling step) in each move
    ratios = np.concatenate([np.abs(qd).max(axis=0) / limits["vmax"], np.abs(qdd).max(axis=0) / limits["amax"],
                             np.abs(qddd).max(axis=0) / limits["jmax"]])
    assert ratios.max() > 0.99
    # at rest at pick and place: the dwells are holds
    for t0 in (0.0, res.moves[0].total + spec.dwell):
        hold = traj.sample(np.linspace(t0, t0 + spec.dwell, 11))
        assert np.ptp(hold[0], axis=0).max() == 0.0 and np.abs(hold[1]).max() == 0.0


def test_cycle_time_is_the_moves_plus_the_dwells_and_picks_per_minute(planned):
    _, spec, _, res = planned
    assert res.cycle_time == pytest.approx(res.moves[0].total + res.moves[1].total + 2 * spec.dwell, rel=1e-12)
    assert res.trajectory.duration == pytest.approx(res.cycle_time, rel=1e-12)
    assert res.picks_per_minute == pytest.approx(60.0 / res.cycle_time, rel=1e-12)
    np.testing.assert_allclose(res.move_times, [m.total for m in res.moves])


def test_straightness_is_measured_on_the_vertical_segments(planned):
    arm, _, _, res = planned
    assert res.line_deviation.shape == (len(LINE_NAMES),)
    # independent: distance from the vertical line through pick while lifting (first move, first segment)
    move = res.moves[0]
    t = np.linspace(res.spec.dwell, res.spec.dwell + move.durations[0], 501)
    p = arm.position(res.trajectory(t))
    pick = res.waypoints[0, :3, 3]
    horizontal = np.linalg.norm(p[:, :2] - pick[:2], axis=1).max()
    assert res.line_deviation[0] == pytest.approx(horizontal, rel=1e-2, abs=1e-9)
    if arm.name == "scara_mushroom":
        assert res.max_line_deviation < 1e-9  # the vertical axis alone moves
    else:
        assert 1e-5 < res.max_line_deviation < 0.05  # joint-space moves bow on a six-axis arm


@pytest.mark.parametrize("name", sorted(POINTS))
def test_doubling_vmax_halves_a_velocity_limited_cycle(name):
    arm = robots.load(name)
    spec = PickPlace(*POINTS[name], lift=0.05, dwell=0.0)
    slow = plan_cycle(CycleRequest(arm, spec, timing=CycleTiming(vmax=0.5 * arm.velocity_limit)))
    fast = plan_cycle(CycleRequest(arm, spec, timing=CycleTiming(vmax=arm.velocity_limit)))
    assert fast.cycle_time == pytest.approx(slow.cycle_time / 2, rel=1e-6)
    assert fast.limit_ratios["velocity"].max() == pytest.approx(1.0, abs=1e-6)


def test_transfer_vias_and_the_gantry_path():
    from pinarms.scenarios import GANTRY_PATH_AXIS_M

    arm = robots.load("gantry_flower")
    P = arm.position(GANTRY_PATH_AXIS_M)
    spec = PickPlace(P[0], P[-1], lift=0.10, dwell=0.1, via=list(P[2:-2]))
    res = plan_cycle(CycleRequest(arm, spec, timing=CycleTiming(amax=15.0, jmax=200.0)))
    assert res.names[:3] == ("pick", "above pick", "via 1") and len(res.names) == 2 * len(P) - 1
    np.testing.assert_allclose(res.q_via[: len(P)], GANTRY_PATH_AXIS_M, atol=1e-12)
    np.testing.assert_allclose(res.q_via[len(P) - 1:], GANTRY_PATH_AXIS_M[::-1], atol=1e-12)
    assert res.max_line_deviation < 1e-9  # Cartesian axes: the multi-quintic keeps x, y still while lifting


def test_an_unreachable_place_is_a_status_naming_it():
    arm = robots.load("aubo_i3")
    res = plan_cycle(CycleRequest(arm, PickPlace([0.35, 0.2, 0.15], [1.5, 0.0, 0.2])))
    assert res.status is CycleStatus.UNREACHABLE and not res.solved and res.trajectory is None
    assert re.search(r"the place point \[1\.5, 0\.0, 0\.2\] m .*out of reach", res.reason)
    assert res.as_dict() == {"status": "unreachable", "reason": res.reason, "robot": "aubo_i3"}
    with pytest.raises(UnreachableTarget, match="the place point"):  # asked for a cycle: the failure raised
        res.raise_for_status()
    scara = robots.load("scara_mushroom")
    res = plan_cycle(CycleRequest(scara, PickPlace(POINTS["scara_mushroom"][0], [-0.2, 0.35, 0.17])))
    assert res.status is CycleStatus.UNREACHABLE and "the above place point" in res.reason  # the lift leaves J3


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"lift": 0.0}, "lift"),
        ({"lift": -0.05}, "lift"),
        ({"lift": float("nan")}, "lift"),
        ({"dwell": -0.1}, "dwell"),
        ({"dwell": float("inf")}, "dwell"),
        ({"pick": [0.3, float("nan"), 0.1]}, "pick holds NaN"),
        ({"place": [0.3, 0.1]}, "place must be a position"),
        ({"via": [[0.1, 0.2]]}, "via point 1"),
        ({"orientation": np.diag([1.0, 1.0, -1.0])}, "orientation"),
    ],
)
def test_bad_spec_raises_invalid_input(kwargs, match):
    args = {"pick": [0.3, 0.25, 0.1], "place": [-0.2, 0.35, 0.08], **kwargs}
    with pytest.raises(InvalidInput, match=match):
        PickPlace(**args)


@pytest.mark.parametrize("limits", [{"vmax": 0.0}, {"vmax": [1.0, 1.0, -1.0, 1.0]}, {"amax": 0.0},
                                    {"jmax": float("nan")}, {"vmax": [1.0, 2.0]}])
def test_bad_limits_raise_invalid_limits(limits):
    arm = robots.load("scara_mushroom")
    with pytest.raises(InvalidLimits):
        plan_cycle(CycleRequest(arm, PickPlace(*POINTS["scara_mushroom"]), timing=CycleTiming(**limits)))


def test_bad_arguments():
    arm = robots.load("scara_mushroom")
    spec = PickPlace(*POINTS["scara_mushroom"], via=[[0.1, 0.35, 0.15]])
    with pytest.raises(InvalidInput, match="3-5-3"):
        plan_cycle(CycleRequest(arm, spec, timing=CycleTiming(kind="3-5-3")))
    with pytest.raises(InvalidInput, match="kind"):
        plan_cycle(CycleRequest(arm, spec, timing=CycleTiming(kind="cubic")))
    with pytest.raises(InvalidInput, match="PickPlace"):
        plan_cycle(CycleRequest(arm, {"pick": [0.3, 0.25, 0.1]}))


# ------------------------------------------------------------------ straight approach and retreat
@pytest.fixture(scope="module")
def straight_aubo():
    arm = robots.load("aubo_i3")
    pick, place = POINTS["aubo_i3"]
    spec = PickPlace(pick, place, lift=0.05, dwell=0.2)
    return arm, plan_cycle(CycleRequest(arm, spec, timing=CycleTiming(amax=2.0 * arm.velocity_limit),
                                        approach=CycleApproach(approach="straight", tool_speed=0.5)))


def test_straight_approach_keeps_the_tcp_on_the_vertical_lines(straight_aubo):
    arm, res = straight_aubo
    assert res.approach == "straight"
    assert res.max_line_deviation < 1e-4  # within the Cartesian path's 0.1 mm tolerance
    joint = plan_cycle(CycleRequest(arm, res.spec, timing=CycleTiming(amax=res.amax)))
    assert joint.max_line_deviation > 1e-3  # the joint-space lift bows by more than 1 mm on this arm
    assert res.joint_cycle_time == pytest.approx(joint.cycle_time, rel=1e-12)
    assert res.straight_cost == pytest.approx(res.cycle_time - joint.cycle_time)
    assert 0.0 <= res.line_cost < 0.01  # a 5 cm lift costs almost nothing over a joint-space line


def test_straight_cycle_is_one_feasible_closed_trajectory(straight_aubo):
    arm, res = straight_aubo
    assert res.trajectory.check(JointLimits(res.vmax, res.amax)).ok
    assert res.trajectory.duration == pytest.approx(res.cycle_time, rel=1e-12)
    q_end = res.trajectory(res.trajectory.end_time)
    assert np.abs(q_end - res.q_via[0]).max() < 1e-8  # back at the pick configuration
    for move in res.moves:
        assert move.total == pytest.approx(move.trajectory.duration, rel=1e-12)
        for line in move.lines:
            t = np.linspace(0.0, line.duration, 401)
            assert line.tool_speed(t)[0].max() <= 0.5 * (1 + 1e-6)  # carrying food
    assert res.as_dict()["approach"] == "straight"


def test_straight_approach_needs_an_acceleration_limit():
    arm = robots.load("scara_mushroom")
    with pytest.raises(InvalidLimits, match="amax"):
        plan_cycle(CycleRequest(arm, PickPlace(*POINTS["scara_mushroom"]), approach=CycleApproach(approach="straight")))
    with pytest.raises(InvalidInput, match="approach"):
        plan_cycle(CycleRequest(arm, PickPlace(*POINTS["scara_mushroom"]), approach=CycleApproach(approach="diagonal")))


@pytest.mark.slow
def test_straight_approach_with_a_payload_under_torque_limits():
    from pinarms import optim, planning

    arm = robots.load("scara_mushroom")
    spec = PickPlace(*POINTS["scara_mushroom"], lift=0.04, dwell=0.1)
    amax = 20.0 * arm.velocity_limit
    res = plan_cycle(CycleRequest(arm, spec, timing=CycleTiming(amax=amax),
                                  load=CycleLoad(payload=0.5, torque_limits=True),
                                  approach=CycleApproach(approach="straight")))
    assert res.payload is not None and res.torque_limit is not None
    ratios = res.torque_ratios
    assert ratios.max() <= 1.0 + 1e-6  # refined torque peaks of both moves, lines included
    assert ratios.max() > 0.99  # the torques limit this cycle
    lift_loaded, lift_empty = res.moves[0].lines[0], res.moves[1].lines[1]
    assert lift_loaded.ratios["joint torque"] <= 1.0 + 1e-6
    kinematic = optim.time_optimal(lift_loaded.path, [planning.JointVelocityConstraint(res.vmax),
                                                      planning.JointAccelerationConstraint(res.amax)])
    assert lift_loaded.duration > kinematic.duration * 1.01  # the loaded lift is torque-limited
    assert lift_empty.duration < lift_loaded.duration  # the empty gripper lowers to the pick faster
