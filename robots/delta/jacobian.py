"""The platform Jacobian of a delta in motor coordinates: ``p_dot = J(theta) theta_dot`` [m/rad].

Closed form: differentiating ``|p - C_i(theta_i)|^2 = l^2`` gives ``A p_dot = D theta_dot`` with
rows ``A_i = (p - C_i)^T`` and ``D = diag((p - C_i) . dC_i/dtheta_i)``, so ``J = A^-1 D``.
From Pinocchio's constraint Jacobian ``J_c = [J_motor, J_passive]`` (the closures hold while
moving): ``q_dot_passive = -J_passive^-1 J_motor theta_dot``, whose platform rows are ``J``.
"""

from __future__ import annotations

import numpy as np

from pinarms.robots.delta.geometry import DeltaGeometry
from pinarms.robots.delta.kinematics import as_points, forward_position, virtual_elbows
from pinarms.robots.delta.model import DeltaRobot

__all__ = ["constraint_matrices", "platform_jacobian", "platform_jacobian_pinocchio"]


def constraint_matrices(geom: DeltaGeometry, theta) -> tuple[np.ndarray, np.ndarray]:
    """``(A, d)`` of the velocity equation ``A p_dot = diag(d) theta_dot``: A (N, 3, 3) [m], d (N, 3) [m^2/rad]."""
    th, _ = as_points(theta, "theta")
    p = forward_position(geom, th)
    rel = p[:, None, :] - virtual_elbows(geom, th)                        # p - C_i, (N, 3, 3)
    e = geom.radial
    dc = -geom.upper_arm * (np.sin(th)[:, :, None] * e + np.cos(th)[:, :, None] * np.array([0.0, 0.0, 1.0]))
    return rel, np.einsum("nij,nij->ni", rel, dc)


def platform_jacobian(geom: DeltaGeometry, theta) -> np.ndarray:
    """Closed-form ``J`` (3, 3) or (N, 3, 3) [m/rad]; NaN/inf near a parallel singularity."""
    th, single = as_points(theta, "theta")
    a, d = constraint_matrices(geom, th)
    jac = np.linalg.solve(a, d[:, :, None] * np.eye(3)[None])
    return jac[0] if single else jac


def platform_jacobian_pinocchio(delta: DeltaRobot, q) -> np.ndarray:
    """``J`` (3, 3) [m/rad] at a closed configuration ``q`` (nq,), from Pinocchio's constraint Jacobians."""
    jc = delta.constraint_jacobian(np.asarray(q, dtype=float))
    passive = delta.passive_q                      # nq = nv for the family: q and v indices agree
    qd_passive = -np.linalg.solve(jc[:, passive], jc[:, delta.motor_q])
    rows = np.searchsorted(passive, delta.platform_q)
    return qd_passive[rows]
