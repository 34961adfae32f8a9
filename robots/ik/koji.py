"""Closed-form IK of the suspended koji-turning arm with a parallelogram (seed 004).

The paper's position-only method: the parallelogram keeps the wrist level, so the wrist
point ``W`` (on the wrist's vertical axis) depends on the waist, upper-arm and forearm
angles only, and the wrist angle only turns the reach bar ``H`` about that axis.

- waist: ``θ1 = atan2(−W_x, W_y)`` (the arm's vertical plane contains ``W``), and
  ``θ1 + π`` (the arm folded back over the waist);
- upper arm / forearm: a planar two-link problem in the arm plane with the forearm angle
  *absolute* (the parallelogram's property), two branches; candidates outside the joint
  ranges are dropped (the paper's "third step");
- wrist: the tool's heading is ``θ1 + θ4``, so ``θ4`` follows from the target's yaw.

For a pose target ``T`` the wrist point is ``W = T · (M⁻¹ p_W)`` (the reach bar undone
along the target's own heading), which is where the yaw enters. Up to four candidates.

Structure assumed (checked on the model): independent joints waist, shoulder, forearm,
wrist, all revolute; shoulder and forearm axes parallel and not parallel to the waist axis;
wrist axis parallel to the waist axis; one ``<mimic>`` of the shoulder between shoulder and
forearm, and one of the forearm between forearm and wrist, each undoing its master's
rotation exactly (``multiplier · axis = −axis_master``, offset 0).
"""

from __future__ import annotations

import numpy as np

from pinarms.errors import ModelError
from pinarms.robots.ik.geometry import STRUCTURE_TOL, angle_about, chain_axes, plane_basis, planar_two_link, rotate, solve_cos_sin
from pinarms.robots.ik.solver import AnalyticIK

__all__ = ["KojiIK"]


class KojiIK(AnalyticIK):
    """All IK solutions (up to 4) of the koji arm: waist, upper arm, absolute forearm, wrist."""

    family = "parallelogram arm (koji turner)"
    key = "koji"

    def __init__(self, robot, frame: str = "tcp") -> None:
        super().__init__(robot, frame)
        chain = chain_axes(robot, frame)
        axes = chain.axes
        where = f"robot '{robot.name}'"
        indep = [a for a in axes if not a.is_mimic]
        mimics = [a for a in axes if a.is_mimic]
        if robot.nq != 4 or len(indep) != 4 or len(mimics) != 2 or any(a.kind != "revolute" for a in axes):
            raise ModelError(
                f"{where}: the koji solver needs four independent revolute joints and two revolute "
                f"<mimic> joints, found {[(a.name, a.kind, a.is_mimic) for a in axes]}"
            )
        waist, shoulder, forearm, wrist = indep
        pos = {a.name: i for i, a in enumerate(axes)}
        w1, w2 = waist.direction, shoulder.direction
        if np.linalg.norm(np.cross(w1, w2)) < 1e-3:
            raise ModelError(f"{where}: axis of '{shoulder.name}' is parallel to the waist axis")
        if np.linalg.norm(np.cross(w2, forearm.direction)) > STRUCTURE_TOL:
            raise ModelError(f"{where}: axes of '{shoulder.name}' and '{forearm.name}' are not parallel")
        if np.linalg.norm(np.cross(w1, wrist.direction)) > STRUCTURE_TOL:
            raise ModelError(f"{where}: axis of '{wrist.name}' is not parallel to the waist axis")
        links = []
        for master, nxt in ((shoulder, forearm), (forearm, wrist)):
            found = [m for m in mimics if m.q_index == master.q_index]
            m = found[0] if found else None
            if (
                m is None
                or not pos[master.name] < pos[m.name] < pos[nxt.name]
                or abs(m.offset) > 0.0
                or np.linalg.norm(m.scale * m.direction + master.direction) > STRUCTURE_TOL
            ):
                raise ModelError(
                    f"{where}: no <mimic> joint between '{master.name}' and '{nxt.name}' that undoes "
                    f"'{master.name}' (multiplier -1 about the same axis, offset 0): the arm is not a "
                    "parallelogram the koji solver can handle"
                )
            links.append(m)
        self.waist, self.shoulder, self.forearm, self.wrist = waist, shoulder, forearm, wrist
        self.u = links[0].point - shoulder.point  # upper arm: shoulder axis → elbow axis
        self.v = links[1].point - forearm.point  # forearm: elbow axis → wrist pitch axis
        self.sign3 = float(np.sign(forearm.direction @ w2))
        self.sign4 = float(np.sign(wrist.direction @ w1))
        self.home_inv = np.linalg.inv(chain.home)
        self.wrist_in_tool = self.home_inv[:3, :3] @ wrist.point + self.home_inv[:3, 3]
        self.basis = plane_basis(w2)
        self.yaw_basis = plane_basis(w1)
        self._mark_revolute(axes)
        self._self_check()

    def wrist_points(self, targets: np.ndarray) -> np.ndarray:
        """Wrist point ``W (N, 3)`` [m, base frame] of pose targets ``(N, 4, 4)``."""
        return targets[:, :3, :3] @ self.wrist_in_tool + targets[:, :3, 3]

    def arm_angles(self, wrist_points: np.ndarray) -> np.ndarray:
        """The paper's position-only step: ``(θ1, θ2, θ3)`` candidates ``(N, 4, 3)`` [rad] of wrist points ``(N, 3)``.

        NaN rows are candidates that do not exist (point out of the arm's reach).
        """
        W = np.asarray(wrist_points, dtype=float)
        N = W.shape[0]
        w1, w2 = self.waist.direction, self.shoulder.direction
        p1, p4 = self.waist.point, self.wrist.point
        v1 = W - p1
        k12 = w1 @ w2
        vw1 = v1 @ w1
        # (R1 w2)·(W − p1) = w2·(p4 − p1): θ1 = atan2(−Px, Py) and θ1 + π for the paper's axes
        q1 = solve_cos_sin(v1 @ w2 - k12 * vw1, v1 @ np.cross(w1, w2), w2 @ (p4 - p1) - k12 * vw1)  # (N,2)
        local = rotate(w1, -q1, np.broadcast_to(v1[:, None, :], (N, 2, 3))) + p1  # W in the waist frame
        reach = local - p4 + self.u + self.v  # = R2 u + R3 v (absolute forearm angle)
        alpha, beta = planar_two_link(self.basis, self.u, self.v, reach)  # (N,2,2)
        out = np.empty((N, 2, 2, 3))
        out[..., 0] = q1[:, :, None]
        out[..., 1] = beta
        out[..., 2] = self.sign3 * (alpha + beta)
        return out.reshape(N, 4, 3)

    def raw(self, targets: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
        N = targets.shape[0]
        arm = self.arm_angles(self.wrist_points(targets))  # (N,4,3)
        a = self.yaw_basis[0]
        yaw = angle_about(self.waist.direction, a, targets[:, :3, :3] @ (self.home_inv[:3, :3].T @ a))
        out = np.empty((N, 4, 4))
        out[..., self.waist.q_index] = arm[..., 0]
        out[..., self.shoulder.q_index] = arm[..., 1]
        out[..., self.forearm.q_index] = arm[..., 2]
        out[..., self.wrist.q_index] = self.sign4 * (yaw[:, None] - arm[..., 0])
        return out
