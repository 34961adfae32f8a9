"""Motor torques of a delta along a platform motion, with the closed chain (Pinocchio).

For each sample the full state of the tree is made to satisfy the closures at position,
velocity and acceleration level (the platform's motion given, every other coordinate solved
with Pinocchio's constraint Jacobian ``J_c`` and drift ``gamma``)::

    q: closed form;  J_c v = 0;  J_c a = -gamma   (gamma = J_c_dot v, from classical accelerations)

then the equations of motion of the tree with the closure forces ``lambda``::

    M a + h = rnea(q, v, a) = S^T tau + J_c^T lambda

are solved for the motor (and tool) torques ``tau`` and the nine closure forces at once (a
square system: nv unknowns). :func:`check_with_constraint_dynamics` runs the torques forward
through Pinocchio's ``constraintDynamics`` and returns the accelerations it finds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinarms.robots.delta.errors import DeltaInputError
from pinarms.robots.delta.kinematics import inverse_position
from pinarms.robots.delta.model import DeltaRobot

__all__ = ["ClosedChainState", "closed_chain_state", "motor_torques", "check_with_constraint_dynamics"]


@dataclass(frozen=True)
class ClosedChainState:
    """Configurations, velocities and accelerations of the tree, (N, nq) / (N, nv), satisfying the closures."""

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray


def _samples(values, n: int | None, what: str) -> np.ndarray:
    arr = np.atleast_2d(np.asarray(values, dtype=float))
    if arr.ndim != 2 or arr.shape[1] != 3 or (n is not None and len(arr) != n) or not np.all(np.isfinite(arr)):
        raise DeltaInputError(f"{what} must be finite, of shape (N, 3) with one row per sample, got {np.shape(values)}")
    return arr


def _drift(delta: DeltaRobot, data: pin.Data, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``gamma = J_c_dot v`` of the point closures: relative classical acceleration at zero ``a``, in frame1's axes."""
    model = delta.model
    pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
    pin.updateFramePlacements(model, data)
    out = []
    for c in delta.closures.closures:
        f1, f2 = model.getFrameId(c.frame1), model.getFrameId(c.frame2)
        acc = [pin.getFrameClassicalAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED).linear for f in (f1, f2)]
        out.append(data.oMf[f1].rotation.T @ (acc[0] - acc[1]))
    return np.concatenate(out)


def closed_chain_state(delta: DeltaRobot, p, pd, pdd, *, branch: int = 0) -> ClosedChainState:
    """The tree's state along platform positions ``p`` [m], velocities ``pd`` [m/s], accelerations ``pdd`` [m/s^2].

    The tool axis (if any) stays at 0. Raises :class:`~.errors.DeltaUnreachable` for an unreachable ``p``.
    """
    p = _samples(p, None, "p")
    pd, pdd = _samples(pd, len(p), "pd"), _samples(pdd, len(p), "pdd")
    theta = np.atleast_2d(inverse_position(delta.geometry, p, branch=branch))
    if np.isnan(theta).any():
        row = int(np.flatnonzero(np.isnan(theta).any(axis=1))[0])
        inverse_position(delta.geometry, p[row], branch=branch)   # raises DeltaUnreachable naming the point
    q = np.atleast_2d(delta.configuration(theta))
    nv = delta.model.nv
    known = delta.platform_q if delta.tool_q is None else np.append(delta.platform_q, delta.tool_q)
    rest = np.setdiff1d(np.arange(nv), known)
    v, a = np.zeros((len(p), nv)), np.zeros((len(p), nv))
    data = delta.model.createData()
    for n in range(len(p)):
        jc = delta.constraint_jacobian(q[n])
        v[n, delta.platform_q] = pd[n]
        v[n, rest] = -np.linalg.solve(jc[:, rest], jc[:, delta.platform_q] @ pd[n])
        gamma = _drift(delta, data, q[n], v[n])
        a[n, delta.platform_q] = pdd[n]
        a[n, rest] = -np.linalg.solve(jc[:, rest], jc[:, delta.platform_q] @ pdd[n] + gamma)
    return ClosedChainState(q, v, a)


def motor_torques(delta: DeltaRobot, state: ClosedChainState) -> tuple[np.ndarray, np.ndarray]:
    """Motor torques [N m] (N, 3) and closure forces [N] (N, 9) (frame1's axes) along ``state``.

    With the fourth axis, its torque is an unknown of the same system (the tool's inertia
    held at zero angular acceleration) and is not returned.
    """
    model, data = delta.model, delta.model.createData()
    actuated = delta.motor_q if delta.tool_q is None else np.append(delta.motor_q, delta.tool_q)
    sel = np.zeros((len(actuated), model.nv))
    sel[np.arange(len(actuated)), actuated] = 1.0
    tau = np.empty((len(state.q), 3))
    lam = np.empty((len(state.q), 9))
    for n, (q, v, a) in enumerate(zip(state.q, state.v, state.a)):
        full = pin.rnea(model, data, q, v, a)
        jc = delta.constraint_jacobian(q)
        x = np.linalg.solve(np.hstack([sel.T, jc.T]), full)
        tau[n], lam[n] = x[:3], x[len(actuated):]
    return tau, lam


def check_with_constraint_dynamics(delta: DeltaRobot, state: ClosedChainState, tau: np.ndarray) -> np.ndarray:
    """Accelerations (N, nv) Pinocchio's ``constraintDynamics`` gives with ``tau`` on the motors (tool free)."""
    model, data = delta.model, delta.model.createData()
    cdatas = [cm.createData() for cm in delta.constraint_models]
    pin.initConstraintDynamics(model, data, delta.constraint_models, cdatas)
    settings = pin.ProximalSettings(1e-14, 1e-12, 50)
    out = np.empty_like(state.a)
    for n, (q, v) in enumerate(zip(state.q, state.v)):
        full = np.zeros(model.nv)
        full[delta.motor_q] = tau[n]
        out[n] = pin.constraintDynamics(model, data, q, v, full, delta.constraint_models, cdatas, settings)
    return out
