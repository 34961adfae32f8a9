"""Time-optimal path timing (reachability analysis written here) against dense re-checks and toppra."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import optim, robots
from pinarms.optim import InfeasibleProblem, time_optimal, toppra_path_duration
from pinarms.optim.topp import topp_profile
from pinarms.planning import (JointAccelerationConstraint, JointLimits, JointVelocityConstraint, PathRows,
                              PathSamples, ToolAccelerationConstraint, ToolSpeedConstraint, Trajectory,
                              cartesian_path, from_definition, joint_spline, tcp_speed)
from pinarms.robots.reach.layout import default_orientation


def pose(R, p):
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


@pytest.fixture(scope="module")
def lift(aubo):
    R = default_orientation(aubo)
    return cartesian_path(aubo, np.stack([pose(R, [0.35, 0.20, 0.0]), pose(R, [0.35, 0.20, 0.30])]))


@pytest.fixture(scope="module")
def limits(aubo):
    v = aubo.velocity_limit
    return v, 2.0 * v  # rad/s, rad/s² (the acceleration is this test's choice)


@pytest.fixture(scope="module")
def timed(lift, limits):
    v, a = limits
    return time_optimal(lift, [JointVelocityConstraint(v), JointAccelerationConstraint(a)])


def test_the_result_is_a_trajectory_feasible_when_rechecked_densely(timed, limits, lift):
    v, a = limits
    traj = timed.trajectory
    assert isinstance(traj, Trajectory) and traj.n_joints == 6
    assert traj.check(JointLimits(v, a)).ok  # exact peaks of every piece
    t = np.linspace(0.0, traj.duration, 20001)
    q, qd, qdd, _ = traj.sample(t)
    assert np.max(np.abs(qd) / v) <= 1.0 + 1e-9
    assert np.max(np.abs(qdd) / a) <= 1.0 + 1e-9
    assert np.max(np.abs(qdd) / a) > 0.999  # time-optimal: some joint at its acceleration limit
    assert np.abs(qd[[0, -1]]).max() < 1e-12  # at rest at both ends
    # q(t) is the path timed: q(t) = q(s(t)) exactly
    s, sd, _ = timed.state(t)
    assert np.abs(q - lift(s)).max() < 1e-12
    assert np.abs(qd - lift.sample(s)[1] * sd[:, None]).max() < 1e-9
    assert timed.dilation <= 1.0 + 1e-3


def test_within_one_percent_of_toppra_on_the_same_path(timed, limits, lift):
    v, a = limits
    same_grid = toppra_path_duration(lift, v, a, np.unique(timed.grid))
    assert timed.duration == pytest.approx(same_grid, rel=1e-3)
    dense = toppra_path_duration(lift, v, a, np.linspace(0.0, lift.length, 2001))
    assert timed.duration == pytest.approx(dense, rel=1e-2)
    assert timed.duration >= dense * (1.0 - 1e-3)  # ours is feasible: not faster than the converged optimum


def test_topp_profile_equals_toppra_profile_on_a_grid(lift, limits):
    v, a = limits
    grid = np.linspace(0.0, lift.length, 61)
    rows = PathRows.concatenate([c.rows(PathSamples.of(lift, grid)) for c in
                                 (JointVelocityConstraint(v), JointAccelerationConstraint(a))])
    prof = topp_profile(rows.a, rows.b, rows.lo, rows.hi, grid)
    assert prof.duration == pytest.approx(toppra_path_duration(lift, v, a, grid), rel=1e-6)
    coll = topp_profile(rows.a, rows.b, rows.lo, rows.hi, grid, scheme="collocation")
    assert coll.duration == pytest.approx(toppra_path_duration(lift, v, a, grid, discretization="collocation"),
                                          rel=1e-6)


def test_trapezoid_closed_form_on_a_straight_joint_path():
    path = joint_spline(np.array([[0.0, 0.0], [1.0, 0.5]]))  # CELL_NOTES: Δq = 1, 0.5 rad
    res = time_optimal(path, [JointVelocityConstraint(1.0), JointAccelerationConstraint(2.0)], grid=200)
    assert res.duration == pytest.approx(1.5, rel=5e-3)  # Δ/v + v/a
    assert res.duration >= 1.5 - 1e-9


def test_tool_speed_limit_while_carrying_food(aubo, lift, limits):
    v, a = limits
    res = time_optimal(lift, [JointVelocityConstraint(v), JointAccelerationConstraint(a), ToolSpeedConstraint(0.5)])
    t, lin, ang = tcp_speed(aubo, res.trajectory, 2000.0)
    assert lin.max() <= 0.5 * (1.0 + 1e-3)
    assert lin.max() > 0.49  # the limit is reached on a 0.3 m lift
    assert res.ratios["tool speed"] <= 1.0 + 1e-9
    assert res.duration == pytest.approx(toppra_path_duration(lift, v, a, np.unique(res.grid), tool_speed=0.5),
                                         rel=1e-3)
    assert np.abs(res.tool_speed(t[::50])[0] - lin[::50]).max() < 1e-6  # the result's own speed profile agrees


def test_tool_acceleration_limit(aubo, limits):
    v, a = limits
    ur5 = robots.load("ur5")
    R = default_orientation(ur5)
    path = cartesian_path(ur5, np.stack([pose(R, p) for p in ([0.4, 0.2, 0.1], [0.4, 0.2, 0.3], [0.2, 0.45, 0.3])]),
                          blend=0.05)
    res = time_optimal(path, [JointVelocityConstraint(ur5.velocity_limit), ToolAccelerationConstraint(2.0)])
    t = np.linspace(0.0, res.duration, 4001)
    q, qd, qdd, _ = res.trajectory.sample(t)
    J = ur5.jacobian(q)
    h = 1e-7
    dJ = (ur5.jacobian(q + h * qd) - ur5.jacobian(q - h * qd)) / (2 * h)
    acc = np.einsum("nij,nj->ni", J, qdd)[:, :3] + np.einsum("nij,nj->ni", dJ, qd)[:, :3]
    peak = np.linalg.norm(acc, axis=1).max()
    assert peak <= 2.0 * (1.0 + 2e-3)
    assert peak > 2.0 * np.cos(np.pi / 64) * 0.99  # the inscribed polygon loses at most 0.12 %


def test_a_stop_brings_the_arm_to_rest(aubo):
    R = default_orientation(aubo)
    path = cartesian_path(aubo, np.stack([pose(R, p) for p in ([0.35, 0.2, 0.05], [0.35, 0.2, 0.2], [0.2, 0.3, 0.2])]))
    assert path.stops.size == 1
    res = time_optimal(path, [JointVelocityConstraint(aubo.velocity_limit),
                              JointAccelerationConstraint(2 * aubo.velocity_limit)])
    t_stop = res.time_at(path.stops[0])[0]
    knots = res.trajectory.knot_times
    k = int(np.argmin(np.abs(knots - t_stop)))
    assert abs(knots[k] - t_stop) < 1e-6  # the sections join at the stop (ṡ = 0: s(t) is flat there)
    assert res.state(knots[k])[1][0] == 0.0
    assert np.abs(res.trajectory.sample(knots[k])[1]).max() < 1e-12


def test_jerk_limit_gives_a_smoothed_feasible_result(lift, limits, timed):
    v, a = limits
    cons = [JointVelocityConstraint(v), JointAccelerationConstraint(a)]
    res = time_optimal(lift, cons, jerk=60.0)
    assert res.smoothing > 0.0
    assert res.trajectory.check(JointLimits(v, a, 60.0)).ok  # exact peaks, jerk included
    assert res.trajectory.peaks().jerk.max() > 0.999 * 60.0 or res.trajectory.peaks().acceleration.max() > 0.999 * a[0]
    assert timed.duration < res.duration < 2.0 * timed.duration
    t = np.linspace(0.0, res.duration, 5001)
    s, sd, sdd = res.state(t)
    assert np.all(np.diff(s) >= 0.0) and sd[0] == 0.0 and abs(sd[-1]) < 1e-12
    assert np.abs(res.trajectory(t) - lift(s)).max() < 1e-12  # still the same path, exactly
    _, qd, qdd, _ = res.trajectory.sample(np.array([0.0, res.duration]))
    assert np.abs(qdd).max() < 1e-9  # smoothed: no acceleration step at the start and the end


def test_the_trajectory_goes_into_a_session_and_comes_back(timed, aubo, tmp_path):
    from pinarms import viz

    session = viz.Session(aubo, title="lift")
    session.add_trajectory("lift", timed.trajectory, hz=200.0)
    path = session.save(tmp_path / "lift.pinarms")
    back = viz.load_session(path).trajectories["lift"].rebuild()
    t = np.linspace(0.0, timed.duration, 101)
    assert np.abs(back(t) - timed.trajectory(t)).max() < 1e-12
    assert np.abs(from_definition(timed.trajectory.definition)(t) - timed.trajectory(t)).max() == 0.0


def test_infeasible_start_and_bad_arguments(lift, limits):
    v, a = limits
    cons = [JointVelocityConstraint(v), JointAccelerationConstraint(a)]
    with pytest.raises(InfeasibleProblem, match="start speed"):
        time_optimal(lift, cons, start_speed=50.0)
    with pytest.raises(optim.InvalidSettings, match="constraints"):
        time_optimal(lift, [])
    with pytest.raises(optim.InvalidSettings, match="grid"):
        time_optimal(lift, cons, grid=0)
