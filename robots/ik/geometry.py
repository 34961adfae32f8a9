"""Screw axes of a chain read from the Pinocchio model, and vectorised geometric subproblems.

The closed-form solvers write forward kinematics as a product of exponentials,
``T(q) = E_1(q_1) ··· E_n(q_n) · M``, where ``E_i`` rotates about (or translates along)
joint ``i``'s axis as it lies at ``q = 0`` in the base frame, and ``M`` is the target
frame's pose at ``q = 0``. Every axis direction, point and ``M`` come from the loaded
model's joint placements (:func:`chain_axes`); no link length is written twice.

The subproblems take arrays with any leading batch shape and never loop in Python.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinarms.errors import ModelError
from pinarms.robots.so3 import hat as _skew

__all__ = [
    "ChainAxis",
    "Chain",
    "chain_axes",
    "rotate",
    "rotate_const",
    "solve_cos_sin",
    "angle_about",
    "plane_basis",
    "line_intersection",
]

#: Tolerance of the structure checks on the model (parallel / perpendicular / intersecting).
STRUCTURE_TOL = 1e-9


@dataclass(frozen=True)
class ChainAxis:
    """One joint of the chain at ``q = 0``, in the base frame.

    Attributes:
        name: joint name in the URDF.
        kind: ``"revolute"`` or ``"prismatic"``.
        direction: unit axis ``(3,)``; positive joint motion turns right-handed about it
            (revolute) or moves along it (prismatic).
        point: a point of the axis ``(3,)`` [m] (the joint frame's origin).
        q_index: index of the independent coordinate that drives the joint.
        scale: ``θ = scale · q[q_index]`` (``1`` for an independent joint; a ``<mimic>``
            multiplier otherwise).
        offset: the ``<mimic>`` offset [rad or m] (``0`` for an independent joint).
        unbounded: a continuous joint (no position limits).
    """

    name: str
    kind: str
    direction: np.ndarray
    point: np.ndarray
    q_index: int
    scale: float
    offset: float
    unbounded: bool

    @property
    def is_mimic(self) -> bool:
        return self.scale != 1.0 or self.offset != 0.0


@dataclass(frozen=True)
class Chain:
    """The joints from the base to a frame, and the frame's pose ``M`` at ``q = 0``."""

    axes: tuple[ChainAxis, ...]
    home: np.ndarray  # (4, 4) T_frame_to_base at q = 0

    @property
    def independent(self) -> tuple[ChainAxis, ...]:
        """The axes that are not ``<mimic>`` joints, in chain order."""
        return tuple(a for a in self.axes if not a.is_mimic)


def chain_axes(robot, frame: str = "tcp") -> Chain:
    """Screw axes of every joint between the base and ``frame`` at ``q = 0`` (base frame).

    Raises:
        ModelError: a joint on the path is not a 1-DoF revolute/prismatic joint.
    """
    model = robot.model
    tree = robot.kinematic_tree
    fid = robot.frame_id(frame)
    data = model.createData()
    q0 = robot.q_to_pinocchio(np.zeros(robot.nq))
    pin.framesForwardKinematics(model, data, q0)
    axes = []
    for j in (int(i) for i in tree.ancestors[model.frames[fid].parentJoint]):
        kind = {1: "revolute", 2: "prismatic"}.get(int(tree.kind[j]))
        if kind is None:  # pragma: no cover - KinematicTree rejects other joints already
            raise ModelError(f"joint '{model.names[j]}' is neither revolute nor prismatic")
        oMi = data.oMi[j]
        direction = oMi.rotation @ tree.axis_rot[j][:, 2]
        direction = direction / np.linalg.norm(direction)
        q_index = int(tree.q_index[j])
        axes.append(
            ChainAxis(
                name=model.names[j],
                kind=kind,
                direction=direction,
                point=np.array(oMi.translation),
                q_index=q_index,
                scale=float(tree.scale[j]),
                offset=float(tree.offset[j]),
                unbounded=bool(tree.coordinates.is_unbounded[q_index]) and tree.scale[j] == 1.0,
            )
        )
    return Chain(axes=tuple(axes), home=np.array(data.oMf[fid].homogeneous))


# ------------------------------------------------------------------ subproblems
def rotate(direction: np.ndarray, angle: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Rotate vectors ``x (..., 3)`` by ``angle (...)`` [rad] about the unit ``direction (3,)`` (Rodrigues)."""
    w0, w1, w2 = (float(v) for v in direction)
    c = np.cos(angle)
    s = np.sin(angle)
    x0, x1, x2 = x[..., 0], x[..., 1], x[..., 2]
    k = (1.0 - c) * (w0 * x0 + w1 * x1 + w2 * x2)
    out = np.empty(np.broadcast_shapes(x.shape, c.shape + (3,)))
    out[..., 0] = c * x0 + s * (w1 * x2 - w2 * x1) + k * w0
    out[..., 1] = c * x1 + s * (w2 * x0 - w0 * x2) + k * w1
    out[..., 2] = c * x2 + s * (w0 * x1 - w1 * x0) + k * w2
    return out


def rotate_const(direction: np.ndarray, angle: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate one constant vector ``v (3,)`` by every ``angle (...)`` about ``direction``: ``(..., 3)``."""
    w = np.asarray(direction, dtype=float)
    v = np.asarray(v, dtype=float)
    c = np.cos(angle)[..., None]
    s = np.sin(angle)[..., None]
    par = (v @ w) * w
    return par + c * (v - par) + s * np.cross(w, v)


#: ``1 − |c| / sqrt(a² + b²)`` below which :func:`solve_cos_sin` treats the roots as one.
#: Rounding in ``c`` reaches ~1e-13 relative after a chain of transforms (an arccos would
#: then be off by ~5e-7 rad). A genuine pair of roots that close (≤ 2.8e-6 rad apart)
#: merges into one whose pose error is second order (within the FK tolerance) or is
#: restored by the solver's Gauss–Newton polish.
_DOUBLE_ROOT = 1e-12


def solve_cos_sin(a: np.ndarray, b: np.ndarray, c: np.ndarray, slack: float = 1e-10) -> np.ndarray:
    """Both roots ``x`` of ``a·cos x + b·sin x = c``, stacked on a new last axis ``(..., 2)``.

    Roots are NaN where ``|c| > sqrt(a² + b²)`` beyond a relative ``slack`` (no real
    solution); within the slack the two roots merge (a tangent point, rounding only).
    """
    r = np.hypot(a, b)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = c / r
    ratio = np.where(np.abs(ratio) <= 1.0 + slack, np.clip(ratio, -1.0, 1.0), np.nan)
    # |ratio| within rounding of 1 is a double root: arccos would turn a 1e-16 rounding
    # error into a 1e-8 angle error (a square root), so snap it to the tangent point.
    ratio = np.where(np.abs(ratio) >= 1.0 - _DOUBLE_ROOT, np.sign(ratio), ratio)
    base = np.arctan2(b, a)
    delta = np.arccos(ratio)
    return np.stack([base + delta, base - delta], axis=-1)


def angle_about(direction: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Signed angle [rad] turning ``a`` into ``b`` about ``direction`` (both projected on its normal plane)."""
    w = np.asarray(direction, dtype=float)
    cross = np.sum(b * (a @ _skew(w).T), axis=-1)  # (a × b)·w = b·(w × a)
    dot = np.sum(a * b, axis=-1) - (a @ w) * (b @ w)
    return np.arctan2(cross, dot)


def plane_basis(normal: np.ndarray) -> np.ndarray:
    """Rows ``(e1, e2)`` of an orthonormal basis of the plane normal to ``normal``, with ``e1 × e2 = normal``."""
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(helper, n)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    return np.stack([e1, e2])


def line_intersection(p1: np.ndarray, w1: np.ndarray, p2: np.ndarray, w2: np.ndarray) -> tuple[np.ndarray, float]:
    """Midpoint of the closest points of two non-parallel lines and their distance [m]."""
    n = np.cross(w1, w2)
    nn = float(n @ n)
    if nn < STRUCTURE_TOL:
        raise ValueError("parallel lines")
    d = p2 - p1
    t1 = float(np.cross(d, w2) @ n) / nn
    t2 = float(np.cross(d, w1) @ n) / nn
    c1 = p1 + t1 * w1
    c2 = p2 + t2 * w2
    return 0.5 * (c1 + c2), float(np.linalg.norm(c1 - c2))


def planar_two_link(
    basis: np.ndarray, first: np.ndarray, second_offset: np.ndarray, reach: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Angles ``(α, β)`` with ``Rot(β)·(first + Rot(α)·second_offset) = reach`` in a plane.

    Args:
        basis: ``(2, 3)`` rows spanning the plane (``e1 × e2`` is the positive rotation axis).
        first: ``(..., 3)`` vector from the first axis to the second (projected).
        second_offset: ``(..., 3)`` vector from the second axis to the point (projected).
        reach: ``(..., 3)`` vector from the first axis to the point's target (projected).

    Returns:
        ``α (..., 2)`` of the second joint and ``β (..., 2)`` of the first, both branches;
        NaN where the point cannot be reached.
    """
    v = first @ basis.T
    u = second_offset @ basis.T
    d = reach @ basis.T
    a = np.sum(v * u, axis=-1)
    b = v[..., 1] * u[..., 0] - v[..., 0] * u[..., 1]
    c = 0.5 * (np.sum(d * d, axis=-1) - np.sum(v * v, axis=-1) - np.sum(u * u, axis=-1))
    alpha = solve_cos_sin(a, b, c)  # (..., 2)
    ca, sa = np.cos(alpha), np.sin(alpha)
    ux, uy = u[..., 0:1], u[..., 1:2]
    sx = v[..., 0:1] + ca * ux - sa * uy
    sy = v[..., 1:2] + sa * ux + ca * uy
    dx, dy = d[..., 0:1], d[..., 1:2]
    beta = np.arctan2(sx * dy - sy * dx, sx * dx + sy * dy)
    return alpha, beta
