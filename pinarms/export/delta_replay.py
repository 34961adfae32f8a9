"""A delta's motion replayed in MuJoCo through its exported MJCF, and MuJoCo's motor torques.

:func:`replay_delta_in_mujoco` gives MuJoCo only the motor angles of each sample and lets it
solve every passive joint itself: Newton's projection onto the MJCF's equality constraints
(MuJoCo's ``efc_pos`` and dense ``efc_J`` of the ``connect`` rows), each sample starting from
MuJoCo's previous solution. The platform body's position is then compared with pinarms'
closed-form forward kinematics. :func:`mujoco_motor_torques` is the MuJoCo route to the torques
of :func:`pinarms.robots.delta.motor_torques`: MuJoCo's inverse dynamics of the tree
(``mj_inverse`` with constraints off) balanced by the motors and the ``connect`` forces.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from pinarms.robots.delta import ClosedChainState, DeltaRobot, ProjectionFailed, forward_position
from pinarms.errors import ModelError

__all__ = ["DeltaReplay", "replay_delta_in_mujoco", "mujoco_motor_torques"]


@dataclass(frozen=True)
class DeltaReplay:
    """Per sample: platform position in MuJoCo [m] (N, 3), its distance to pinarms' FK [m], the largest
    equality-constraint violation MuJoCo reports [m]."""

    platform: np.ndarray
    platform_error: np.ndarray
    closure_violation: np.ndarray


def _mujoco(mjcf: str | os.PathLike, delta: DeltaRobot):
    try:
        import mujoco
    except ImportError as exc:
        raise ModelError("the MuJoCo replay needs MuJoCo's Python package: pip install mujoco") from exc
    try:
        model = mujoco.MjModel.from_xml_path(os.fspath(mjcf))
    except Exception as exc:  # MuJoCo raises ValueError with its own message
        raise ModelError(f"MuJoCo refuses {os.fspath(mjcf)!r}: {' '.join(str(exc).split())}") from exc
    model.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    # MuJoCo's coordinates in pinarms' order (every joint of the family is a hinge or a slide: one qpos, one dof)
    index = np.array([model.joint(delta.model.names[j]).qposadr[0] for j in range(1, delta.model.njoints)])
    return mujoco, model, mujoco.MjData(model), index


def _equality_rows(mujoco, data) -> np.ndarray:
    return np.flatnonzero(data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY)


def replay_delta_in_mujoco(delta: DeltaRobot, mjcf: str | os.PathLike, theta, *, tol: float = 1e-12,
                           max_iter: int = 50) -> DeltaReplay:
    """Replay motor angles ``theta`` (N, 3) [rad] in MuJoCo (passive joints solved by MuJoCo's constraints).

    The first sample starts from pinarms' home configuration, each next one from MuJoCo's previous solution.

    Raises:
        ProjectionFailed: MuJoCo's constraints were not met within ``tol`` for a sample.
    """
    mujoco, model, data, index = _mujoco(mjcf, delta)
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    motors, passive = index[delta.motor_q], index[delta.passive_q]
    data.qpos[index] = delta.home()
    platform_body = model.body("platform_link").id
    out, violation = np.empty((len(theta), 3)), np.empty(len(theta))
    for n, th in enumerate(theta):
        data.qpos[motors] = th
        for _ in range(max_iter):
            mujoco.mj_forward(model, data)
            rows = _equality_rows(mujoco, data)
            if np.abs(data.efc_pos[rows]).max() <= tol:
                break
            jac = data.efc_J.reshape(data.nefc, model.nv)[rows][:, passive]   # hinge/slide: dof = qpos index
            data.qpos[passive] -= np.linalg.lstsq(jac, data.efc_pos[rows], rcond=None)[0]
        else:
            raise ProjectionFailed(f"MuJoCo's constraints not met for sample {n} (theta = {th.tolist()} rad): "
                                   f"violation {np.abs(data.efc_pos[rows]).max():.3g} m")
        out[n] = data.xpos[platform_body]
        violation[n] = np.abs(data.efc_pos[rows]).max()
    error = np.linalg.norm(out - forward_position(delta.geometry, theta), axis=1)
    return DeltaReplay(out, error, violation)


def mujoco_motor_torques(delta: DeltaRobot, mjcf: str | os.PathLike, state: ClosedChainState) -> np.ndarray:
    """Motor torques [N m] (N, 3) along ``state`` by MuJoCo: ``mj_inverse`` of the tree (constraints off),
    balanced by the motors (and the tool axis) and the ``connect`` forces on MuJoCo's constraint Jacobian."""
    mujoco, model, data, index = _mujoco(mjcf, delta)
    actuated = delta.motor_q if delta.tool_q is None else np.append(delta.motor_q, delta.tool_q)
    sel = np.zeros((len(actuated), model.nv))
    sel[np.arange(len(actuated)), index[actuated]] = 1.0
    tau = np.empty((len(state.q), 3))
    for n, (q, v, a) in enumerate(zip(state.q, state.v, state.a)):
        data.qpos[index], data.qvel[index], data.qacc[index] = q, v, a
        mujoco.mj_forward(model, data)
        rows = _equality_rows(mujoco, data)
        jac = data.efc_J.reshape(data.nefc, model.nv)[rows]
        flags = int(model.opt.disableflags)
        model.opt.disableflags = flags | int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
        data.qacc[index] = a
        mujoco.mj_inverse(model, data)
        model.opt.disableflags = flags
        x = np.linalg.solve(np.hstack([sel.T, jac.T]), data.qfrc_inverse.copy())
        tau[n] = x[:3]
    return tau
