"""Batched placements of every joint and collision geometry of a model (numpy).

Pinocchio places the geometries of one configuration per call. For the broad phase of
batched collision checks (bounding spheres and boxes of ``N`` configurations at once),
:class:`BatchedPlacements` evaluates the world placement of every joint of a batch
``q (N, nq)`` with a few numpy products per joint, and from them any geometry's.

Joints: revolute and prismatic about/along any axis, continuous, and ``<mimic>`` joints
of those (the value ``scale · q_master + offset``). ``q`` holds one coordinate per
independent joint, in the order of the joints' velocity index (pinarms' convention).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinarms.errors import ModelError

__all__ = ["BatchedPlacements"]


def _skew(a: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


class BatchedPlacements:
    """World placements of all joints of ``model`` for a batch of configurations.

    Args:
        model: a Pinocchio model of 1-DoF joints (and mimics), built with ``mimic=True``.

    Raises:
        ModelError: a joint that is neither a pure rotation nor a pure translation.
    """

    def __init__(self, model: pin.Model) -> None:
        self.model = model
        data = model.createData()
        pin.forwardKinematics(model, data, pin.neutral(model))
        n = model.njoints
        self.parent = [int(model.parents[i]) for i in range(n)]
        self.index = np.zeros(n, dtype=int)
        self.scale = np.ones(n)
        self.offset = np.zeros(n)
        self.revolute = np.zeros(n, dtype=bool)
        self.axis = np.zeros((n, 3))
        self.K = np.zeros((n, 3, 3))
        self.K2 = np.zeros((n, 3, 3))
        self.M_R = np.zeros((n, 3, 3))
        self.M_p = np.zeros((n, 3))
        for i in range(1, n):
            joint = model.joints[i]
            if "Mimic" in joint.shortname():
                mimic = joint.extract()
                self.scale[i], self.offset[i] = mimic.scaling, mimic.offset
            self.index[i] = joint.idx_v
            motion = np.array(data.joints[i].S).reshape(6, -1)[:, 0] / self.scale[i]
            lin, ang = motion[:3], motion[3:]
            if np.linalg.norm(ang) > 1e-12 and np.linalg.norm(lin) < 1e-12:
                self.revolute[i] = True
                a = ang / np.linalg.norm(ang)
                self.axis[i] = a
                self.K[i] = _skew(a)
                self.K2[i] = self.K[i] @ self.K[i]
            elif np.linalg.norm(lin) > 1e-12 and np.linalg.norm(ang) < 1e-12:
                self.axis[i] = lin / np.linalg.norm(lin)
            else:
                raise ModelError(f"joint {model.names[i]!r} is neither a pure rotation nor a pure translation")
            M = model.jointPlacements[i]
            self.M_R[i] = M.rotation
            self.M_p[i] = M.translation

    def joints(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World rotations ``(N, njoints, 3, 3)`` and positions ``(N, njoints, 3)`` of every joint.

        Joint 0 (the universe) is the identity.
        """
        q = np.asarray(q, dtype=float)
        N, n = q.shape[0], self.model.njoints
        R = np.empty((N, n, 3, 3))
        p = np.empty((N, n, 3))
        R[:, 0] = np.eye(3)
        p[:, 0] = 0.0
        for i in range(1, n):
            par = self.parent[i]
            value = q[:, self.index[i]]
            if self.scale[i] != 1.0 or self.offset[i] != 0.0:
                value = self.scale[i] * value + self.offset[i]
            RM = R[:, par] @ self.M_R[i]  # (N, 3, 3)
            p[:, i] = p[:, par] + R[:, par] @ self.M_p[i]
            if self.revolute[i]:
                s, c = np.sin(value), np.cos(value)
                local = np.eye(3) + s[:, None, None] * self.K[i] + (1.0 - c)[:, None, None] * self.K2[i]
                R[:, i] = RM @ local
            else:
                R[:, i] = RM
                p[:, i] += value[:, None] * (RM @ self.axis[i])
        return R, p

    @staticmethod
    def compose(R: np.ndarray, p: np.ndarray, local_R: np.ndarray, local_p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(R, p) · (local_R, local_p)`` for batched ``R (..., 3, 3)``, ``p (..., 3)`` and constant locals."""
        return R @ local_R, p + R @ local_p
