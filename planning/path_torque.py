"""Joint torque limits along a geometric path, as a path constraint (rows linear in (s̈, ṡ²)).

Along ``q(s)`` timed by ``s(t)``, with ``u = s̈`` and ``x = ṡ²``, inverse dynamics is

    ``τ = M(q) (q' u + q'' x) + C(q, q' ṡ) q' ṡ + g(q) = a u + b x + g``

with ``a = M(q) q'`` and ``b = M(q) q'' + C(q, q') q'`` (the Coriolis term is quadratic in
the speed). Three batched RNEA calls give them: ``g = RNEA(q, 0, 0)``,
``a = RNEA(q, 0, q') − g``, ``b = RNEA(q, q', q'') − g``. The limit ``|τ_j| ≤ τmax_j`` is
the row ``−τmax − g ≤ a u + b x ≤ τmax − g`` per joint: what :func:`optim.time_optimal`
reads (the same split TOPP-RA makes for its ``JointTorqueConstraint``).

The constraint can cover a block of the path's joints (``columns``): a path in the joint
space of two arms takes one constraint per arm, each with its own robot and limits.
Gravity is the robot's own (its base frame's −z unless its model says otherwise).

Units: N·m (N for prismatic joints).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pinarms.planning.errors import TrajectoryError
from pinarms.planning.path_constraints import PathConstraint, PathRows, PathSamples, _limit

__all__ = ["JointTorqueConstraint"]


@dataclass(frozen=True, eq=False)
class JointTorqueConstraint(PathConstraint):
    """``|τ_j| <= tau_max_j`` [N·m or N] along the path (module docstring).

    Attributes:
        robot: the :class:`robots.Robot` whose joints these are (with its payload).
        tau_max: torque limits, scalar or per joint (default the URDF's ``effort``).
        columns: which of the path's joints are the robot's, in its order (default all).
    """

    robot: Any
    tau_max: Any = None
    columns: Any = None
    name = "joint torque"

    def __post_init__(self) -> None:
        if not hasattr(self.robot, "inverse_dynamics"):
            raise TrajectoryError(f"robot must be a robots.Robot, got {type(self.robot).__name__}")
        n = int(self.robot.nq)
        limit = self.robot.effort_limit if self.tau_max is None else self.tau_max
        object.__setattr__(self, "tau_max", _limit(limit, n, "tau_max [N·m or N]"))
        cols = np.arange(n) if self.columns is None else np.asarray(self.columns, dtype=int).reshape(-1)
        if cols.size != n:
            raise TrajectoryError(f"columns must name the robot's {n} joints in the path, got {cols.tolist()}")
        object.__setattr__(self, "columns", cols)

    def rows(self, samples: PathSamples) -> PathRows:
        c = self.columns
        q, dq, ddq = samples.q[:, c], samples.dq[:, c], samples.ddq[:, c]
        zero = np.zeros_like(q)
        robot = self.robot
        g = robot.inverse_dynamics(q, zero, zero).reshape(q.shape)
        a = robot.inverse_dynamics(q, zero, dq).reshape(q.shape) - g
        b = robot.inverse_dynamics(q, dq, ddq).reshape(q.shape) - g
        tau = np.broadcast_to(self.tau_max, q.shape)
        return PathRows(a, b, -tau - g, tau - g, tuple(f"torque of joint {j + 1}" for j in range(q.shape[1])))
