"""The standard pick cycle of a serial arm (a :class:`pinarms.robots.Robot`), time-optimal under its
joint speed, acceleration and torque limits with the payload.

The tcp keeps the orientation it has at ``q_ref`` (a SCARA's tool keeps its yaw in the world:
its fourth joint turns against the first two). Joint values come from the arm's closed-form IK,
on the branch nearest ``q_ref`` and then nearest the previous point; their path derivatives from
central differences; torques from the arm's RNEA with the payload at the tcp.
"""

from __future__ import annotations

from typing import Any, TYPE_CHECKING

import numpy as np

from pinarms.optim.errors import InfeasibleProblem

from pinarms.optim.standard_cycle.path import StandardCycle, gate_breaks, gate_length, gate_points
from pinarms.optim.standard_cycle.timing import GateTiming, JointPathRows, time_rows

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot

__all__ = ["serial_gate_rows", "serial_standard_cycle"]

_H = 1e-4   # step of the central differences along the path [m]


def _joint_path(robot: Any, rotation: np.ndarray, points: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
    """IK of every point (the tcp at ``rotation``), each on the branch nearest the previous solution."""
    out, prev = np.empty((len(points), robot.nq)), q_ref
    pose = np.eye(4)
    pose[:3, :3] = rotation
    for k, p in enumerate(points):
        pose[:3, 3] = p
        candidates = np.atleast_2d(robot.ik_all(pose, q_ref=prev))
        if candidates.size == 0:
            raise InfeasibleProblem(f"{robot.name}: the cycle's point {p.tolist()} m is out of reach")
        prev = candidates[np.argmin(np.linalg.norm(candidates - prev, axis=1))]
        out[k] = prev
    return out


def serial_gate_rows(robot: Robot, cycle: StandardCycle, q_ref, n: int = 400) -> JointPathRows:
    """The rows of the gate for a serial arm (about ``n`` grid intervals)."""
    arm = robot.with_payload(cycle.payload) if cycle.payload > 0 else robot
    q_ref = np.asarray(q_ref, dtype=float)
    rotation = arm.fk(q_ref)[:3, :3]
    s = np.union1d(np.linspace(0.0, gate_length(cycle), n + 1), gate_breaks(cycle))
    rows = []
    for side in ("left", "right"):
        q = {}
        for k in (0, -1, 1):
            q[k] = _joint_path(arm, rotation, gate_points(cycle, s + k * _H, side=side)[0], q_ref if k == 0 else q[0][0])
        dq, ddq = (q[1] - q[-1]) / (2 * _H), (q[1] - 2 * q[0] + q[-1]) / _H ** 2
        zero = np.zeros_like(dq)
        c = np.atleast_2d(arm.inverse_dynamics(q[0], zero, zero))
        ta = np.atleast_2d(arm.inverse_dynamics(q[0], zero, dq)) - c
        tb = np.atleast_2d(arm.inverse_dynamics(q[0], dq, ddq)) - c
        rows.append((dq, ddq, ta, tb, c))
    (dl, ddl, al, bl, cl), (dr, ddr, ar, br, cr) = rows
    return JointPathRows(s, np.hstack([dl, dr]), np.hstack([ddl, ddr]), np.hstack([al, ar]), np.hstack([bl, br]),
                         np.hstack([cl, cr]))


def serial_standard_cycle(robot: Robot, cycle: StandardCycle, q_ref, n: int = 400) -> GateTiming:
    """Time-optimal one-way move of the gate (rest to rest) under the arm's ``velocity_limit``,
    ``acceleration_limit`` and the URDF's effort limits; the cycle takes twice its ``duration``."""
    rows = serial_gate_rows(robot, cycle, q_ref, n)
    effort = np.asarray(robot.model.effortLimit, dtype=float)
    twice = lambda v: np.concatenate([v, v])  # noqa: E731  (left and right rows)
    return time_rows(rows, twice(robot.velocity_limit), twice(robot.acceleration_limit), twice(effort))
