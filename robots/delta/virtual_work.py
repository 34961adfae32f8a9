"""Motor torques of a delta by virtual work on the closed form: the independent check of :mod:`.dynamics`.

Every joint frame of the tree is written from the closed form alone (motor angles by
:func:`~.kinematics.inverse_position`, elbow angles from the forearm direction, the platform's
translation); each body's mass, centre of mass and inertia are read from the model. Along a
platform motion ``p(t)`` (a function of time), the motor torques are::

    tau_i = sum_b  m_b (a_b - g) . dc_b/dtheta_i  +  (I_b w_dot_b + w_b x I_b w_b) . dw_b/dtheta_dot_i

with velocities and accelerations by central differences in time and the partial derivatives
by central differences in the motor angles. No Pinocchio algorithm is used (no RNEA, no
constraint Jacobian): only the closed form and the inertial parameters.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from pinarms.robots.delta.kinematics import forward_position, inverse_position
from pinarms.robots.delta.model import DeltaRobot

__all__ = ["body_frames", "virtual_work_torques"]

_G = np.array([0.0, 0.0, -9.81])


def _rot_y(a: np.ndarray) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def _rot_z(a: np.ndarray) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def body_frames(delta: DeltaRobot, theta: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """World pose ``(R (N, 3, 3), origin (N, 3))`` of every moving joint frame, by the closed form alone."""
    g = delta.geometry
    th = np.atleast_2d(theta)
    p = forward_position(g, th)
    out = {}
    for i in range(3):
        yaw = _rot_z(np.full(len(th), g.azimuths[i]))
        e = g.radial[i]
        r_arm = yaw @ _rot_y(th[:, i])
        out[f"leg{i + 1}_motor"] = (r_arm, np.repeat((g.base_radius * e)[None], len(th), 0))
        elbow = g.base_radius * e + g.upper_arm * r_arm[:, :, 0]
        rod = (p + g.platform_radius * e - elbow) / g.forearm
        local = np.einsum("nji,nj->ni", r_arm, rod)                       # rod in the upper arm's axes
        fold, swing = np.arctan2(-local[:, 2], local[:, 0]), np.arcsin(np.clip(local[:, 1], -1, 1))
        r_fold = r_arm @ _rot_y(fold)
        out[f"leg{i + 1}_elbow_fold"] = (r_fold, elbow)
        out[f"leg{i + 1}_elbow_swing"] = (r_fold @ _rot_z(swing), elbow)
    eye = np.repeat(np.eye(3)[None], len(th), 0)
    out["platform_x"] = (eye, p * np.array([1.0, 0.0, 0.0]))
    out["platform_y"] = (eye, p * np.array([1.0, 1.0, 0.0]))
    out["platform_z"] = (eye, p)
    if delta.has_tool_axis:
        out["tool"] = (eye, p)
    return out


def _kinematics(delta: DeltaRobot, theta: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per body: world rotation, centre of mass, and world inertia about it."""
    model = delta.model
    out = {}
    for name, (rot, origin) in body_frames(delta, theta).items():
        inertia = model.inertias[model.getJointId(name)]
        com = origin + rot @ inertia.lever
        out[name] = (rot, com, rot @ inertia.inertia @ np.swapaxes(rot, 1, 2), inertia.mass)
    return out


def _omega(r_next: np.ndarray, r_prev: np.ndarray, step: float) -> np.ndarray:
    """World angular velocity from rotations one ``step`` on each side (central difference)."""
    rel = r_next @ np.swapaxes(r_prev, 1, 2)
    return Rotation.from_matrix(rel).as_rotvec() / (2.0 * step)


def virtual_work_torques(delta: DeltaRobot, p_of_t: Callable[[np.ndarray], np.ndarray], t: np.ndarray, *,
                         dt: float = 1e-4, dtheta: float = 1e-6) -> np.ndarray:
    """Motor torques [N m] (N, 3) along ``p_of_t`` (times (N,) [s] -> platform centres (N, 3) [m]) at times ``t``."""
    t = np.asarray(t, dtype=float)
    th = {k: inverse_position(delta.geometry, p_of_t(t + k * dt)) for k in (-2, -1, 0, 1, 2)}
    kin = {k: _kinematics(delta, th[k]) for k in th}
    tau = np.zeros((len(t), 3))
    partial = {}
    for i in range(3):
        step = np.zeros(3)
        step[i] = dtheta
        partial[i] = (_kinematics(delta, th[0] + step), _kinematics(delta, th[0] - step))
    for name, (rot, com, inertia, mass) in kin[0].items():
        acc = (kin[1][name][1] - 2.0 * com + kin[-1][name][1]) / dt ** 2
        w = _omega(kin[1][name][0], kin[-1][name][0], dt)
        w_dot = (_omega(kin[2][name][0], kin[0][name][0], dt) - _omega(kin[0][name][0], kin[-2][name][0], dt)) / (2 * dt)
        force = mass * (acc - _G)
        moment = np.einsum("nij,nj->ni", inertia, w_dot) + np.cross(w, np.einsum("nij,nj->ni", inertia, w))
        for i in range(3):
            plus, minus = partial[i][0][name], partial[i][1][name]
            dc = (plus[1] - minus[1]) / (2.0 * dtheta)
            dw = _omega(plus[0], minus[0], dtheta)
            tau[:, i] += np.einsum("ni,ni->n", force, dc) + np.einsum("ni,ni->n", moment, dw)
    return tau
