"""Rotations (SO(3)), vectorised over batches: the one module of rotation helpers.

exp and log of SO(3), the hat and vee maps, the angle of a rotation, rotations about an
axis, from unit quaternions, about z, and a frame whose z is a given axis. Every package
above ``robots`` takes its rotations from here.

Rotation vectors ``phi`` (N, 3) [rad] give ``R = exp([phi]x)`` (Rodrigues' formula, with
Taylor series below 1e-4 rad); ``log`` returns the rotation vector of angle in [0, π]
(near π the axis is taken from the symmetric part of R, so it stays accurate there).
"""

from __future__ import annotations

import numpy as np

__all__ = ["hat", "vee", "exp", "log", "angle", "about", "from_quaternion", "rot_z", "frame_z_to"]


def hat(v: np.ndarray) -> np.ndarray:
    """Skew matrices (..., 3, 3) of vectors (..., 3): ``hat(v) @ x == cross(v, x)``."""
    v = np.asarray(v, dtype=float)
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def vee(M: np.ndarray) -> np.ndarray:
    """Vector (..., 3) of the skew-symmetric part of matrices (..., 3, 3)."""
    return 0.5 * np.stack([M[..., 2, 1] - M[..., 1, 2], M[..., 0, 2] - M[..., 2, 0], M[..., 1, 0] - M[..., 0, 1]],
                          axis=-1)


def exp(phi: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of rotation vectors (..., 3) [rad]."""
    phi = np.asarray(phi, dtype=float)
    th2 = np.sum(phi * phi, axis=-1)
    th = np.sqrt(th2)
    small = th < 1e-4
    safe = np.where(small, 1.0, th)
    a = np.where(small, 1.0 - th2 / 6.0 + th2 * th2 / 120.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - th2 / 24.0 + th2 * th2 / 720.0, (1.0 - np.cos(safe)) / (safe * safe))
    K = hat(phi)
    return np.eye(3) + a[..., None, None] * K + b[..., None, None] * (K @ K)


def angle(R: np.ndarray) -> np.ndarray:
    """Rotation angle(s) [rad] in [0, π] of matrices (..., 3, 3), accurate at small angles too."""
    R = np.asarray(R, dtype=float)
    c = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    s = np.linalg.norm(vee(R), axis=-1)
    return np.arctan2(s, np.clip(c, -1.0, 1.0))


def log(R: np.ndarray) -> np.ndarray:
    """Rotation vectors (..., 3) [rad], angle in [0, π], of matrices (..., 3, 3)."""
    R = np.asarray(R, dtype=float)
    th = angle(R)
    v = vee(R)  # = sin(th) * axis
    s = np.sin(th)
    small = th < 1e-4
    ratio = np.where(small, 1.0 + th * th / 6.0, th / np.where(small, 1.0, np.maximum(s, 1e-300)))
    out = ratio[..., None] * v
    near_pi = th > np.pi - 1e-3
    if np.any(near_pi):
        # axis from the symmetric part: R + I - (1 - cos th) ... = 2 cos^2(th/2) I + ..., use B = (R + R^T)/2 - cos(th) I
        Rn = R[near_pi]
        thn = th[near_pi]
        B = 0.5 * (Rn + np.swapaxes(Rn, -1, -2)) - np.cos(thn)[:, None, None] * np.eye(3)  # = (1 - cos) a a^T
        k = np.argmax(np.diagonal(B, axis1=-2, axis2=-1), axis=-1)
        col = np.take_along_axis(B, k[:, None, None].repeat(3, axis=1), axis=2)[..., 0]
        axis = col / np.linalg.norm(col, axis=-1, keepdims=True)
        vn = v[near_pi]
        sign = np.where(np.sum(axis * vn, axis=-1) < 0.0, -1.0, 1.0)
        out[near_pi] = (sign * thn)[:, None] * axis
    return out


def about(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rodrigues rotations ``(K, 3, 3)`` about the unit ``axis`` (3,) by ``angles (K,)`` [rad]."""
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(angles)[:, None, None], np.cos(angles)[:, None, None]
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def from_quaternion(q: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(N, 3, 3)`` of unit quaternions ``(N, 4)`` stored ``(x, y, z, w)``."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    R = np.empty((q.shape[0], 3, 3))
    R[:, 0, 0] = 1 - 2 * (y * y + z * z)
    R[:, 0, 1] = 2 * (x * y - z * w)
    R[:, 0, 2] = 2 * (x * z + y * w)
    R[:, 1, 0] = 2 * (x * y + z * w)
    R[:, 1, 1] = 1 - 2 * (x * x + z * z)
    R[:, 1, 2] = 2 * (y * z - x * w)
    R[:, 2, 0] = 2 * (x * z - y * w)
    R[:, 2, 1] = 2 * (y * z + x * w)
    R[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def rot_z(angle: float) -> np.ndarray:
    """The rotation (3, 3) by ``angle`` [rad] about z."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def frame_z_to(axis: np.ndarray) -> np.ndarray:
    """A fixed rotation (3, 3) whose third column is the unit vector of ``axis``.

    Its x is ``helper × z`` normalised, with ``helper`` the x axis unless z is within
    about 25° of it (then the y axis); its y is ``z × x``.
    """
    z = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])
