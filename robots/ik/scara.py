"""Closed-form IK of a SCARA arm (seed 000): both elbow branches, the vertical stroke and the hand rotation.

Structure assumed (checked on the model, :class:`~pinarms.errors.ModelError` otherwise): four
independent joints, three revolute and one prismatic, every axis parallel to the first
one's direction ``w`` (vertical for the mushroom-packing SCARA). The first two revolute
joints form the planar arm, the third turns the hand. Lengths and axis positions come from
the model (:mod:`.geometry`).

A SCARA reaches a *position and a yaw* about ``w``: a target whose orientation is tilted
has no solution (the FK check of :class:`~.solver.AnalyticIK` drops it, and
:meth:`pinarms.robots.Robot.ik_failure_reason` says so). With ``g = T_target · M⁻¹``:

- stroke: translations along ``w`` commute with rotations about axes parallel to ``w``,
  so ``d = w·(g P − P) / (w·a)`` for a point ``P`` of the hand axis (``a``: the slide's axis);
- elbow: the plane projection of ``g P`` is a planar two-link problem (two branches);
- hand: the yaw of ``R_g`` about ``w`` minus the two arm angles.
"""

from __future__ import annotations

import numpy as np

from pinarms.errors import ModelError
from pinarms.robots.ik.geometry import STRUCTURE_TOL, angle_about, chain_axes, plane_basis, planar_two_link
from pinarms.robots.ik.solver import AnalyticIK

__all__ = ["ScaraIK"]


class ScaraIK(AnalyticIK):
    """All IK solutions (two elbow branches) of a 4-axis SCARA, for position + yaw targets."""

    family = "SCARA"
    key = "scara"

    def __init__(self, robot, frame: str = "tcp") -> None:
        super().__init__(robot, frame)
        chain = chain_axes(robot, frame)
        axes = chain.axes
        where = f"robot '{robot.name}'"
        rev = [a for a in axes if a.kind == "revolute"]
        pri = [a for a in axes if a.kind == "prismatic"]
        if robot.nq != 4 or len(axes) != 4 or len(rev) != 3 or len(pri) != 1 or any(a.is_mimic for a in axes):
            raise ModelError(
                f"{where}: the SCARA solver needs three revolute and one prismatic independent joint "
                f"between the base and '{frame}', found {[(a.name, a.kind) for a in axes]}"
            )
        w = rev[0].direction
        for a in axes[1:]:
            if np.linalg.norm(np.cross(w, a.direction)) > STRUCTURE_TOL:
                raise ModelError(f"{where}: axis of '{a.name}' is not parallel to the axis of '{rev[0].name}'")
        d = rev[1].point - rev[0].point
        if np.linalg.norm(d - (d @ w) * w) < 1e-6:
            raise ModelError(f"{where}: the axes of '{rev[0].name}' and '{rev[1].name}' coincide")
        self.w = w
        self.rev = rev
        self.slide = pri[0]
        self.signs = [float(np.sign(a.direction @ w)) for a in rev]
        self.slide_gain = float(pri[0].direction @ w)
        self.home_inv = np.linalg.inv(chain.home)
        self.basis = plane_basis(w)
        self._mark_revolute(axes)
        self._self_check()

    def raw(self, targets: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
        N = targets.shape[0]
        w = self.w
        r0, r1, r2 = self.rev
        g = targets @ self.home_inv
        Rg, tg = g[:, :3, :3], g[:, :3, 3]
        P = r2.point
        gP = Rg @ P + tg
        stroke = ((gP - P) @ w) / self.slide_gain  # (N,)
        alpha, beta = planar_two_link(self.basis, r1.point - r0.point, P - r1.point, gP - r0.point)  # (N,2)
        a = self.basis[0]
        phi = angle_about(w, a, Rg @ a)  # (N,)
        s0, s1, s2 = self.signs
        out = np.empty((N, 2, 4))
        out[..., r0.q_index] = s0 * beta
        out[..., r1.q_index] = s1 * alpha
        out[..., r2.q_index] = s2 * (phi[:, None] - beta - alpha)
        out[..., self.slide.q_index] = stroke[:, None]
        return out
