"""An independent clearance check for the motion tests: PyBullet's own kinematics and distances.

The arm is loaded into PyBullet from its URDF (PyBullet's forward kinematics, not
Pinocchio's), each fixture (and each other arm, at its held configuration) as separate
bodies built from the cell's primitives, and ``getClosestPoints`` gives the distances
(Bullet's GJK, not coal). Nothing of pinarms' checker is used.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np


class BulletScene:
    """PyBullet copies of a cell's arms (from their URDFs) and fixtures (from their primitives)."""

    def __init__(self, cell, arms):
        import pybullet as pb

        self.pb = pb
        self.client = pb.connect(pb.DIRECT)
        self.cell = cell
        self.arms = {}
        self._files = []
        for name in arms:
            arm = cell.arm(name)
            fd, path = tempfile.mkstemp(suffix=".urdf")
            with os.fdopen(fd, "w") as f:
                f.write(arm.robot.urdf_text)
            self._files.append(path)
            quat = _quat(arm.base_to_world[:3, :3])
            body = pb.loadURDF(path, arm.base_to_world[:3, 3].tolist(), quat, useFixedBase=True,
                               physicsClientId=self.client)
            joints = {}
            for j in range(pb.getNumJoints(body, physicsClientId=self.client)):
                info = pb.getJointInfo(body, j, physicsClientId=self.client)
                joints[info[1].decode()] = j
                pb.changeDynamics(body, j, collisionMargin=0.0, physicsClientId=self.client)
            pb.changeDynamics(body, -1, collisionMargin=0.0, physicsClientId=self.client)
            self.arms[name] = (body, [joints[n] for n in arm.robot.joint_names])
        self.fixtures = []
        for fixture in cell.fixtures:
            for shape in fixture.shapes:
                if shape.kind == "box":
                    s = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[v / 2 for v in shape.size],
                                                physicsClientId=self.client)
                elif shape.kind == "cylinder":
                    s = pb.createCollisionShape(pb.GEOM_CYLINDER, radius=shape.size[0], height=shape.size[1],
                                                physicsClientId=self.client)
                else:
                    continue
                T = shape.shape_to_world
                b = pb.createMultiBody(0, s, basePosition=T[:3, 3].tolist(), baseOrientation=_quat(T[:3, :3]),
                                       physicsClientId=self.client)
                pb.changeDynamics(b, -1, collisionMargin=0.0, physicsClientId=self.client)
                self.fixtures.append(b)

    def set(self, name, q):
        body, idx = self.arms[name]
        for j, v in zip(idx, q):
            self.pb.resetJointState(body, j, float(v), physicsClientId=self.client)

    def distance(self, a, b=None):
        """Smallest distance [m] from the moving links of arm ``a`` (its base, bolted to its stand,
        left out) to the fixtures (``b`` None) or to the moving links of arm ``b``."""
        body = self.arms[a][0]
        n = self.pb.getNumJoints(body, physicsClientId=self.client)
        best = np.inf
        if b is None:
            for o in self.fixtures:
                for link in range(n):
                    pts = self.pb.getClosestPoints(body, o, 1.0, linkIndexA=link, physicsClientId=self.client)
                    if pts:
                        best = min(best, min(p[8] for p in pts))
            return best
        pts = self.pb.getClosestPoints(body, self.arms[b][0], 0.25, physicsClientId=self.client)
        return min((p[8] for p in pts), default=np.inf)

    def close(self):
        self.pb.disconnect(self.client)
        for path in self._files:
            os.unlink(path)


def _quat(R):
    import pinocchio as pin

    q = pin.Quaternion(np.asarray(R, dtype=float))
    return [q.x, q.y, q.z, q.w]


def dense_times(trajectory, levers, resolution=0.001):
    """Instants along ``trajectory`` with at most ``resolution`` [m] of travel of the fastest point between them."""
    v = np.asarray(trajectory.peaks().velocity) @ np.asarray(levers)
    n = int(np.ceil(v * trajectory.duration / resolution)) + 1
    return np.linspace(trajectory.start_time, trajectory.end_time, max(n, 50))
