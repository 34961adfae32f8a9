"""A Pinocchio model compiled into arrays for batched forward kinematics and Jacobians.

Pinocchio evaluates one configuration per call; a Python loop over 10^6 samples spends
almost all its time in the interpreter. :class:`KinematicTree` reads the model once
(joint placements, joint axes, mimic couplings) and then evaluates a whole batch
``q (N, nq)`` with a few BLAS calls and elementwise numpy operations per joint.

Every 1-DoF joint is rewritten so that it moves along or about its local z axis:
``R(axis, θ) = A · Rz(θ) · Aᵀ`` with a constant ``A`` taking z to the axis, and the
trailing ``Aᵀ`` is folded into the placements of the joint's children and frames.
Supported joints: revolute (any axis), prismatic (any axis), continuous (unbounded
revolute, ``nq_pin = 2``) and ``<mimic>`` joints of those (``θ = scale·q_master + offset``).
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from .errors import ModelError

__all__ = ["KinematicTree", "JointCoordinates"]

_CHUNK = 16384  # samples per block: keeps the working set in cache and memory bounded
_WORKERS = max(1, min(4, os.cpu_count() or 1))

_REVOLUTE, _PRISMATIC = 1, 2


def _rotation_z_to(axis: np.ndarray) -> np.ndarray:
    """A rotation matrix whose third column is the unit vector ``axis``."""
    z = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z])


@dataclass(frozen=True)
class JointCoordinates:
    """How the robot's independent joint values map to Pinocchio's configuration vector.

    pinarms uses one real coordinate per independent 1-DoF joint (the tangent
    coordinate, Pinocchio's ``idx_v``). A continuous joint is stored by Pinocchio as
    ``(cos θ, sin θ)``; every other supported joint as ``θ`` or ``d`` itself.
    """

    nq_pin: int
    idx_q_pin: np.ndarray  # (nq,) start of each independent joint in Pinocchio's q
    is_unbounded: np.ndarray  # (nq,) bool: continuous joint stored as (cos, sin)

    def to_pin(self, q: np.ndarray) -> np.ndarray:
        """Pinocchio configuration vector(s) for ``q (nq,)`` or ``(N, nq)``."""
        q = np.asarray(q, dtype=float)
        out = np.zeros(q.shape[:-1] + (self.nq_pin,))
        for j, (iq, unb) in enumerate(zip(self.idx_q_pin, self.is_unbounded)):
            if unb:
                out[..., iq] = np.cos(q[..., j])
                out[..., iq + 1] = np.sin(q[..., j])
            else:
                out[..., iq] = q[..., j]
        return out

    def from_pin(self, q_pin: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`to_pin`."""
        q_pin = np.asarray(q_pin, dtype=float)
        cols = []
        for iq, unb in zip(self.idx_q_pin, self.is_unbounded):
            if unb:
                cols.append(np.arctan2(q_pin[..., iq + 1], q_pin[..., iq]))
            else:
                cols.append(q_pin[..., iq])
        return np.stack(cols, axis=-1)


class KinematicTree:
    """Batched forward kinematics and frame Jacobians of a Pinocchio model.

    Args:
        model: a Pinocchio model whose joints are all 1-DoF revolute, prismatic or
            continuous, or mimics of those (built with ``mimic=True``).

    Raises:
        ModelError: the model holds a joint kind this evaluator does not support
            (free flyer, spherical, planar, ...).
    """

    def __init__(self, model: pin.Model) -> None:
        self.model = model
        n = model.njoints
        data = model.createData()
        pin.forwardKinematics(model, data, pin.neutral(model))

        self.parent = np.array([model.parents[i] for i in range(n)], dtype=int)
        self.kind = np.zeros(n, dtype=int)
        self.q_index = np.full(n, -1, dtype=int)  # index of the independent coordinate
        self.scale = np.ones(n)
        self.offset = np.zeros(n)
        axis_rot = np.tile(np.eye(3), (n, 1, 1))  # A_i: z → joint axis, joint frame
        placement_R = np.tile(np.eye(3), (n, 1, 1))
        placement_p = np.zeros((n, 3))

        idx_q_pin, unbounded = [], []
        for i in range(1, n):
            joint = model.joints[i]
            short = joint.shortname()
            is_mimic = "Mimic" in short
            if is_mimic:
                mimic = joint.extract()
                self.scale[i], self.offset[i] = mimic.scaling, mimic.offset
            elif joint.nv != 1:
                raise ModelError(
                    f"joint '{model.names[i]}' is a {short} with {joint.nv} degrees of freedom; "
                    "pinarms models arms made of 1-DoF revolute, prismatic and continuous joints "
                    "(and <mimic> joints of those)"
                )
            self.q_index[i] = joint.idx_v
            if not is_mimic:
                idx_q_pin.append(joint.idx_q)
                unbounded.append(joint.nq == 2)
            motion = np.array(data.joints[i].S).reshape(6, -1)[:, 0] / self.scale[i]
            linear, angular = motion[:3], motion[3:]
            if np.linalg.norm(angular) > 1e-12 and np.linalg.norm(linear) < 1e-12:
                self.kind[i] = _REVOLUTE
                axis = angular
            elif np.linalg.norm(linear) > 1e-12 and np.linalg.norm(angular) < 1e-12:
                self.kind[i] = _PRISMATIC
                axis = linear
            else:
                raise ModelError(
                    f"joint '{model.names[i]}' ({short}) is neither a pure rotation nor a pure "
                    "translation; pinarms cannot evaluate it in batch"
                )
            axis_rot[i] = _rotation_z_to(axis)
            M = model.jointPlacements[i]
            placement_R[i] = M.rotation
            placement_p[i] = M.translation

        # Fold A_parentᵀ into each child's placement and A_iᵀ... into nothing: joint i's
        # batched frame is R_i' = R_i · A_i, so a child c sees the placement
        # A_parentᵀ · M_c, and its own frame gets · A_c.
        self.local_R = np.empty((n, 3, 3))
        self.local_p = np.empty((n, 3))
        for i in range(1, n):
            Ap = axis_rot[self.parent[i]]
            self.local_R[i] = Ap.T @ placement_R[i] @ axis_rot[i]
            self.local_p[i] = Ap.T @ placement_p[i]
        self.axis_rot = axis_rot
        self.coordinates = JointCoordinates(
            nq_pin=model.nq,
            idx_q_pin=np.array(idx_q_pin, dtype=int),
            is_unbounded=np.array(unbounded, dtype=bool),
        )
        self.nq = model.nv
        # joints on the path from the root to each joint (for Jacobians)
        self.ancestors = []
        for i in range(n):
            chain, j = [], i
            while j > 0:
                chain.append(j)
                j = self.parent[j]
            self.ancestors.append(chain[::-1])

    # ------------------------------------------------------------------ frames
    def frame_of(self, frame_id: int) -> tuple[int, np.ndarray, np.ndarray]:
        """``(joint, R, p)``: the frame's parent joint and its placement in the batched joint frame."""
        f = self.model.frames[frame_id]
        A = self.axis_rot[f.parentJoint]
        return f.parentJoint, A.T @ f.placement.rotation, A.T @ f.placement.translation

    # ------------------------------------------------------------- evaluation
    # Rotations are held as 3×3 nested lists of (N,) arrays (structure of arrays), so
    # that products with the constant placements skip their zero entries and every
    # operation is a contiguous elementwise numpy call.
    def _joint_poses(self, q: np.ndarray, upto: int) -> tuple[dict, dict]:
        """World rotations and positions of every joint on the path to ``upto``.

        Returns ``R[i]`` (3×3 nested list of ``(N,)`` arrays or floats) and ``p[i]``
        (list of 3) in the batched joint frames; joint 0 (the universe) is the identity.
        """
        Rs = {0: _IDENTITY}
        ps = {0: [0.0, 0.0, 0.0]}
        for i in self.ancestors[upto]:
            par = self.parent[i]
            Rp, pp = Rs[par], ps[par]
            R = _mat_const(Rp, self.local_R[i])
            p = _add(pp, _vec_const(Rp, self.local_p[i]))
            value = q[:, self.q_index[i]]
            if self.scale[i] != 1.0:
                value = self.scale[i] * value
            if self.offset[i] != 0.0:
                value = value + self.offset[i]
            if self.kind[i] == _REVOLUTE:
                c, s = np.cos(value), np.sin(value)
                for row in R:
                    x, y = row[0], row[1]
                    row[0], row[1] = c * x + s * y, c * y - s * x
            else:
                p = [p[k] + value * R[k][2] for k in range(3)]
            Rs[i], ps[i] = R, p
        return Rs, ps

    def frame_pose(self, q: np.ndarray, frame_id: int) -> np.ndarray:
        """Homogeneous transforms ``(N, 4, 4)`` frame → world for a batch ``q (N, nq)``."""
        N = q.shape[0]
        out = np.empty((N, 4, 4))
        joint, fR, fp = self.frame_of(frame_id)

        def block(start: int) -> None:
            qc = q[start : start + _CHUNK]
            n = qc.shape[0]
            Rs, ps = self._joint_poses(qc, joint)
            R = _mat_const(Rs[joint], fR)
            p = _add(ps[joint], _vec_const(Rs[joint], fp))
            buf = np.empty((n, 4, 4))
            for a in range(3):
                for b in range(3):
                    buf[:, a, b] = R[a][b]
                buf[:, a, 3] = p[a]
            buf[:, 3, :3] = 0.0
            buf[:, 3, 3] = 1.0
            out[start : start + n] = buf

        _run_chunks(block, N)
        return out

    def origin_and_columns(self, qc: np.ndarray, frame_id: int) -> tuple[list, list]:
        """Frame origin and Jacobian columns of one chunk ``qc (n, nq)``, structure of arrays.

        Returns ``p`` (3 arrays ``(n,)``, world frame [m]) and ``cols``: for each
        independent joint, 6 entries (linear then angular, world axes at the frame origin),
        each an ``(n,)`` array or the float 0.0 when the joint does not move the frame.

        Column of a revolute joint with world axis ``ω`` through ``o``: ``[ω × (p − o); ω]``;
        of a prismatic joint: ``[axis; 0]``; a mimic joint adds ``scale ×`` its column to
        its master's column.
        """
        joint, _, fp = self.frame_of(frame_id)
        Rs, ps = self._joint_poses(qc, joint)
        p = _add(ps[joint], _vec_const(Rs[joint], fp))
        cols: list = [[0.0] * 6 for _ in range(self.nq)]
        for i in self.ancestors[joint]:
            w = [Rs[i][k][2] for k in range(3)]
            if self.kind[i] == _REVOLUTE:
                d = [p[a] - ps[i][a] for a in range(3)]
                six = [w[1] * d[2] - w[2] * d[1], w[2] * d[0] - w[0] * d[2], w[0] * d[1] - w[1] * d[0]] + w
            else:
                six = w + [0.0, 0.0, 0.0]
            k, col = self.scale[i], cols[self.q_index[i]]
            for a in range(6):
                col[a] = col[a] + (six[a] if k == 1.0 else k * six[a])
        return p, cols

    def frame_jacobian(self, q: np.ndarray, frame_id: int) -> np.ndarray:
        """Frame Jacobians ``(N, 6, nq)``: world-aligned axes at the frame origin, linear rows first."""
        N = q.shape[0]
        J = np.zeros((N, 6, self.nq))

        def block(start: int) -> None:
            qc = q[start : start + _CHUNK]
            Jc = J[start : start + qc.shape[0]]
            _, cols = self.origin_and_columns(qc, frame_id)
            for c, col in enumerate(cols):
                for a in range(6):
                    Jc[:, a, c] = col[a]

        _run_chunks(block, N)
        return J


def _run_chunks(block, N: int) -> None:
    """Call ``block(start)`` for every chunk of ``N`` samples, on all cores when it pays.

    numpy releases the GIL inside its elementwise loops, so threads over disjoint chunks
    scale with the cores; each chunk writes only its own rows of the output.
    """
    starts = range(0, N, _CHUNK)
    if len(starts) < 4 or _WORKERS == 1:
        for s in starts:
            block(s)
        return
    with ThreadPoolExecutor(max_workers=_WORKERS) as pool:
        list(pool.map(block, starts))


_IDENTITY = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]


def _snap(x: float) -> float:
    """Exact 0 or ±1 for placement entries within 1e-14 of them (skips needless products)."""
    for v in (0.0, 1.0, -1.0):
        if abs(x - v) < 1e-14:
            return v
    return float(x)


def _lin(terms: list) -> Any:
    """Σ coefficient·value over (value, coefficient) pairs, skipping zeros and unit factors."""
    acc = 0.0
    for value, coef in terms:
        coef = _snap(coef)
        if coef == 0.0 or (isinstance(value, float) and value == 0.0):
            continue
        term = value if coef == 1.0 else (-value if coef == -1.0 else coef * value)
        acc = term if (isinstance(acc, float) and acc == 0.0) else acc + term
    return acc


def _mat_const(R: list, C: np.ndarray) -> list:
    """``R · C`` for a batched rotation ``R`` (nested lists) and a constant 3×3 ``C``."""
    return [[_lin([(R[a][k], C[k, b]) for k in range(3)]) for b in range(3)] for a in range(3)]


def _vec_const(R: list, v: np.ndarray) -> list:
    """``R · v`` for a batched rotation ``R`` and a constant vector ``v``."""
    return [_lin([(R[a][k], v[k]) for k in range(3)]) for a in range(3)]


def _add(p: list, d: list) -> list:
    return [p[a] + d[a] for a in range(3)]
