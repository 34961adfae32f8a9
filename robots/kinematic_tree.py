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

from pinarms.errors import ModelError
from pinarms.robots.so3 import frame_z_to as _rotation_z_to

__all__ = ["KinematicTree", "JointCoordinates", "REVOLUTE", "PRISMATIC"]

_CHUNK = 16384  # samples per block: keeps the working set in cache and memory bounded
_WORKERS = max(1, min(4, os.cpu_count() or 1))

#: Codes of a 1-DoF joint's kind in :attr:`KinematicTree.kind`: rotating about its axis, or sliding along it.
REVOLUTE, PRISMATIC = 1, 2


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
        unb = self.is_unbounded
        if not unb.any():
            out[..., self.idx_q_pin] = q
            return out
        iq = self.idx_q_pin
        out[..., iq[~unb]] = q[..., ~unb]
        out[..., iq[unb]] = np.cos(q[..., unb])
        out[..., iq[unb] + 1] = np.sin(q[..., unb])
        return out

    def from_pin(self, q_pin: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`to_pin`."""
        q_pin = np.asarray(q_pin, dtype=float)
        iq, unb = self.idx_q_pin, self.is_unbounded
        out = q_pin[..., iq]
        if unb.any():
            out[..., unb] = np.arctan2(q_pin[..., iq[unb] + 1], q_pin[..., iq[unb]])
        return out


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
        self.parent = np.array([model.parents[i] for i in range(n)], dtype=int)
        self.kind = np.zeros(n, dtype=int)
        self.q_index = np.full(n, -1, dtype=int)  # index of the independent coordinate
        self.scale = np.ones(n)
        self.offset = np.zeros(n)
        axis_rot, placement_R, placement_p, idx_q_pin, unbounded = self._read_joints(model)
        self._fold_axes(axis_rot, placement_R, placement_p)
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
        self._compile_constants()

    def _read_joints(self, model: pin.Model) -> tuple:
        """Kind, coordinate, mimic scale/offset of every joint (set on ``self``); returns
        ``(axis_rot, placement_R, placement_p, idx_q_pin, unbounded)``.

        ``axis_rot[i]`` (A_i) takes z to joint i's axis; the placements are the model's.
        """
        n = model.njoints
        data = model.createData()
        pin.forwardKinematics(model, data, pin.neutral(model))
        axis_rot = np.tile(np.eye(3), (n, 1, 1))  # A_i: z → joint axis, joint frame
        placement_R = np.tile(np.eye(3), (n, 1, 1))
        placement_p = np.zeros((n, 3))
        idx_q_pin, unbounded = [], []
        for i in range(1, n):
            joint = model.joints[i]
            is_mimic = self._read_coupling(model, i, joint)
            self.q_index[i] = joint.idx_v
            if not is_mimic:
                idx_q_pin.append(joint.idx_q)
                unbounded.append(joint.nq == 2)
            motion = np.array(data.joints[i].S).reshape(6, -1)[:, 0] / self.scale[i]
            self.kind[i], axis = _joint_kind(model.names[i], joint.shortname(), motion)
            axis_rot[i] = _rotation_z_to(axis)
            M = model.jointPlacements[i]
            placement_R[i] = M.rotation
            placement_p[i] = M.translation
        return axis_rot, placement_R, placement_p, idx_q_pin, unbounded

    def _read_coupling(self, model: pin.Model, i: int, joint) -> bool:
        """Whether joint ``i`` is a mimic (its scale and offset set on ``self``); raises for a multi-DoF joint."""
        short = joint.shortname()
        if "Mimic" in short:
            mimic = joint.extract()
            self.scale[i], self.offset[i] = mimic.scaling, mimic.offset
            if not (np.isfinite(mimic.scaling) and mimic.scaling != 0.0 and np.isfinite(mimic.offset)):
                raise ModelError(
                    f"mimic joint '{model.names[i]}' has multiplier {mimic.scaling!r} and offset "
                    f"{mimic.offset!r}; a mimic needs a finite, non-zero multiplier (a joint that never "
                    "moves is a fixed joint)"
                )
            return True
        if joint.nv != 1:
            raise ModelError(
                f"joint '{model.names[i]}' is a {short} with {joint.nv} degrees of freedom; "
                "pinarms models arms made of 1-DoF revolute, prismatic and continuous joints "
                "(and <mimic> joints of those)"
            )
        return False

    def _fold_axes(self, axis_rot: np.ndarray, placement_R: np.ndarray, placement_p: np.ndarray) -> None:
        """``local_R``, ``local_p``, ``axis_rot``: every joint rewritten to move along or about its own z.

        Fold A_parentᵀ into each child's placement and A_iᵀ... into nothing: joint i's
        batched frame is R_i' = R_i · A_i, so a child c sees the placement
        A_parentᵀ · M_c, and its own frame gets · A_c.
        """
        n = self.parent.shape[0]
        self.local_R = np.empty((n, 3, 3))
        self.local_p = np.empty((n, 3))
        for i in range(1, n):
            Ap = axis_rot[self.parent[i]]
            self.local_R[i] = Ap.T @ placement_R[i] @ axis_rot[i]
            self.local_p[i] = Ap.T @ placement_p[i]
        self.axis_rot = axis_rot

    def _compile_constants(self) -> None:
        """Constants of the evaluation, computed once: for every joint the nonzero terms of
        its placement (entries within 1e-14 of 0 or ±1 snapped), its coordinate's
        index, scale and offset as plain Python numbers; the same for every frame."""
        n = self.parent.shape[0]
        self._steps = [None] + [
            (
                i,
                int(self.parent[i]),
                _matrix_terms(self.local_R[i]),
                _vector_terms(self.local_p[i]),
                int(self.q_index[i]),
                float(self.scale[i]),
                float(self.offset[i]),
                int(self.kind[i]) == REVOLUTE,
            )
            for i in range(1, n)
        ]
        self._path = [tuple(self._steps[i] for i in chain) for chain in self.ancestors]
        self._frames = []
        for f in self.model.frames:
            A = self.axis_rot[f.parentJoint]
            fR = A.T @ f.placement.rotation
            fp = A.T @ f.placement.translation
            self._frames.append((int(f.parentJoint), fR, fp, _matrix_terms(fR), _vector_terms(fp)))

    # ------------------------------------------------------------------ frames
    def frame_of(self, frame_id: int) -> tuple[int, np.ndarray, np.ndarray]:
        """``(joint, R, p)``: the frame's parent joint and its placement in the batched joint frame."""
        joint, fR, fp, _, _ = self._frames[frame_id]
        return joint, fR.copy(), fp.copy()

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
        for i, par, R_terms, p_terms, iq, scale, offset, revolute in self._path[upto]:
            Rp, pp = Rs[par], ps[par]
            R = _mat_const(Rp, R_terms)
            p = _add(pp, _vec_const(Rp, p_terms))
            value = q[:, iq]
            if scale != 1.0:
                value = scale * value
            if offset != 0.0:
                value = value + offset
            if revolute:
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
        joint, _, _, fR, fp = self._frames[frame_id]

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
        joint, _, _, _, fp = self._frames[frame_id]
        Rs, ps = self._joint_poses(qc, joint)
        p = _add(ps[joint], _vec_const(Rs[joint], fp))
        cols: list = [[0.0] * 6 for _ in range(self.nq)]
        for i in self.ancestors[joint]:
            w = [Rs[i][k][2] for k in range(3)]
            if self.kind[i] == REVOLUTE:
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


def _joint_kind(name: str, short: str, motion: np.ndarray) -> tuple[int, np.ndarray]:
    """``(REVOLUTE or PRISMATIC, axis)`` of a 1-DoF joint from its motion subspace ``(6,)`` (linear first)."""
    linear, angular = motion[:3], motion[3:]
    if np.linalg.norm(angular) > 1e-12 and np.linalg.norm(linear) < 1e-12:
        return REVOLUTE, angular
    if np.linalg.norm(linear) > 1e-12 and np.linalg.norm(angular) < 1e-12:
        return PRISMATIC, linear
    raise ModelError(
        f"joint '{name}' ({short}) is neither a pure rotation nor a pure "
        "translation; pinarms cannot evaluate it in batch"
    )


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


def _vector_terms(v: np.ndarray) -> tuple:
    """``((k, v_k), ...)`` for the entries of a constant vector that are not (snapped) zero."""
    return tuple((k, c) for k in range(3) if (c := _snap(v[k])) != 0.0)


def _matrix_terms(C: np.ndarray) -> tuple:
    """:func:`_vector_terms` of each column of a constant 3×3 matrix."""
    return tuple(_vector_terms(C[:, b]) for b in range(3))


def _dot(row: list, terms: tuple) -> Any:
    """``Σ row[k]·c`` over the precomputed nonzero terms ``(k, c)``, skipping exact zeros and unit factors."""
    acc = 0.0
    for k, c in terms:
        value = row[k]
        if value.__class__ is float and value == 0.0:
            continue
        term = value if c == 1.0 else (-value if c == -1.0 else c * value)
        acc = term if (acc.__class__ is float and acc == 0.0) else acc + term
    return acc


def _mat_const(R: list, C_terms: tuple) -> list:
    """``R · C`` for a batched rotation ``R`` (nested lists) and a constant 3×3 ``C`` (as :func:`_matrix_terms`)."""
    return [[_dot(row, col) for col in C_terms] for row in R]


def _vec_const(R: list, v_terms: tuple) -> list:
    """``R · v`` for a batched rotation ``R`` and a constant vector ``v`` (as :func:`_vector_terms`)."""
    return [_dot(row, v_terms) for row in R]


def _add(p: list, d: list) -> list:
    return [p[a] + d[a] for a in range(3)]
