"""Cartesian helpers: waypoints (TCP poses) to joint via points by IK, and the TCP path of a trajectory.

These are the only functions of :mod:`pinarms.planning` that talk to a robot. They use only the
robot's public methods (duck typing, so any object with the same methods works):

* ``has_analytic_ik`` (bool) and ``ik_branches(pose, q_ref=...) -> (q (k, nq), branch (k,))``
  — every analytic solution within the joint limits with its branch label (shoulder, elbow,
  wrist flip): the solution on the previous waypoint's branch is kept (the nearest such
  one, in rad/m), so consecutive waypoints stay in one arm configuration even when another
  branch happens to be closer in joint space; only when that branch has no solution within
  the limits does the path switch to the nearest solution of another branch. (An object
  with ``ik_all(pose, q_ref=...)`` but no ``ik_branches`` gets the nearest solution.)
* otherwise ``ik(pose, q_seed=previous) -> (nq,)`` — numerical IK seeded with the
  previous solution (which usually keeps the branch, but cannot guarantee it);
* ``fk(q (N, nq), frame=...) -> (N, 4, 4)`` — batched forward kinematics.

Poses are homogeneous transforms of the TCP frame in the robot's base (world) frame, m.
"""

from __future__ import annotations

from typing import Any, Callable, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning import _inputs
from pinarms.planning.bspline import quintic_bspline
from pinarms.planning.errors import TrajectoryError
from pinarms.planning.multi_quintic import multi_quintic
from pinarms.planning.piecewise import piecewise_polynomial
from pinarms.planning.polynomial import polynomial
from pinarms.planning.trajectory import Trajectory
from pinarms.errors import UnreachableTarget
from pinarms.robots.ties import argmin_tied

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot

__all__ = ["joint_waypoints", "joint_path_from_waypoints", "tcp_path", "tcp_speed", "PATH_KINDS"]

PATH_KINDS: dict[str, Callable[..., Trajectory]] = {
    "multi-quintic": multi_quintic,
    "quintic-bspline": quintic_bspline,
    "piecewise-polynomial": piecewise_polynomial,
    "polynomial": polynomial,
}


def _poses(poses: Any) -> np.ndarray:
    P = _inputs.finite_array(poses, "poses")
    if P.ndim == 2 and P.shape == (4, 4):
        P = P[None]
    if P.ndim != 3 or P.shape[1:] != (4, 4):
        raise TrajectoryError(f"poses must be (N, 4, 4) homogeneous transforms (m), got shape {P.shape}")
    return P


def joint_waypoints(robot: Robot, poses: ArrayLike, q_start: ArrayLike | None = None) -> np.ndarray:
    """Joint configurations (N, nq) for TCP poses (N, 4, 4) on one IK branch, each nearest the previous one.

    The first pose's solution is the one nearest ``q_start`` when given; otherwise, with
    analytic IK, the first solution the robot returns, and with numerical IK the robot's
    default seed. With analytic IK the following poses keep the first pose's branch (see
    the module docstring).

    Raises:
        pinarms.errors.UnreachableTarget: naming the waypoint index that has no solution.
    """
    P = _poses(poses)
    nq = int(robot.nq)
    prev = None if q_start is None else _inputs.per_joint(q_start, nq, "q_start")
    analytic = bool(getattr(robot, "has_analytic_ik", False))
    labelled = analytic and hasattr(robot, "ik_branches")
    out = np.empty((P.shape[0], nq))
    branch = None
    for i, pose in enumerate(P):  # one IK per waypoint (a handful), not per sample
        try:
            if analytic:
                if labelled:
                    sols, labels = robot.ik_branches(pose, q_ref=prev)
                    sols = np.asarray(sols, dtype=float).reshape(-1, nq)
                else:
                    sols = np.asarray(robot.ik_all(pose, q_ref=prev), dtype=float).reshape(-1, nq)
                    labels = np.full(sols.shape[0], -1)
                if sols.shape[0] == 0:
                    raise UnreachableTarget("no analytic solution within the joint limits")
                same = np.flatnonzero(labels == branch) if branch is not None else np.arange(0)
                pool = same if same.size else np.arange(sols.shape[0])
                pick = pool[0] if prev is None else pool[argmin_tied(np.linalg.norm(sols[pool] - prev, axis=1))]
                q, branch = sols[pick], labels[pick]
            else:
                q = np.asarray(robot.ik(pose, q_seed=prev), dtype=float).reshape(nq)
        except UnreachableTarget as exc:
            raise UnreachableTarget(
                f"waypoint {i} (position {P[i, :3, 3].tolist()} m) is unreachable: {exc}; "
                "move it inside the workspace or relax the joint limits"
            ) from exc
        out[i] = q
        prev = q
    return out


def joint_path_from_waypoints(
    robot: Robot,
    poses: ArrayLike,
    times: ArrayLike,
    kind: str = "multi-quintic",
    q_start: ArrayLike | None = None,
    **options: Any,
) -> Trajectory:
    """Joint trajectory through TCP waypoints: IK per pose (:func:`joint_waypoints`), then ``kind``.

    Args:
        robot: a :class:`pinarms.robots.Robot` (or an object with the same IK/FK methods).
        poses: (N, 4, 4) TCP poses in the base frame (m).
        times: (N,) knot times (s), strictly increasing.
        kind: ``"multi-quintic"`` (default), ``"quintic-bspline"``, ``"piecewise-polynomial"``
            (give ``degrees=``) or ``"polynomial"`` (give ``degree=``).
        q_start: optional configuration (nq,) selecting the branch of the first waypoint.
        **options: passed on to the trajectory constructor.
    """
    key = kind.replace("_", "-") if isinstance(kind, str) else kind
    if key not in PATH_KINDS:
        raise TrajectoryError(f"unknown trajectory kind {kind!r}; choose one of {sorted(PATH_KINDS)}")
    P = _poses(poses)
    t = _inputs.knot_times(times)
    if t.size != P.shape[0]:
        raise TrajectoryError(f"{P.shape[0]} poses but {t.size} times; give one time per pose")
    q = joint_waypoints(robot, P, q_start)
    return PATH_KINDS[key](t, q, **options)


def tcp_path(robot: Robot, trajectory: Trajectory, hz: float, frame: str = "tcp") -> tuple[np.ndarray, np.ndarray]:
    """TCP positions along a trajectory sampled at ``hz``: ``(t (N,), positions (N, 3) in m)``, batched FK."""
    if trajectory.n_joints != int(robot.nq):
        raise TrajectoryError(
            f"the trajectory has {trajectory.n_joints} joints but the robot has nq = {robot.nq}"
        )
    t, q = trajectory.at_rate(hz)[:2]
    T = np.asarray(robot.fk(q, frame=frame))
    return t, T[:, :3, 3].copy()


def tcp_speed(robot: Robot, trajectory: Trajectory, hz: float, frame: str = "tcp") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """tcp speed along a trajectory sampled at ``hz``: ``(t (N,), linear (N,) [m/s], angular (N,) [rad/s])``.

    ``|J(q) q̇|`` per sample (batched Jacobian, base axes at the tcp): the Cartesian speed
    to plot beside the joint curves, or to check against a tool-speed limit.
    """
    if trajectory.n_joints != int(robot.nq):
        raise TrajectoryError(
            f"the trajectory has {trajectory.n_joints} joints but the robot has nq = {robot.nq}"
        )
    t, q, qd = trajectory.at_rate(hz)[:3]
    J = np.asarray(robot.jacobian(q, frame=frame))
    twist = np.einsum("nij,nj->ni", J, qd)
    return t, np.linalg.norm(twist[:, :3], axis=1), np.linalg.norm(twist[:, 3:], axis=1)
