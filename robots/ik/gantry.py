"""Closed-form IK of a three-axis Cartesian gantry (seed 002): the unique solution within the strokes.

Structure assumed (checked on the model): three independent prismatic joints whose axes
are linearly independent. Then ``T(q) = Trans(A q) · M`` with ``A`` the ``(3, 3)`` matrix of
the axis directions at ``q = 0`` (from the model), so ``q = A⁻¹ (p_target − p_M)``; the
orientation cannot change, and a target with another orientation has no solution.
"""

from __future__ import annotations

import numpy as np

from pinarms.errors import ModelError
from pinarms.robots.ik.geometry import chain_axes
from pinarms.robots.ik.solver import AnalyticIK

__all__ = ["GantryIK"]


class GantryIK(AnalyticIK):
    """The one IK solution of a three-prismatic-axis gantry."""

    family = "Cartesian gantry"
    key = "gantry"

    def __init__(self, robot, frame: str = "tcp") -> None:
        super().__init__(robot, frame)
        chain = chain_axes(robot, frame)
        axes = chain.axes
        if robot.nq != 3 or len(axes) != 3 or any(a.kind != "prismatic" or a.is_mimic for a in axes):
            raise ModelError(
                f"robot '{robot.name}': the gantry solver needs three independent prismatic joints "
                f"between the base and '{frame}', found {[(a.name, a.kind) for a in axes]}"
            )
        A = np.column_stack([a.direction for a in axes])
        if abs(np.linalg.det(A)) < 1e-6:
            raise ModelError(f"robot '{robot.name}': the gantry's three axes are not independent")
        self.A_inv = np.linalg.inv(A)
        self.order = [a.q_index for a in axes]
        self.home = chain.home
        self._self_check()

    def raw(self, targets: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
        d = (targets[:, :3, 3] - self.home[:3, 3]) @ self.A_inv.T
        out = np.empty((targets.shape[0], 1, 3))
        out[:, 0, self.order] = d
        return out
