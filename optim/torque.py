"""Joint-torque limits in segment timing: the keywords, and the checks that no timing can meet.

The torque-limit object is :class:`pinarms.planning.JointTorqueConstraint` (one class for segment
timing and path timing; its docstring gives the scaling law ``tau(s) = (tau_1 - g) / s² + g``
and the grid). :data:`TorqueConstraint` is that class under its former name here.
:func:`torque_constraint` builds it from ``minimize_time``/``plan_cycle`` keywords (limits
checked as :class:`InvalidLimits`), :func:`static_check` and :func:`path_static_check` refuse
via points and paths the arm cannot even hold still (``|g(q)| > L``): any slower timing is
feasible as long as the arm can hold every sample still, and where it cannot, no timing
exists (:class:`InfeasibleProblem` names the joint and the instant).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.optim.errors import InvalidLimits, InvalidSettings
from pinarms.optim.ga.problem import check_limit, path_static_check, static_check
from pinarms.planning.torque import JointTorqueConstraint

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot
    from pinarms.robots.payload import Payload

__all__ = ["TorqueConstraint", "torque_constraint", "static_check", "path_static_check"]

#: The former name of :class:`pinarms.planning.JointTorqueConstraint` in segment timing.
TorqueConstraint = JointTorqueConstraint


def torque_constraint(robot: Robot, torque_limits: ArrayLike, payload: Payload | None = None,
                      samples_per_piece: int | None = None) -> JointTorqueConstraint | None:
    """The :class:`pinarms.planning.JointTorqueConstraint` asked for by ``minimize_time``/``plan_cycle`` keywords, or None.

    Args:
        robot: the arm (required when torque limits are asked for).
        torque_limits: ``False``/``None`` (no torque limits), ``True`` (the URDF's joint
            ``effort`` limits, ``robot.effort_limit``) or limits per joint [N·m or N].
        payload: ``None``, a mass [kg], a :class:`pinarms.robots.Payload` or its dict form; the
            robot carries it (``robot.with_payload``).

    Raises:
        InvalidSettings: torque limits without a robot, or a payload without torque limits
            (a payload changes only torques).
        InvalidLimits: ``True`` but the URDF has no effort limit for some joint.
    """
    if torque_limits is None or torque_limits is False:
        if payload is not None:
            raise InvalidSettings("a payload changes only the torques: pass torque_limits=True (or limits) with it")
        return None
    if robot is None:
        raise InvalidSettings("torque limits need the robot whose inverse dynamics give the torques: pass robot=arm")
    if payload is not None:
        robot = robot.with_payload(payload)
    if torque_limits is True:
        effort = np.asarray(robot.effort_limit, dtype=float)
        missing = [n for n, e in zip(robot.joint_names, effort) if not e > 0.0]
        if missing:
            raise InvalidLimits(f"robot '{robot.name}' has no effort limit for joint(s) {missing} in its URDF: "
                                "pass torque_limits=[...] (N·m or N per joint; on the command line --torque-max)")
        torque_limits = effort
    if not hasattr(robot, "inverse_dynamics"):
        raise InvalidSettings(f"robot must be a robots.Robot, got {type(robot).__name__}")
    limit = check_limit(torque_limits, int(robot.nq), "torque limit [N·m or N]", required=True)
    return JointTorqueConstraint(robot, limit, samples_per_piece=samples_per_piece)
