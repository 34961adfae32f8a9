"""Candidate base placements of a layout search, and the frames they define (stage 0 of
:func:`pinarms.optim.layout.search_layout`): grids, seeded random samples, ``base_to_world`` and the
points moved into each candidate's base frame. Units: m, rad.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pinarms.optim.types import AxisRange, Placement

from pinarms.optim.caps import MAX_AXIS_VALUES, MAX_PLACEMENTS, count_setting
from pinarms.optim.errors import SettingOutOfRange
from pinarms.optim.status import Status
from pinarms.errors import InvalidInput

__all__ = ["CandidateFailure", "FAILURES", "AXES", "grid_candidates", "random_candidates", "base_to_world",
           "points_in_base_frame", "PPM_RTOL"]



class CandidateFailure(Status):
    """Why one candidate placement of a layout search fails (the value is the word printed)."""

    #: a pick, place or lift point is beyond the arm's reach from the placement
    UNREACHABLE = "unreachable"
    #: a point is within reach but needs a joint outside its limits
    JOINT_LIMIT = "joint limit"
    #: a pick or place is closer than ``min_margin`` to the edge of the workspace
    BOUNDARY = "boundary"
    #: no cycle keeps the clearance from the cell's fixtures and other arms
    COLLISION = "collision"
    #: no timing meets the limits
    TIMING = "timing"
    #: not planned: its proven lower bound cannot beat the best ones (``LayoutRequest(bound=True)``)
    OUTRANKED = "outranked"


#: The failures in the order they are checked.
FAILURES = tuple(CandidateFailure)
#: Names of the placement coordinates (columns of a candidate array).
AXES = ("x", "y", "z", "yaw")
#: Relative tolerance under which two picks-per-minute figures count as tied (the lower index wins).
PPM_RTOL = 1e-9


# ------------------------------------------------------------------ candidates
def _axis(value: Any, name: str) -> np.ndarray:
    """One coordinate: a number (fixed) or ``(lo, hi, step)`` (lo, lo+step, …, up to hi inclusive)."""
    unit = "rad" if name == "yaw" else "m"
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        if not np.isfinite(value):
            raise InvalidInput(f"{name} must be finite, got {value!r}")
        return np.array([float(value)])
    try:
        lo, hi, step = (float(v) for v in value)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{name} must be a number or (lo, hi, step) in {unit}, got {value!r}") from exc
    if not (np.isfinite(lo) and np.isfinite(hi) and np.isfinite(step)) or step <= 0 or hi < lo:
        raise InvalidInput(f"{name} = ({lo}, {hi}, {step}): need finite lo <= hi and step > 0 [{unit}]")
    span = (hi - lo) / step  # may be inf for a tiny step: compared before any int()
    if not span < MAX_AXIS_VALUES:
        raise SettingOutOfRange(f"{name} = ({lo}, {hi}, {step}) gives more than {MAX_AXIS_VALUES:,} values, the most "
                                "one grid coordinate may have: use a larger step")
    count = int(np.floor(span + 1e-9)) + 1
    return lo + step * np.arange(count)


def grid_candidates(x: AxisRange, y: AxisRange, z: AxisRange = 0.0, yaw: AxisRange = 0.0) -> np.ndarray:
    """Base placements ``(M, 4)`` = every combination of the coordinates' values.

    Each coordinate is a number or ``(lo, hi, step)`` [m, yaw in rad]; rows are ordered with
    ``x`` varying slowest and ``yaw`` fastest.
    """
    axes = [_axis(v, n) for v, n in zip((x, y, z, yaw), AXES)]
    count = math.prod(int(a.size) for a in axes)  # Python ints: no wrap-around
    if count > MAX_PLACEMENTS:
        raise SettingOutOfRange(f"the grid has {count:,} placements, more than the {MAX_PLACEMENTS:,} a layout search "
                                "takes: use larger steps or random_candidates")
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.column_stack([m.reshape(-1) for m in mesh])


def random_candidates(n: int, x: AxisRange, y: AxisRange, z: AxisRange = 0.0, yaw: AxisRange = 0.0,
                      seed: int = 0) -> np.ndarray:
    """``n`` base placements ``(n, 4)`` uniform within bounds, from ``numpy.random.default_rng(seed)``.

    Each coordinate is a number (fixed) or ``(lo, hi)`` [m, yaw in rad]; the draws are made
    column by column in the order x, y, z, yaw (fixed coordinates draw nothing).
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise InvalidInput(f"n must be a positive number of placements, got {n!r}")
    n = count_setting(n, "n (random placements)", 1, MAX_PLACEMENTS)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInput(f"seed must be an integer >= 0, got {seed!r}")
    rng = np.random.default_rng(int(seed))
    out = np.empty((int(n), 4))
    for k, (value, name) in enumerate(zip((x, y, z, yaw), AXES)):
        if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
            if not np.isfinite(value):
                raise InvalidInput(f"{name} must be finite, got {value!r}")
            out[:, k] = float(value)
            continue
        try:
            lo, hi = (float(v) for v in value)
        except (TypeError, ValueError) as exc:
            raise InvalidInput(f"{name} must be a number or (lo, hi), got {value!r}") from exc
        if not (np.isfinite(lo) and np.isfinite(hi)) or hi < lo:
            raise InvalidInput(f"{name} = ({lo}, {hi}): need finite lo <= hi")
        out[:, k] = rng.uniform(lo, hi, size=int(n))
    return out


def base_to_world(placement: Placement) -> np.ndarray:
    """``T_base_to_world (4, 4)`` of a placement ``(x, y, z, yaw)`` (or ``(N, 4, 4)`` for ``(N, 4)``)."""
    P = np.asarray(placement, dtype=float)
    single = P.ndim == 1
    P = np.atleast_2d(P)
    c, s = np.cos(P[:, 3]), np.sin(P[:, 3])
    T = np.zeros((P.shape[0], 4, 4))
    T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = c, -s, s, c
    T[:, 2, 2] = T[:, 3, 3] = 1.0
    T[:, :3, 3] = P[:, :3]
    return T[0] if single else T


def points_in_base_frame(points: np.ndarray, placements: np.ndarray) -> np.ndarray:
    """Points ``(K, 3)`` of the line frame in the base frames of ``(M, 4)`` placements: ``(M, K, 3)``.

    ``p_base = R_z(-yaw) (p - (x, y, z))``, the inverse of :func:`base_to_world`.
    """
    d = points[None, :, :] - placements[:, None, :3]
    c, s = np.cos(placements[:, 3])[:, None], np.sin(placements[:, 3])[:, None]
    out = np.empty_like(d)
    out[..., 0] = c * d[..., 0] + s * d[..., 1]
    out[..., 1] = -s * d[..., 0] + c * d[..., 1]
    out[..., 2] = d[..., 2]
    return out
