"""optim.plan_motion: collision-free moves in a cell (OMPL), proven continuously, timed optimally.

The cell of most tests is tests/optim/data/aubo_wall.urdf.xacro: the AUBO-i3 on a stand, a
table in front and a 2 cm wall across its reach. Clearances are re-checked by PyBullet on
the same primitives (its own kinematics and distances: tests/optim/motion_helpers.py).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from pinarms import robots
from pinarms.optim import (GoalInCollision, InfeasibleProblem, InvalidLimits, InvalidSettings, NoPathFound,
                           StartInCollision)
from pinarms.optim.motion import MotionChecker, MotionLimits, MotionOptions, MotionRequest, MotionStatus, plan_motion
from pinarms.optim.motion.goals import ik_candidates
from pinarms.optim.motion.scenes import Region, region_pose
from pinarms.robots.cell.motion import joint_levers
from pinarms.errors import InvalidInput, UnreachableTarget

from tests.optim.motion_helpers import BulletScene, dense_times

DATA = Path(__file__).parent / "data"
MARGIN = 0.01


@pytest.fixture(scope="module")
def wall():
    return robots.load_cell(DATA / "aubo_wall.urdf.xacro")


def _tool_down(cell, point, branch=0):
    arm = cell.arm("aubo")
    T = region_pose(Region("r", (0, 0, 0), (1, 1, 1)), point)
    q, _ = ik_candidates(arm.robot, arm.to_base(T), cell.neutral)
    return q[branch], T


@pytest.fixture(scope="module")
def across(wall):
    """Tool down 10 cm above the table on either side of the wall, same IK branch."""
    qa, _ = _tool_down(wall, [0.45, 0.2, 0.80])
    qb, Tb = _tool_down(wall, [0.45, -0.2, 0.80])
    return qa, qb, Tb


def _plan(cell, start, goal, **options):
    return plan_motion(MotionRequest(cell, "aubo", start, goal, options=MotionOptions(**options)))


@pytest.fixture(scope="module")
def planned(wall, across):
    qa, qb, _ = across
    return _plan(wall, qa, qb, margin=MARGIN, seed=0, time_limit=30.0)


def test_the_straight_move_hits_the_wall(wall, across):
    qa, qb, _ = across
    checker = MotionChecker(wall, ["aubo"], margin=MARGIN)
    assert checker.state_valid(qa) and checker.state_valid(qb)
    assert not checker.edge_valid(qa, qb).ok
    s = np.linspace(0.0, 1.0, 400)[:, None]
    c = wall.clearance(qa + s * (qb - qa))
    assert c.distance.min() < -0.03  # 3 cm deep into the wall
    assert {"wall"} & set(c.pair_of(int(np.argmin(c.distance))).bodies)


def test_planned_path_keeps_the_margin_under_an_independent_dense_check(wall, planned, across):
    qa, qb, _ = across
    traj = planned.trajectory
    np.testing.assert_allclose(traj.sample(traj.start_time)[0], qa, atol=1e-9)
    np.testing.assert_allclose(traj.sample(traj.end_time)[0], qb, atol=1e-9)
    t = dense_times(traj, joint_levers(wall), resolution=0.001)
    q = traj.sample(t)[0]
    bullet = BulletScene(wall, ["aubo"])
    try:
        d = np.empty(t.size)
        for i, qi in enumerate(q):
            bullet.set("aubo", qi)
            d[i] = bullet.distance("aubo")
    finally:
        bullet.close()
    assert t.size > 500
    # Bullet's cylinders are within 2e-5 m of the exact distance (tests/robots/test_cell.py)
    assert d.min() >= MARGIN - 2e-5, f"PyBullet: {d.min():.5f} m at t = {t[np.argmin(d)]:.4f} s"
    # the motion really goes round the wall (the straight line went 6 cm into it)
    assert d.min() < 0.1
    # pinarms' own report agrees with Bullet where the arm passes closest
    assert planned.clearance.min_environment >= MARGIN
    assert planned.clearance.min_environment == pytest.approx(d.min(), abs=2e-3)
    assert planned.check.collision_free


def test_plan_is_timed_within_the_limits_and_reports_its_steps(wall, planned):
    traj = planned.trajectory
    arm = wall.arm("aubo").robot
    peaks = traj.peaks()
    assert np.all(peaks.velocity <= arm.velocity_limit * (1 + 1e-9))
    tau = planned.timing.ratios.get("joint torque", 0.0)
    acc = planned.timing.ratios.get("joint acceleration", 0.0)
    # the default acceleration limits (velocity limit / 0.25 s) bind before the torques here: the time-optimal
    # profile rides them; the torques stay within theirs
    assert planned.limits["amax_source"] == "default: velocity limit / 0.25 s"
    assert 0.99 < acc <= 1.0 + 1e-3 and 0.0 < tau <= 1.0 + 1e-3
    assert np.all(peaks.acceleration <= arm.acceleration_limit * (1 + 1e-6))
    assert planned.smoothing in ("cubic spline", "straight line", "polyline with stops")
    assert planned.path_length <= planned.raw_length + 1e-9
    d = planned.as_dict()
    assert d["planner"] == "RRTConnect" and d["collision_free"]
    assert set(d["seconds"]) >= {"search", "shortcut", "smooth", "time", "check", "total"}
    assert planned.states >= 2


def test_same_seed_same_path_and_seed_matters(wall, across, planned):
    qa, qb, _ = across
    again = _plan(wall, qa, qb, margin=MARGIN, seed=0, time_limit=30.0)
    np.testing.assert_array_equal(again.raw_path, planned.raw_path)
    np.testing.assert_array_equal(again.simplified, planned.simplified)
    assert again.duration == planned.duration
    others = [_plan(wall, qa, qb, margin=MARGIN, seed=s, time_limit=30.0).raw_path for s in (1, 2)]
    assert any(p.shape != planned.raw_path.shape or not np.array_equal(p, planned.raw_path) for p in others)


def test_pose_goal_every_branch_tried(wall, across):
    qa, _, Tb = across
    plan = _plan(wall, qa, Tb, margin=MARGIN, seed=0, time_limit=30.0)
    assert plan.status is MotionStatus.SOLVED and plan.ok and plan.reason == ""
    arm = wall.arm("aubo")
    assert len(plan.goals) >= 2
    assert sum(g.valid for g in plan.goals) >= 1
    np.testing.assert_allclose(arm.tcp_to_world(plan.trajectory.sample(plan.trajectory.end_time)[0]), Tb, atol=1e-8)


def test_goal_inside_a_fixture_is_refused_at_once_with_the_fixture(wall, across):
    qa, _, _ = across
    T = region_pose(Region("r", (0, 0, 0), (1, 1, 1)), [0.45, 0.0, 0.80])  # inside the wall
    t0 = time.perf_counter()
    plan = _plan(wall, qa, T, margin=MARGIN)
    assert time.perf_counter() - t0 < 0.1
    assert plan.status is MotionStatus.GOAL_IN_COLLISION and "wall" in plan.reason and plan.which == "goal"
    assert plan.pairs == (("tcp", "wall"),) and plan.distances[0] < 0.0 and plan.configurations is None
    assert plan.goal is None and plan.as_dict()["status"] == "goal in collision"
    with pytest.raises(GoalInCollision, match="wall") as err:
        plan.raise_for_status()
    assert err.value.which == "goal"


def test_goal_configuration_in_collision_names_the_pair(wall, across):
    qa, qb, _ = across
    s = np.linspace(0.0, 1.0, 400)[:, None]
    line = qa + s * (qb - qa)
    deepest = line[int(np.argmin(wall.clearance(line).distance))]
    t0 = time.perf_counter()
    plan = _plan(wall, qa, deepest, margin=MARGIN)
    assert time.perf_counter() - t0 < 0.1
    assert plan.status is MotionStatus.GOAL_IN_COLLISION and "wall" in plan.pairs[0] and plan.distances[0] < 0.0
    np.testing.assert_array_equal(plan.configurations, deepest[None])  # the joint values in collision
    with pytest.raises(GoalInCollision, match=r"wall.*overlap by"):
        plan.duration  # a plan not solved has no motion: its properties say why
    back = _plan(wall, deepest, qa, margin=MARGIN)
    assert back.status is MotionStatus.START_IN_COLLISION and back.which == "start" and "wall" in back.pairs[0]
    np.testing.assert_array_equal(back.configurations, deepest[None])
    with pytest.raises(StartInCollision, match="wall"):
        back.raise_for_status()


def test_every_ik_branch_in_collision_lists_each_reason(wall, across):
    qa, _, _ = across
    # just above the wall's top edge: the tcp is clear, every arm configuration reaching it is not
    T = region_pose(Region("r", (0, 0, 0), (1, 1, 1)), [0.45, 0.0, 1.06])
    plan = _plan(wall, qa, T, margin=MARGIN)
    assert plan.status is MotionStatus.GOAL_IN_COLLISION and plan.reason.startswith("every IK solution")
    assert len(plan.pairs) >= 2 and all("wall" in p for p in plan.pairs)
    # each branch with its joint values (rad, 4 digits): branches that read alike are told apart
    arm = wall.arm("aubo")
    q, labels = ik_candidates(arm.robot, arm.to_base(T), qa, seed=0)
    np.testing.assert_array_equal(plan.configurations, q)  # every branch's joint values, in the plan
    text = plan.reason
    for qi, b in zip(q, labels):
        values = ", ".join(f"{v:.4g}" for v in qi)
        assert f"branch {b} (q = [{values}] rad)" in text, (b, values, text)


def test_no_path_within_the_time_limit_is_a_status(wall, across):
    qa, qb, _ = across
    plan = _plan(wall, qa, qb, margin=MARGIN, time_limit=1e-6)
    assert plan.status is MotionStatus.NO_PATH and not plan.ok
    assert plan.planner == "RRTConnect" and plan.states >= 1 and plan.seconds["search"] >= 0.0
    np.testing.assert_array_equal(plan.goal, qb)
    with pytest.raises(NoPathFound, match=r"RRTConnect found no collision-free path in 1e-06 s \(\d+ states") as err:
        plan.raise_for_status()
    assert err.value.planner == "RRTConnect" and err.value.states == plan.states


def test_bad_arguments(wall, across):
    qa, qb, _ = across
    with pytest.raises(InvalidInput, match="no arm"):
        MotionRequest(wall, "nope", qa, qb)
    with pytest.raises(InvalidInput, match="6 finite joint"):
        MotionRequest(wall, "aubo", qa[:5], qb)
    with pytest.raises(InvalidInput, match="margin must be > 0"):
        MotionOptions(margin=0.0)
    with pytest.raises(InvalidInput, match="outside the joint limits"):  # bad input stays an exception
        plan_motion(MotionRequest(wall, "aubo", qa + np.array([10.0, 0, 0, 0, 0, 0]), qb))
    with pytest.raises(InvalidSettings, match="unknown planner"):
        MotionOptions(planner="astar")
    with pytest.raises(InvalidLimits, match="vmax must be one positive number or 6"):
        MotionRequest(wall, "aubo", qa, qb, limits=MotionLimits(vmax=[1.0, 2.0]))
    with pytest.raises(InvalidInput, match="options must be a MotionOptions"):
        MotionRequest(wall, "aubo", qa, qb, options={"margin": 0.01})
    with pytest.raises(InvalidInput, match="plan_motion takes one MotionRequest"):
        plan_motion(wall)


def test_an_unreachable_pose_goal_is_a_status_found_before_any_search(wall, across):
    qa, _, _ = across
    T = region_pose(Region("r", (0, 0, 0), (1, 1, 1)), [3.0, 0.0, 0.80])  # 3 m away: beyond the arm's reach
    plan = _plan(wall, qa, T, margin=MARGIN)
    assert plan.status is MotionStatus.GOAL_UNREACHABLE and plan.states == 0 and "unreachable" in plan.reason
    assert plan.as_dict()["status"] == "goal unreachable" and plan.as_dict()["goal"] is None
    with pytest.raises(UnreachableTarget, match="unreachable for arm 'aubo'"):
        plan.raise_for_status()


def test_a_path_that_cannot_be_timed_under_the_limits_is_a_status(wall, across):
    """Torque limits far below what holds the arm against gravity: the path is found, its timing is not."""
    qa, qb, _ = across
    request = MotionRequest(wall, "aubo", qa, qb, options=MotionOptions(margin=MARGIN, seed=0, time_limit=30.0),
                            limits=MotionLimits(amax=False, torque=1e-3))
    plan = plan_motion(request)
    assert plan.status is MotionStatus.LIMITS_NOT_MET and "cannot be timed under the limits" in plan.reason
    assert plan.trajectory is None and plan.seconds["total"] > 0.0
    with pytest.raises(InfeasibleProblem):
        plan.raise_for_status()
