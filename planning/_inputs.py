"""Shared argument checks of the trajectory constructors (private).

Every check raises :class:`pinarms.planning.errors.TrajectoryError` naming the argument and the
offending value, so that callers see *what* to fix rather than a numpy broadcasting error.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pinarms.planning.errors import TrajectoryError


def finite_array(value: Any, what: str) -> np.ndarray:
    """``value`` as a float64 array; raises if it is not numeric or holds NaN/inf."""
    try:
        if np.iscomplexobj(value):
            raise TypeError("complex values")
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise TrajectoryError(f"{what} must be numeric (real), got {value!r}") from exc
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        index = tuple(int(i) for i in bad)
        raise TrajectoryError(
            f"{what} must be finite; entry {index if arr.ndim else ()} is {float(arr[tuple(bad)])!r}"
        )
    return arr


def knot_times(times: Any, what: str = "times", minimum: int = 2) -> np.ndarray:
    """Strictly increasing knot times (s), at least ``minimum`` of them, as a (m+1,) array."""
    t = finite_array(times, what)
    if t.ndim != 1:
        raise TrajectoryError(f"{what} must be a 1-D sequence of instants (s), got shape {t.shape}")
    if t.size < minimum:
        raise TrajectoryError(f"{what} needs at least {minimum} instants, got {t.size}: {t.tolist()}")
    steps = np.diff(t)
    if np.any(steps <= 0.0):
        i = int(np.argmax(steps <= 0.0))
        raise TrajectoryError(
            f"{what} must be strictly increasing; {what}[{i + 1}] = {float(t[i + 1])!r} does not come "
            f"after {what}[{i}] = {float(t[i])!r}"
        )
    return t


def knot_times_batch(times: Any, what: str = "times", minimum: int = 2) -> np.ndarray:
    """Knot times of P trajectories as a (P, m+1) array, every row strictly increasing (s)."""
    t = finite_array(times, what)
    if t.ndim != 2:
        raise TrajectoryError(
            f"{what} must be a 2-D array (P individuals, m+1 instants) (s), got shape {t.shape}; "
            "for a single trajectory use the constructor without _batch"
        )
    if t.shape[1] < minimum:
        raise TrajectoryError(f"{what} needs at least {minimum} instants per row, got shape {t.shape}")
    steps = np.diff(t, axis=1)
    if np.any(steps <= 0.0):
        p, i = (int(k) for k in np.argwhere(steps <= 0.0)[0])
        raise TrajectoryError(
            f"{what} rows must be strictly increasing; {what}[{p}, {i + 1}] = {float(t[p, i + 1])!r} does not "
            f"come after {what}[{p}, {i}] = {float(t[p, i])!r}"
        )
    return t


def scalar(value: Any, what: str) -> float:
    """A finite real number given as a Python/numpy scalar or a 0-d array."""
    arr = finite_array(value, what)
    if arr.ndim != 0:
        raise TrajectoryError(f"{what} must be a single number, got shape {arr.shape}: {value!r}")
    return float(arr)


def durations(values: Any, what: str = "durations") -> np.ndarray:
    """Positive segment durations (s) as a (m,) array."""
    h = finite_array(values, what)
    if h.ndim != 1 or h.size == 0:
        raise TrajectoryError(f"{what} must be a non-empty 1-D sequence (s), got shape {h.shape}")
    if np.any(h <= 0.0):
        i = int(np.argmax(h <= 0.0))
        raise TrajectoryError(f"{what} must be positive; {what}[{i}] = {float(h[i])!r}")
    return h


def via_positions(positions: Any, n_points: int, what: str = "positions") -> np.ndarray:
    """Via positions as (n_points, n_joints); a 1-D input is one joint, shape (n_points, 1)."""
    q = finite_array(positions, what)
    if q.ndim == 1:
        q = q[:, None]
    if q.ndim != 2:
        raise TrajectoryError(f"{what} must be (points,) or (points, joints), got shape {q.shape}")
    if q.shape[0] != n_points:
        raise TrajectoryError(
            f"{what} has {q.shape[0]} points but there are {n_points} times; give one row per instant"
        )
    if q.shape[1] == 0:
        raise TrajectoryError(f"{what} has no joints (shape {q.shape})")
    return q


def per_joint(value: Any, n_joints: int, what: str, *, positive: bool = False) -> np.ndarray:
    """A scalar or (n_joints,) value broadcast to (n_joints,)."""
    if type(value) in (int, float) and math.isfinite(value) and not (positive and value <= 0):
        return np.full(n_joints, float(value))
    v = finite_array(value, what)
    if v.ndim > 1 or (v.ndim == 1 and v.size not in (1, n_joints)):
        raise TrajectoryError(f"{what} must be a scalar or have {n_joints} entries, got shape {v.shape}")
    v = np.broadcast_to(v.reshape(-1) if v.ndim else v, (n_joints,)).astype(float)
    if positive and np.any(v <= 0.0):
        i = int(np.argmax(v <= 0.0))
        raise TrajectoryError(f"{what} must be positive; entry {i} is {float(v[i])!r}")
    return v


def per_point(value: Any, n_points: int, n_joints: int, what: str) -> np.ndarray:
    """Per-via-point values (velocities, accelerations) as (n_points, n_joints).

    Accepts a scalar, a (n_points,) array for one joint, or the full (n_points, n_joints).
    """
    v = finite_array(value, what)
    if v.ndim == 0:
        return np.full((n_points, n_joints), float(v))
    if v.ndim == 1 and n_joints == 1 and v.size == n_points:
        return v[:, None].copy()
    if v.shape != (n_points, n_joints):
        raise TrajectoryError(
            f"{what} must have shape ({n_points}, {n_joints}) (one row per via point), got {v.shape}"
        )
    return v.copy()
