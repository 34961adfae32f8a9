"""An IK target checked: a tool pose (frame → base) or, for position-only IK, a tool position.

A pose is a homogeneous transform ``(4, 4)`` or a batch ``(N, 4, 4)`` [m]: finite, its
rotation block a proper rotation (orthonormal within 1e-6, determinant +1), its last row
``(0, 0, 0, 1)``. Position-only IK also takes a position ``(3,)`` / ``(N, 3)`` [m], turned
into a pose with the identity rotation. One plain pose takes a fast path in Python floats
(numpy calls cost µs each; an IK call on one pose is tens of µs).
"""

import math

import numpy as np
from numpy.typing import ArrayLike

from pinarms.robots._checks import real_array
from pinarms.errors import InvalidInput

__all__ = ["check_ik_target"]

_F64 = np.dtype(np.float64)


def check_ik_target(target: ArrayLike, *, position_only: bool = False) -> tuple[np.ndarray, bool]:
    """The targets as ``(N, 4, 4)`` and whether a single target was given (see :meth:`pinarms.robots.Robot.check_target`).

    Raises:
        InvalidInput: wrong shape, non-finite entries, or a rotation block that is not a
            proper rotation (orthonormal within 1e-6, determinant +1).
    """
    if target.__class__ is np.ndarray and target.shape == (4, 4) and target.dtype is _F64:
        m = target.tolist()  # one pose: the checks below in plain floats (numpy calls cost µs each)
        (a, b, c, x), (d, e, f, y), (g, h, i, z), last = m
        if all(map(math.isfinite, (a, b, c, d, e, f, g, h, i, x, y, z))) and last == [0.0, 0.0, 0.0, 1.0]:
            ortho = max(
                abs(a * a + b * b + c * c - 1.0), abs(d * d + e * e + f * f - 1.0), abs(g * g + h * h + i * i - 1.0),
                abs(a * d + b * e + c * f), abs(a * g + b * h + c * i), abs(d * g + e * h + f * i),
            )
            det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
            if ortho <= 1e-6 and det > 0.0:
                return target[None], True
    arr = real_array(target, "IK target")
    if position_only and arr.shape[-1:] == (3,) and arr.ndim in (1, 2):
        single = arr.ndim == 1
        pts = arr.reshape(-1, 3)
        arr = np.tile(np.eye(4), (pts.shape[0], 1, 1))
        arr[:, :3, 3] = pts
    else:
        single = arr.ndim == 2
        if single:
            arr = arr[None]
        if arr.ndim != 3 or arr.shape[1:] != (4, 4):
            extra = " or a position (3,)" if position_only else ""
            hint = (
                "; for a position without orientation use Robot.ik(position, position_only=True)"
                if not position_only and np.shape(target)[-1:] == (3,)
                else ""
            )
            raise InvalidInput(
                f"IK target must be a pose of shape (4, 4) or (N, 4, 4){extra}, got shape {np.shape(target)}{hint}"
            )
    if arr.shape[0] == 0:
        return arr, single
    if not np.all(np.isfinite(arr)):
        raise InvalidInput("IK target holds a non-finite value (NaN or inf)")
    if not position_only or not single or np.shape(target) == (4, 4):
        R = arr[:, :3, :3]
        ortho = np.abs(R @ np.swapaxes(R, 1, 2) - np.eye(3)).max(axis=(1, 2))
        det = np.linalg.det(R)
        bad = np.flatnonzero((ortho > 1e-6) | (det < 0.0))
        if bad.size:
            k = int(bad[0])
            raise InvalidInput(
                f"IK target {k}: its rotation block is not a proper rotation "
                f"(|R Rᵀ − I| = {ortho[k]:.3g}, det = {det[k]:.6g}); pass a homogeneous transform"
            )
        if np.abs(arr[:, 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max() > 1e-9:
            raise InvalidInput("IK target: the last row of a homogeneous transform must be (0, 0, 0, 1)")
    return arr, single
