"""Closed-form IK of six-revolute arms with three parallel axes (UR3/5/10, AUBO-i3): up to 8 solutions.

Structure assumed (checked on the model, :class:`~pinarms.errors.ModelError` otherwise):
axes 2, 3, 4 parallel (direction ``w2``, either sign), axis 1 not parallel to them,
axes 5 and 6 intersecting at a point ``C``, axis 5 not parallel to ``w2``. No length is
hard-coded: axes, points and the home pose ``M`` come from the model (:mod:`.geometry`).

With ``g = T_target · M⁻¹ = E1 ··· E6`` (product of exponentials, angles in the robot's own
joint convention: positive about each URDF axis, zero at the URDF's zero):

1. ``E5, E6`` fix ``C`` and ``E2 E3 E4`` keep the ``w2`` component, so
   ``(R1 w2)·(g C − p1) = w2·(C − p1)``: two ``θ1`` (shoulder left/right).
2. ``R1ᵀ R_g = R_w2(φ) R5 R6`` with ``φ = θ2 ± θ3 ± θ4``, hence
   ``w2·R5 w6 = w2·R1ᵀ R_g w6``: two ``θ5`` (wrist flip).
3. ``R6 (R_gᵀ R1 w2) = R5ᵀ w2`` gives ``θ6`` (free at the wrist singularity, where the
   value of ``q_ref`` is kept), and then ``φ``.
4. ``h = E1⁻¹ g E6⁻¹ E5⁻¹ = E2 E3 E4`` moves a point ``P4`` of axis 4 like a planar
   two-link arm: two ``θ3`` (elbow up/down), then ``θ2``, and ``θ4 = φ − θ2 ∓ θ3``.
"""

from __future__ import annotations

import numpy as np

from pinarms.errors import ModelError
from pinarms.robots.ik.geometry import (
    STRUCTURE_TOL,
    angle_about,
    chain_axes,
    line_intersection,
    plane_basis,
    planar_two_link,
    rotate,
    rotate_const,
    solve_cos_sin,
)
from pinarms.robots.ik.solver import AnalyticIK

__all__ = ["URTypeIK"]

_SINGULAR = 1e-6  # |component of R_gᵀR1w2 normal to w6| below which θ6 is also taken from q_ref


class URTypeIK(AnalyticIK):
    """All IK solutions of a UR-type 6R arm (three parallel middle axes, intersecting last two)."""

    family = "UR-type (three parallel axes)"
    key = "ur_type"
    n_branches = 8  # shoulder × wrist flip × elbow; slots 8-15 repeat them at a singular wrist

    def __init__(self, robot, frame: str = "tcp") -> None:
        super().__init__(robot, frame)
        chain = chain_axes(robot, frame)
        axes = chain.axes
        where = f"robot '{robot.name}'"
        if len(axes) != 6 or robot.nq != 6 or any(a.kind != "revolute" or a.is_mimic for a in axes):
            raise ModelError(
                f"{where}: the UR-type solver needs six independent revolute joints between the base "
                f"and '{frame}', found {[(a.name, a.kind) for a in axes]}"
            )
        w = [a.direction for a in axes]
        p = [a.point for a in axes]
        for k in (2, 3):
            if np.linalg.norm(np.cross(w[1], w[k])) > STRUCTURE_TOL:
                raise ModelError(f"{where}: axes of '{axes[1].name}' and '{axes[k].name}' are not parallel")
        if np.linalg.norm(np.cross(w[0], w[1])) < 1e-3:
            raise ModelError(f"{where}: axis of '{axes[0].name}' is parallel to '{axes[1].name}'")
        if np.linalg.norm(np.cross(w[4], w[1])) < 1e-3:
            raise ModelError(f"{where}: axis of '{axes[4].name}' is parallel to '{axes[1].name}'")
        try:
            C, gap = line_intersection(p[4], w[4], p[5], w[5])
        except ValueError:
            raise ModelError(f"{where}: axes of '{axes[4].name}' and '{axes[5].name}' are parallel") from None
        if gap > STRUCTURE_TOL:
            raise ModelError(
                f"{where}: axes of '{axes[4].name}' and '{axes[5].name}' do not intersect (gap {gap:.3g} m)"
            )
        for k in (1, 2):
            d = p[k + 1] - p[k]
            if np.linalg.norm(d - (d @ w[1]) * w[1]) < 1e-6:
                raise ModelError(f"{where}: axes of '{axes[k].name}' and '{axes[k + 1].name}' coincide")
        self.axes = axes
        self.w = w
        self.p = p
        self.C = C
        self.home_inv = np.linalg.inv(chain.home)
        self.sign3 = float(np.sign(w[2] @ w[1]))
        self.sign4 = float(np.sign(w[3] @ w[1]))
        self.basis = plane_basis(w[1])
        self._mark_revolute(axes)
        self._self_check()

    def raw(self, targets: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
        w1, w2, w3, w4, w5, w6 = self.w
        p1, p2, p3, p4, p5, p6 = self.p
        N = targets.shape[0]
        g = targets @ self.home_inv
        Rg, tg = g[:, :3, :3], g[:, :3, 3]

        # 1. shoulder: (R1 w2)·(g C − p1) = w2·(C − p1)
        v = Rg @ self.C + tg - p1
        k12 = w1 @ w2
        vw1 = v @ w1
        q1 = solve_cos_sin(v @ w2 - k12 * vw1, v @ np.cross(w1, w2), w2 @ (self.C - p1) - k12 * vw1)  # (N,2)

        # 2. wrist flip: w2·R5 w6 = w2·R1ᵀ R_g w6
        y5 = rotate(w1, -q1, np.broadcast_to((Rg @ w6)[:, None, :], (N, 2, 3)))
        k56 = (w5 @ w6) * (w5 @ w2)
        a5 = np.full((N, 2), w2 @ w6 - k56)
        b5 = np.full((N, 2), w2 @ np.cross(w5, w6))
        q5 = solve_cos_sin(a5, b5, y5 @ w2 - k56)  # (N,2,2)

        # 3. θ6 from R6 (R_gᵀ R1 w2) = R5ᵀ w2, free at the wrist singularity
        R1w2 = rotate_const(w1, q1, w2)  # (N,2,3)
        y = (R1w2 @ Rg)[:, :, None, :]  # rows: (R_gᵀ R1 w2)ᵀ, (N,2,1,3)
        z = rotate_const(w5, -q5, w2)  # (N,2,2,3)
        y6 = y @ w6
        y_perp = np.sqrt(np.maximum(np.sum(y * y, axis=-1) - y6 * y6, 0.0))  # = |sin θ5|-like
        q6 = np.where(y_perp > 1e-12, angle_about(w6, y, z), np.nan)
        out = self._finish(Rg, tg, q1, q5, q6)
        near = y_perp < _SINGULAR
        if near.any():  # wrist singularity: θ6 is free, take q_ref's (the arm keeps its planar freedom)
            alt = self._finish(Rg, tg, q1, q5, np.where(near, q_ref[:, 5, None, None], np.nan) + 0.0 * q5)
            out = np.concatenate([out, alt], axis=1)
        return out

    def _finish(self, Rg, tg, q1, q5, q6) -> np.ndarray:
        """φ, the planar arm and θ4 for given θ1 (N,2), θ5 and θ6 (N,2,2): candidates (N, 8, 6)."""
        w1, w2, w3, w4, w5, w6 = self.w
        p1, p2, p3, p4, p5, p6 = self.p
        N = Rg.shape[0]
        # φ = angle of R1ᵀ R_g R6ᵀ R5ᵀ about w2
        a = self.basis[0]
        t = rotate_const(w5, -q5, a)
        t = rotate(w6, -q6, t)
        t = (t.reshape(N, 4, 3) @ Rg.transpose(0, 2, 1)).reshape(N, 2, 2, 3)
        t = rotate(w1, -q1[:, :, None], t)
        phi = angle_about(w2, a, t)  # (N,2,2)

        # 4. planar arm: E2 E3 P4 = h P4
        x = rotate_const(w5, -q5, p4 - p5) + (p5 - p6)
        x = rotate(w6, -q6, x) + p6
        x = (x.reshape(N, 4, 3) @ Rg.transpose(0, 2, 1)).reshape(N, 2, 2, 3) + (tg - p1)[:, None, None, :]
        x = rotate(w1, -q1[:, :, None], x) + (p1 - p2)
        alpha, beta = planar_two_link(self.basis, p3 - p2, p4 - p3, x)  # (N,2,2,2)
        q2 = beta
        q3 = self.sign3 * alpha
        q4 = self.sign4 * (phi[..., None] - q2 - self.sign3 * q3)

        out = np.empty((N, 2, 2, 2, 6))
        out[..., 0] = q1[:, :, None, None]
        out[..., 1] = q2
        out[..., 2] = q3
        out[..., 3] = q4
        out[..., 4] = q5[..., None]
        out[..., 5] = q6[..., None]
        q = np.empty_like(out)
        for k, ax in enumerate(self.axes):
            q[..., ax.q_index] = out[..., k]
        return q.reshape(N, 8, 6)
