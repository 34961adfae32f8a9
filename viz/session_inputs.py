"""The user's values checked and turned into session records (boxes, trajectories, workspaces, histories).

What :class:`pinarms.viz.Session`'s ``add_*`` methods take is checked here: numbers real and finite
(±inf only where a history allows it), shapes, rigid poses, JSON-able metadata; every array
kept is a fresh read-only float64 copy. Errors are :class:`InvalidInput` naming the value.

Frames and units: positions in metres, angles in radians, times in seconds.
"""

from __future__ import annotations

import json
import math
from typing import Any, Mapping, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput

from pinarms.viz.session_archive import F8
from pinarms.viz.session_records import BoxObject, HistoryRecord, RobotEntry, TrajectoryRecord, WorkspaceRecord, check_name

if TYPE_CHECKING:
    from pinarms.optim.ga.engine import GAHistory, GAResult
    from pinarms.robots.reach.workspace import Workspace
    from pinarms.planning.trajectory import Trajectory

__all__ = ["MAX_TRAJECTORY_SAMPLES", "json_normalised", "real_array", "float_array", "pose_array", "box_record",
           "trajectory_record", "workspace_record", "history_record"]

MAX_TRAJECTORY_SAMPLES = 2_000_000
"""Most samples :meth:`Session.add_trajectory` takes from a Trajectory (duration × hz)."""


def json_normalised(obj: object, what: str) -> Any:
    """``obj`` as it will come back from JSON (tuples → lists); rejects NaN and non-JSON values."""
    try:
        return json.loads(json.dumps(obj, allow_nan=False, ensure_ascii=False).encode("utf-8"))
    except (TypeError, ValueError, RecursionError) as exc:  # UnicodeEncodeError (lone surrogates) is a ValueError
        raise InvalidInput(f"{what} must be JSON-able (dicts, lists, str, finite numbers, bool, None): {exc}") from exc


def real_array(values: ArrayLike, what: str) -> np.ndarray:
    """``values`` as a fresh float64 array; complex numbers and non-numbers raise InvalidInput."""
    try:
        if np.iscomplexobj(values):
            raise TypeError("complex numbers")
        return np.array(values, dtype=F8)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidInput(f"{what} must be numbers (real), got {type(values).__name__}") from exc


def float_array(values: ArrayLike, what: str, ndim: int, width: int | None = None, *, allow_inf: bool = False) -> np.ndarray:
    """A fresh, read-only, finite float64 array of ``ndim`` dims (last dim ``width``); ±inf allowed on request."""
    arr = real_array(values, what)
    if arr.ndim != ndim or (width is not None and arr.shape[-1] != width):
        shape = "(N,)" if ndim == 1 else f"(N, {width})"
        raise InvalidInput(f"{what} must have shape {shape}, got {arr.shape}")
    if np.any(np.isnan(arr)) if allow_inf else not np.all(np.isfinite(arr)):
        raise InvalidInput(f"{what} holds NaN{'' if allow_inf else ' or infinite'} values")
    arr.flags.writeable = False
    return arr


def pose_array(values: ArrayLike, what: str) -> np.ndarray:
    """``values`` (default identity) as a read-only rigid transform (4, 4), or InvalidInput naming ``what``."""
    T = real_array(np.eye(4) if values is None else values, what)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise InvalidInput(f"{what} must be a finite (4, 4) homogeneous transform, got shape {T.shape}")
    R = T[:3, :3]
    if not np.allclose(T[3], [0, 0, 0, 1]) or not np.allclose(R.T @ R, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0:
        raise InvalidInput(f"{what} must be a rigid transform (orthonormal rotation, last row 0 0 0 1)")
    T.flags.writeable = False
    return T


def box_record(name: str, size: ArrayLike, pose: ArrayLike, color: ArrayLike) -> BoxObject:
    """The static box ``name``: ``size`` (3,) positive edge lengths in m, ``pose`` (4, 4), ``color`` RGBA in [0, 1]."""
    size_arr = float_array(size, f"size of box {name!r}", 1, 3)
    if np.any(size_arr <= 0):
        raise InvalidInput(f"size of box {name!r} must be positive edge lengths in m, got {size_arr.tolist()}")
    try:
        rgba = tuple(float(c) for c in real_array(color, "color").ravel())
    except InvalidInput:
        rgba = ()
    if len(rgba) != 4 or not all(0.0 <= c <= 1.0 for c in rgba):
        raise InvalidInput(f"color of box {name!r} must be 4 RGBA values in [0, 1], got {color!r}")
    return BoxObject(name, size_arr, pose_array(pose, f"pose of box {name!r}"), rgba)


def trajectory_record(name: str, entry: RobotEntry, trajectory: Trajectory, hz: float) -> TrajectoryRecord:
    """The trajectory ``name`` of robot ``entry``: a ``planning.Trajectory`` sampled at ``hz``, or a ``(t, q)`` pair."""
    if isinstance(trajectory, tuple) and len(trajectory) == 2:
        t, q = trajectory
        definition, knots = None, None
    elif hasattr(trajectory, "sample") and hasattr(trajectory, "knot_times"):
        t, q, knots, definition = _sampled(name, trajectory, hz)
    else:
        raise InvalidInput(
            f"trajectory {name!r} must be a planning.Trajectory or a (t, q) pair of arrays, got {type(trajectory).__name__}"
        )
    t = float_array(t, f"t of trajectory {name!r}", 1)
    q_arr = real_array(q, f"q of trajectory {name!r}")
    if q_arr.ndim == 1 and entry.nq == 1:
        q_arr = q_arr[:, None]
    q = float_array(q_arr, f"q of trajectory {name!r} (robot {entry.key!r} has {entry.nq} joints)", 2, entry.nq)
    if t.size < 2 or np.any(np.diff(t) <= 0) or q.shape[0] != t.size:
        raise InvalidInput(
            f"trajectory {name!r} needs t strictly increasing with at least 2 instants and one q row per instant; "
            f"got t {t.shape}, q {q.shape}"
        )
    knots = float_array(t[[0, -1]] if knots is None else knots, f"knot_times of trajectory {name!r}", 1)
    return TrajectoryRecord(name, entry.key, t, q, knots, definition)


def _sampled(name: str, trajectory: Any, hz: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, Any]:
    """``(t, q, knot_times, definition)`` of a Trajectory sampled at ``hz``, its knots included."""
    if not (isinstance(hz, (int, float)) and math.isfinite(hz) and hz > 0):
        raise InvalidInput(f"hz must be a positive sampling rate in 1/s, got {hz!r}")
    knots = np.asarray(trajectory.knot_times, dtype=float)
    n_wanted = (knots[-1] - knots[0]) * hz
    if not n_wanted < MAX_TRAJECTORY_SAMPLES:
        raise InvalidInput(
            f"trajectory {name!r}: {knots[-1] - knots[0]:g} s at hz={hz:g} gives {n_wanted:.3g} samples, more "
            f"than {MAX_TRAJECTORY_SAMPLES:,}; lower hz"
        )
    n = max(2, int(math.ceil(n_wanted)) + 1)
    t = np.union1d(np.linspace(knots[0], knots[-1], n), knots)
    q = trajectory.sample(t)[0]
    definition = json_normalised(trajectory.definition, f"definition of trajectory {name!r}")
    return t, q, knots, definition


def workspace_record(name: str, entry: RobotEntry, workspace: Workspace | None, points: ArrayLike, manipulability: ArrayLike) -> WorkspaceRecord:
    """The workspace cloud ``name`` of robot ``entry``: a ``Workspace``, or ``points`` (n, 3) and ``manipulability`` (n,)."""
    if workspace is not None:
        if not (hasattr(workspace, "points") and hasattr(workspace, "manipulability")):
            raise InvalidInput(
                f"workspace {name!r} must be a robots.Workspace (points, manipulability), got {type(workspace).__name__}"
            )
        points, manipulability = workspace.points, workspace.manipulability
    if points is None or manipulability is None:
        raise InvalidInput(f"workspace {name!r}: give a Workspace, or both points= and manipulability=")
    pts = float_array(points, f"points of workspace {name!r}", 2, 3)
    w = float_array(manipulability, f"manipulability of workspace {name!r}", 1)
    if pts.shape[0] == 0:
        raise InvalidInput(f"workspace {name!r} has no points; sample at least one")
    if w.shape[0] != pts.shape[0] or np.any(w < 0):
        raise InvalidInput(
            f"workspace {name!r} needs one manipulability value >= 0 per point; got {w.shape[0]} for {pts.shape[0]} points"
        )
    return WorkspaceRecord(name, entry.key, pts, w)


def history_record(name: str, history: GAHistory | GAResult | HistoryRecord | Mapping[str, ArrayLike]) -> HistoryRecord:
    """The optimisation history ``name``: a GA history, a result with ``.history``, or a mapping of columns."""
    if hasattr(history, "history") and not isinstance(history, Mapping):
        history = history.history
    if history is None:
        raise InvalidInput(f"history {name!r} is None (an exact optimiser records no generations)")
    if isinstance(history, Mapping):
        cols = dict(history)
    elif hasattr(history, "as_dict"):
        cols = {k: getattr(history, k) for k in history.as_dict()}
    else:
        raise InvalidInput(f"history {name!r} must be a GA history, a result with .history, or a mapping of columns")
    if "best" not in cols:
        raise InvalidInput(f"history {name!r} needs a 'best' column; got {sorted(cols)}")
    out: dict[str, np.ndarray] = {}
    for k, v in cols.items():
        check_name(k, f"column of history {name!r}")
        # a generation without any finite objective records inf (optim's GA does so)
        out[k] = float_array(v, f"column {k!r} of history {name!r}", 1, allow_inf=True)
    lengths = {v.shape[0] for v in out.values()}
    if 0 in lengths:
        raise InvalidInput(f"history {name!r} has no generations; record at least one row")
    if len(lengths) != 1:
        raise InvalidInput(f"columns of history {name!r} must have equal lengths, got {sorted(lengths)}")
    return HistoryRecord(name, out)
