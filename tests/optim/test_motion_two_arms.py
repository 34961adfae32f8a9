"""Two arms over one belt (planning scene aubo_two_belt): B around A's timed trajectory, or both together.

The right arm (A) runs a fixed move; the left arm (B) is planned. Clearances between the
arms are re-checked by PyBullet with both arms moving (its own kinematics and distances).
"""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.optim.motion import MotionChecker, MotionOptions, MotionRequest, load_scene
from pinarms.optim.motion.goals import ik_candidates
from pinarms.optim.motion.scenes import Region, region_pose
from pinarms.optim.motion import MotionStatus
from pinarms.optim.motion.two_arms import TwoArmRequest, plan_two_arms
from pinarms.robots.cell.motion import joint_levers

from tests.optim.motion_helpers import BulletScene, dense_times

MARGIN = 0.01
R = Region("r", (0, 0, 0), (1, 1, 1))


@pytest.fixture(scope="module")
def belt():
    return load_scene("aubo_two_belt")


def _ik(cell, arm, point, hold, q_ref=None):
    checker = MotionChecker(cell, [arm], margin=MARGIN, hold=hold)
    a = cell.arm(arm)
    q, _ = ik_candidates(a.robot, a.to_base(region_pose(R, np.asarray(point, dtype=float))),
                         cell.neutral[a.q_slice] if q_ref is None else q_ref)
    q = [x for x in q if checker.state_valid(x)]
    assert q, f"no clear IK solution for {arm} at {point}"
    return q[0] if q_ref is None else min(q, key=lambda x: np.abs(x - q_ref).max())


def _quintic(q0, q1, v, slack=1.2):
    T = float(np.max(1.875 * np.abs(q1 - q0) / v)) * slack
    return planning.polynomial([0.0, T], np.stack([q0, q1]), 5)


@pytest.fixture(scope="module")
def stations(belt):
    hold = belt.neutral.copy()
    qa0 = _ik(belt, "right", (0.0, -0.78, 0.84), hold)
    hold[belt.arm("right").q_slice] = qa0
    qb0 = _ik(belt, "left", (0.0, 0.78, 0.84), hold)
    hold[belt.arm("left").q_slice] = qb0
    return hold, qa0, qb0


def _bullet_min_arm_distance(cell, plan, t0, t1):
    """Smallest arm–arm distance (PyBullet) over [t0, t1], both arms playing, sampled so that each
    arm's fastest point moves at most 2 mm between samples (4 mm of approach: 40 % of the margin)."""
    levers = joint_levers(cell)
    bullet = BulletScene(cell, ["left", "right"])
    try:
        times = []
        for arm, traj in plan.trajectories.items():
            times.append(dense_times(traj, levers[cell.arm(arm).q_slice], resolution=0.002))
        t = np.unique(np.concatenate([np.clip(x - 0.0, t0, t1) for x in times] + [np.linspace(t0, t1, 500)]))
        q = {arm: traj.sample(np.clip(t - plan.offsets[arm] + traj.start_time, traj.start_time, traj.end_time))[0]
             for arm, traj in plan.trajectories.items()}
        d = np.empty(t.size)
        for i in range(t.size):
            for arm in q:
                bullet.set(arm, q[arm][i])
            d[i] = bullet.distance("left", "right")
        return t, d
    finally:
        bullet.close()


def test_b_waits_for_a_to_leave_the_shared_belt(belt, stations):
    hold, qa0, qb0 = stations
    vA = belt.arm("right").robot.velocity_limit
    qa1 = _ik(belt, "right", (0.0, 0.10, 0.84), hold)  # A reaches across the belt middle ...
    there = _quintic(qa0, qa1, vA)
    A = there.concatenated(_quintic(qa1, qa0, vA).shifted(there.duration))  # ... and goes back
    qb1 = _ik(belt, "left", (0.05, 0.10, 0.86), hold)  # B's goal: where A was
    request = MotionRequest(belt, "left", qb0, qb1, hold=hold, options=MotionOptions(seed=0, time_limit=20.0))
    plan = plan_two_arms(TwoArmRequest(request, "right", A))
    assert plan.status is MotionStatus.SOLVED and plan.method == "around"
    around = plan.around
    assert around.delay > 0.0  # B must wait for A
    # leaving one step earlier is proven unsafe (the delays are tried in order)
    assert around.delays_tried >= 1
    traj = plan.trajectories["left"]
    np.testing.assert_allclose(traj.sample(traj.end_time)[0], qb1, atol=1e-9)
    assert plan.check.collision_free
    t, d = _bullet_min_arm_distance(belt, plan, 0.0, max(A.duration, traj.end_time))
    assert d.min() >= MARGIN - 2e-5, f"PyBullet: arms {d.min():.5f} m apart at t = {t[np.argmin(d)]:.3f} s"
    # without the wait they would have touched: B played from t = 0 comes closer than the margin
    early = type(plan)(plan.method, plan.trajectories, {"left": 0.0, "right": 0.0}, None, None, (), None)
    moving_part = planning.Trajectory(traj.knot_times[1:] - traj.knot_times[1], traj.coefficients[1:])
    early.trajectories["left"] = moving_part
    t2, d2 = _bullet_min_arm_distance(belt, early, 0.0, max(A.duration, moving_part.end_time))
    assert d2.min() < MARGIN


def test_start_in_a_s_way_falls_back_to_both_arms_together(belt, stations):
    hold, qa0, qb0 = stations
    vA = belt.arm("right").robot.velocity_limit
    qas = _ik(belt, "right", (-0.20, 0.06, 0.84), hold)
    qae = _ik(belt, "right", (0.20, 0.06, 0.84), hold, q_ref=qas)
    A = _quintic(qas, qae, vA, slack=1.05)
    lead = 0.4  # A is this far (in time) from the middle of its sweep when B must leave
    offset = -(A.duration / 2 - lead)
    at_t0, at_mid, at_end = hold.copy(), hold.copy(), hold.copy()
    at_t0[belt.arm("right").q_slice] = A.sample(A.duration / 2 - lead)[0]
    at_end[belt.arm("right").q_slice] = qae
    clear_now = MotionChecker(belt, ["left"], margin=MARGIN, hold=at_t0)
    clear_end = MotionChecker(belt, ["left"], margin=MARGIN, hold=at_end)
    X = belt.arm("left").robot.random_q(20000, seed=5)
    ok_now = ~clear_now.batch_collides(clear_now.full(X))
    in_way = clear_end.batch_collides(clear_end.full(X))
    qbs = X[np.flatnonzero(ok_now & in_way)[0]]  # clear of A now, but where A ends
    request = MotionRequest(belt, "left", qbs, qb0, hold=hold, options=MotionOptions(seed=0, time_limit=20.0))
    plan = plan_two_arms(TwoArmRequest(request, "right", A, other_offset=offset))
    assert plan.status is MotionStatus.SOLVED and plan.method == "joint"
    # B alone around A: no start instant clears A's sweep, a status saying so (both together solved it)
    assert plan.around.status is MotionStatus.NO_PATH and plan.around.trajectory is None
    assert plan.attempts[0][0] == "around" and "plan both arms together" in plan.attempts[0][1]
    assert plan.joint.arms == ("right", "left")
    ta, tb = plan.trajectories["right"], plan.trajectories["left"]
    np.testing.assert_allclose(ta.sample(ta.start_time)[0], at_t0[belt.arm("right").q_slice], atol=1e-9)
    np.testing.assert_allclose(ta.sample(ta.end_time)[0], qae, atol=1e-9)
    np.testing.assert_allclose(tb.sample(tb.end_time)[0], qb0, atol=1e-9)
    # two arms planned together never come closer than the margin (PyBullet, dense)
    t, d = _bullet_min_arm_distance(belt, plan, ta.start_time, ta.end_time)
    assert d.min() >= MARGIN - 2e-5, f"PyBullet: arms {d.min():.5f} m apart at t = {t[np.argmin(d)]:.3f} s"
    assert plan.joint.clearance.min_environment >= MARGIN
