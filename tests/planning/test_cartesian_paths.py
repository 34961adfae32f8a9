"""Cartesian waypoints -> joint via points (IK, consistent branch) and TCP paths (batched FK)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.planning.errors import TrajectoryError
from pinarms.errors import UnreachableTarget


class PlanarArm:
    """Planar 2R arm in the x-y plane (SCARA-like, links 0.25 m and 0.20 m), numpy only."""

    nq = 2
    L1, L2 = 0.25, 0.20
    lower = np.array([-np.pi, -2.8])
    upper = np.array([np.pi, 2.8])

    def __init__(self, analytic: bool = True) -> None:
        self.has_analytic_ik = analytic
        self.ik_calls = 0

    def fk(self, q, frame="tcp"):
        q = np.atleast_2d(np.asarray(q, dtype=float))
        a, b = q[:, 0], q[:, 0] + q[:, 1]
        T = np.tile(np.eye(4), (q.shape[0], 1, 1))
        T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = np.cos(b), -np.sin(b), np.sin(b), np.cos(b)
        T[:, 0, 3] = self.L1 * np.cos(a) + self.L2 * np.cos(b)
        T[:, 1, 3] = self.L1 * np.sin(a) + self.L2 * np.sin(b)
        return T

    def ik_all(self, pose, q_ref=None):
        x, y = pose[0, 3], pose[1, 3]
        c2 = (x * x + y * y - self.L1**2 - self.L2**2) / (2 * self.L1 * self.L2)
        if abs(c2) > 1:
            return np.zeros((0, 2))
        sols = []
        for s2 in (np.sqrt(1 - c2 * c2), -np.sqrt(1 - c2 * c2)):
            q2 = np.arctan2(s2, c2)
            q1 = np.arctan2(y, x) - np.arctan2(self.L2 * s2, self.L1 + self.L2 * c2)
            q = np.array([(q1 + np.pi) % (2 * np.pi) - np.pi, q2])
            if np.all(q >= self.lower) and np.all(q <= self.upper):
                sols.append(q)
        return np.array(sols).reshape(-1, 2)

    def ik(self, pose, q_seed=None):
        self.ik_calls += 1
        q = np.array([0.3, 0.5]) if q_seed is None else np.array(q_seed, dtype=float)
        target = pose[:2, 3]
        for _ in range(50):
            T = self.fk(q)[0]
            err = target - T[:2, 3]
            if np.linalg.norm(err) < 1e-13:
                return q
            a, b = q[0], q[0] + q[1]
            J = np.array(
                [[-self.L1 * np.sin(a) - self.L2 * np.sin(b), -self.L2 * np.sin(b)],
                 [self.L1 * np.cos(a) + self.L2 * np.cos(b), self.L2 * np.cos(b)]]
            )
            q = q + np.linalg.lstsq(J, err, rcond=None)[0]
        raise UnreachableTarget(f"no convergence for {target.tolist()}")


def line_poses(n=5):
    arm = PlanarArm()
    x = np.linspace(0.30, 0.15, n)
    y = np.linspace(-0.10, 0.25, n)
    poses = np.tile(np.eye(4), (n, 1, 1))
    poses[:, 0, 3], poses[:, 1, 3] = x, y
    return arm, poses


@pytest.mark.parametrize("elbow_sign", [1.0, -1.0])
def test_waypoints_keep_the_branch_of_q_start(elbow_sign):
    arm, poses = line_poses()
    q_start = np.array([0.0, elbow_sign * 1.0])
    q = planning.joint_waypoints(arm, poses, q_start=q_start)
    assert np.all(np.sign(q[:, 1]) == elbow_sign)
    np.testing.assert_allclose(arm.fk(q)[:, :2, 3], poses[:, :2, 3], atol=1e-12)


def test_joint_path_passes_the_waypoints_and_tcp_path_follows_it():
    arm, poses = line_poses()
    times = [0.0, 0.4, 0.9, 1.3, 2.0]
    traj = planning.joint_path_from_waypoints(arm, poses, times, q_start=[0.0, 1.0])
    assert traj.definition["kind"] == "multi_quintic"
    q_knots = traj.sample(times)[0]
    np.testing.assert_allclose(arm.fk(q_knots)[:, :2, 3], poses[:, :2, 3], atol=1e-12)
    t, p = planning.tcp_path(arm, traj, hz=100.0)
    assert p.shape == (t.size, 3) and t.size == 201
    np.testing.assert_allclose(p, arm.fk(traj.sample(t)[0])[:, :3, 3])
    np.testing.assert_allclose(p[[0, -1], :2], poses[[0, -1], :2, 3], atol=1e-12)
    bspline = planning.joint_path_from_waypoints(arm, poses, times, kind="quintic-bspline", q_start=[0.0, 1.0])
    assert bspline.definition["kind"] == "quintic_bspline"


def test_numerical_ik_is_seeded_with_the_previous_solution():
    arm, poses = line_poses()
    arm.has_analytic_ik = False
    q = planning.joint_waypoints(arm, poses, q_start=[0.0, -1.0])
    assert arm.ik_calls == len(poses)
    assert np.all(q[:, 1] < 0)  # the seed keeps the elbow-down branch here
    np.testing.assert_allclose(arm.fk(q)[:, :2, 3], poses[:, :2, 3], atol=1e-12)


def test_unreachable_waypoint_is_named():
    arm, poses = line_poses()
    poses[2, 0, 3] = 2.0
    with pytest.raises(UnreachableTarget, match="waypoint 2"):
        planning.joint_waypoints(arm, poses)


def test_bad_cartesian_input():
    arm, poses = line_poses()
    with pytest.raises(TrajectoryError, match="5 poses but 3 times"):
        planning.joint_path_from_waypoints(arm, poses, [0, 1, 2])
    with pytest.raises(TrajectoryError, match=r"\(N, 4, 4\)"):
        planning.joint_waypoints(arm, np.zeros((3, 3)))
    with pytest.raises(TrajectoryError, match="unknown trajectory kind"):
        planning.joint_path_from_waypoints(arm, poses, np.arange(5.0), kind="spline9")
    with pytest.raises(TrajectoryError, match="unknown trajectory kind None"):
        planning.joint_path_from_waypoints(arm, poses, np.arange(5.0), kind=None)
    traj3 = planning.multi_quintic([0, 1], np.zeros((2, 3)) + [[0, 0, 0], [1, 1, 1]])
    with pytest.raises(TrajectoryError, match="robot has nq = 2"):
        planning.tcp_path(arm, traj3, 10.0)


def test_tcp_path_on_a_built_in_robot():
    from pinarms import robots

    robot = robots.load("scara_mushroom")
    q = robot.random_q(2, seed=3)
    traj = planning.multi_quintic([0.0, 1.0], q)
    t, p = planning.tcp_path(robot, traj, hz=50.0)
    assert p.shape == (51, 3)
    np.testing.assert_allclose(p[[0, -1]], robot.fk(q)[:, :3, 3], atol=1e-12)
    np.testing.assert_allclose(p[25], robot.fk(traj.sample(t[25])[0])[:3, 3], atol=1e-12)


class LabelledPlanarArm(PlanarArm):
    """The planar arm with branch labels (0: elbow up, 1: elbow down), like robots.Robot.ik_branches."""

    def ik_branches(self, pose, q_ref=None):
        sols = self.ik_all(pose, q_ref)
        return sols, np.where(sols[:, 1] >= 0.0, 0, 1)


def test_labelled_branch_is_kept_even_when_another_branch_is_nearer():
    # near the stretched-out pose the other elbow can be nearer in joint space: at waypoint 2
    # the true (elbow-up) solution is 0.054 rad away from waypoint 1, the elbow-down one 0.046
    q_true = np.array([[0.2, 0.30], [0.2, 0.01], [0.15, 0.03], [0.15, 0.30]])
    poses = PlanarArm().fk(q_true)
    q = planning.joint_waypoints(LabelledPlanarArm(), poses, q_start=q_true[0])
    np.testing.assert_allclose(q, q_true, atol=1e-9)
    q_nearest = planning.joint_waypoints(PlanarArm(), poses, q_start=q_true[0])
    assert q_nearest[2, 1] < 0.0  # without labels the path flips the elbow


def test_aubo_table2_waypoints_keep_the_branch_until_the_limits_force_a_switch():
    from pinarms import robots
    from pinarms.robots import conventions as conv
    from pinarms import papers

    arm = robots.load("aubo_i3")
    q_paper = np.array([conv.aubo_mdh_to_joint(t) for t in papers.SEED001.table2_joints])
    labels = [int(arm.ik_branches(arm.fk(q), q_ref=q)[1][0]) for q in q_paper]
    # P1, P2 in one branch; P3, P4 in another, because P3's solution on the first branch needs
    # the shoulder at 175° (range ±170°)
    assert labels[0] == labels[1] and labels[2] == labels[3] and labels[1] != labels[2]
    _, geometric = arm._analytic_ik.candidates(arm.fk(q_paper[2])[None], respect_limits=False, with_branches=True)[1:]
    assert labels[0] in geometric  # the first branch exists geometrically at P3 ...
    sols, lab = arm.ik_branches(arm.fk(q_paper[2]))
    assert labels[0] not in lab  # ... but not within the joint limits
    q = planning.joint_waypoints(arm, arm.fk(q_paper), q_start=q_paper[0])
    np.testing.assert_allclose(q, q_paper, atol=1e-9)
