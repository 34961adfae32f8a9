"""Conveyor tracking checked from FK of the planned joint trajectory (independent of the planner)."""

import numpy as np
import pytest

from pinarms import robots
from pinarms.optim.line.belt import Belt, PlaceBox
from pinarms.optim.line.station import Station, base_pose
from pinarms.optim.line.tracking import TrackingSpec, plan_pick


def _tool_world(station, q):
    T = station.robot.fk(q)
    p = T[..., :3, 3] @ station.base_to_world[:3, :3].T + station.base_to_world[:3, 3]
    return p


def _check_rendezvous(station, belt, spec, u_pre, w, height):
    plan = plan_pick(station, belt, spec, u_pre, w, item_height=height, mass=0.1)
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
