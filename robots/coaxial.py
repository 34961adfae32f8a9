"""Shapes that fill the same space at every angle of the joints that carry them (proven, not sampled).

A sphere whose centre lies on a revolute joint's axis, or a cylinder, capsule or cone whose
own axis is that joint's axis, is mapped onto itself by every rotation about the axis: the
set of points it occupies does not depend on the joint's angle. Such a shape is, as far as
any distance is concerned, fixed in the frame of the joint's parent; the test is repeated
there with the parent joint (a sphere at the crossing of two axes is fixed two joints up).
Prismatic joints and other shapes (boxes, meshes) stop the climb. Tolerance: 1e-9 m on the
distance of the centre from the axis, 1e-9 on the sine of the angle between the two axes.

:func:`still_frames` gives, per geometry, the joints in whose frames it is fixed: its own
parent joint and every joint up to where the climb stops. :mod:`.pair_rules` calls two geometries
with a frame in common ``coaxial`` (their distance never changes) and uses the frames for
adjacency (the Panda's link-3 sphere at joint 2 is part of link 2 as far as distances go).
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

__all__ = ["still_frames", "revolute_axis", "symmetry", "AXIS_TOL"]

#: Distance [m] of a centre from an axis, and sine of the angle between two axes, taken as zero.
AXIS_TOL = 1e-9


def revolute_axis(data: pin.Data, j: int) -> np.ndarray | None:
    """Unit axis of joint ``j`` in its own frame (through the frame's origin), ``None`` if not a rotation."""
    motion = np.array(data.joints[j].S).reshape(6, -1)
    if motion.shape[1] != 1:
        return None
    linear, angular = motion[:3, 0], motion[3:, 0]
    norm = float(np.linalg.norm(angular))
    if np.linalg.norm(linear) > 1e-12 or norm < 1e-12:
        return None
    return angular / norm


def symmetry(geometry: coal.CollisionGeometry, placement: pin.SE3) -> tuple[np.ndarray, np.ndarray | None] | None:
    """``(centre, axis)`` in the parent joint's frame: a sphere's centre (axis ``None``: any axis through it), a
    cylinder's, capsule's or cone's centre and local z axis; ``None`` for a shape without a turning symmetry."""
    if isinstance(geometry, coal.Sphere):
        return np.array(placement.translation, dtype=float), None
    if isinstance(geometry, (coal.Cylinder, coal.Capsule, coal.Cone)):
        return np.array(placement.translation, dtype=float), np.array(placement.rotation[:, 2], dtype=float)
    return None


def still_frames(model: pin.Model, data: pin.Data, objs: list) -> list[tuple[int, ...]]:
    """Per geometry of ``objs``, the joints (its parent joint first, then up the tree) in whose frames it is fixed."""
    out = []
    for g in objs:
        j = int(g.parentJoint)
        frames = [j]
        sym = symmetry(g.geometry, g.placement)
        while sym is not None and j > 0:
            u = revolute_axis(data, j)
            if u is None:
                break
            centre, axis = sym
            if np.linalg.norm(centre - (centre @ u) * u) > AXIS_TOL:
                break
            if axis is not None and np.linalg.norm(np.cross(axis, u)) > AXIS_TOL:
                break
            M = model.jointPlacements[j]
            sym = (M.act(centre), None if axis is None else np.asarray(M.rotation) @ axis)
            j = int(model.parents[j])
            frames.append(j)
        out.append(tuple(frames))
    return out
