"""Joint-limit rules of the numerical IK (robots/ik/limit_rules.py): full-turn joints shifted, continuous ones wrapped."""

from __future__ import annotations

import numpy as np

from pinarms import robots
from pinarms.robots.ik import NumericalIK


def test_full_turn_joints_are_shifted_by_two_pi_not_clipped():
    """UR5 joints span ±2π: a projected descent started at the upper limits still converges."""
    ur5 = robots.load("ur5")
    solver = NumericalIK(ur5)
    assert solver.full_turn.all()
    assert not NumericalIK(robots.load("aubo_i3")).full_turn.any()  # ±170°: clipped
    T = ur5.fk(ur5.random_q(40, seed=31))
    solved = 0
    for Tk in T:
        q, pe, re, _ = solver.attempt(ur5.upper.copy(), Tk, False, 1e-10)
        assert ur5.within_limits(q, tol=0.0)
        solved += pe <= 1e-10 and re <= 1e-10
    assert solved >= 28  # 32 of 40 (2 of 40 when the joints are clipped instead)


_CONTINUOUS_ARM = """<?xml version="1.0"?>
<robot name="yaw_pitch_pitch">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="tool"/>
  <joint name="yaw" type="continuous"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/></joint>
  <joint name="shoulder" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><limit lower="-2.5" upper="2.5" effort="1" velocity="1"/></joint>
  <joint name="tool_joint" type="fixed"><parent link="l3"/><child link="tool"/><origin xyz="0.3 0 0"/></joint>
</robot>
"""


def test_continuous_joint_is_wrapped_to_one_turn():
    arm3 = robots.from_urdf_text(_CONTINUOUS_ARM, tcp="tool", name="yaw_pitch_pitch")
    solver = NumericalIK(arm3)
    assert solver.unbounded.tolist() == [True, False, False]
    q_true = arm3.random_q(20, seed=2)
    starts = arm3.random_q(20, seed=3)
    starts[:, 0] += 40.0  # many turns away: the yaw is wrapped, not clipped
    for q, s in zip(q_true, starts):
        p = arm3.position(q)
        res = solver.solve(np.block([[np.eye(3), p[:, None]], [np.zeros((1, 3)), 1.0]]), s, position_only=True)
        assert res.success and np.linalg.norm(arm3.position(res.q) - p) <= 1e-10
        assert -np.pi <= res.q[0] <= np.pi and arm3.within_limits(res.q, tol=0.0)
