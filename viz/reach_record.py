"""Reachability maps in a session: the reachable voxels of a :class:`pinarms.robots.ReachabilityMap`, ready to draw.

A :class:`ReachabilityRecord` keeps what the viewer shows (not the whole map: the HDF5 file
keeps that): the centres of the voxels whose reachability index exceeds ``min_index``, in
the robot's base frame [m], their index in (0, 1], their best manipulability, the voxel edge
[m] and a one-line description of the orientation set. In ``session.json`` it is an item of
the optional section ``"reachability"`` (a row of :data:`pinarms.viz.session_format.KINDS`; absent
when a session holds no map, so older files and readers are unaffected).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, TYPE_CHECKING

import numpy as np

from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.robots.reach.reach_map import ReachabilityMap

__all__ = ["ReachabilityRecord", "make_record", "encode_reachability", "decode_reachability", "MAX_DESCRIPTION"]

MAX_DESCRIPTION = 2000


@dataclass(frozen=True, eq=False)
class ReachabilityRecord:
    """Reachable voxels of one map, in ``robot``'s base frame.

    Attributes:
        name: the record's name; ``robot`` the session's robot key.
        centres: ``(k, 3)`` voxel centres [m]; ``index`` ``(k,)`` reachability index in (0, 1];
        manipulability: ``(k,)`` best manipulability of each voxel (≥ 0).
        resolution: voxel edge [m]; ``description``: what the map tried (orientation set, IK).
    """

    name: str
    robot: str
    centres: np.ndarray
    index: np.ndarray
    manipulability: np.ndarray
    resolution: float
    description: str


def make_record(name: str, robot_key: str, reach_map: ReachabilityMap, min_index: float, float_array: Callable) -> ReachabilityRecord:
    """A record of ``reach_map``'s voxels with index > ``min_index`` (checked like the session's other arrays)."""
    for attr in ("reachable_centres", "best_manipulability", "orientations", "resolution"):
        if not hasattr(reach_map, attr):
            raise InvalidInput(f"reachability {name!r} must be a robots.ReachabilityMap, got {type(reach_map).__name__}")
    if isinstance(min_index, bool) or not (isinstance(min_index, (int, float)) and 0.0 <= float(min_index) < 1.0):
        raise InvalidInput(f"min_index must be a number in [0, 1), got {min_index!r}")
    centres, index = reach_map.reachable_centres(float(min_index))
    if centres.shape[0] == 0:
        raise InvalidInput(f"reachability {name!r}: no voxel has an index above {min_index}; nothing to show")
    w = reach_map.best_manipulability[reach_map.index > float(min_index)]
    description = (f"{reach_map.robot}: {reach_map.resolution * 1000:g} mm voxels, {reach_map.solver} IK; "
                   f"{reach_map.orientations.describe()}")[:MAX_DESCRIPTION]
    return ReachabilityRecord(
        name, robot_key, float_array(centres, f"centres of reachability {name!r}", 2, 3),
        float_array(index, f"index of reachability {name!r}", 1),
        float_array(np.nan_to_num(w, nan=0.0), f"manipulability of reachability {name!r}", 1),
        float(reach_map.resolution), description,
    )


def encode_reachability(r: ReachabilityRecord) -> tuple[dict, dict, dict]:
    """JSON fields, arrays and texts of one record (see :class:`pinarms.viz.session_format.Kind`)."""
    return ({"name": r.name, "robot": r.robot, "resolution": r.resolution, "description": r.description},
            {"centres": r.centres, "index": r.index, "manipulability": r.manipulability}, {})


def decode_reachability(it: Any) -> ReachabilityRecord:
    """The record of a validated session item (JSON fields checked here, arrays already read)."""
    res = it.field("resolution", (int, float))
    if isinstance(res, bool) or not (math.isfinite(res) and res > 0):
        raise it.fail(f"{it.where}.resolution must be a positive length in m")
    desc = it.field("description", str)
    if len(desc) > MAX_DESCRIPTION:
        raise it.fail(f"{it.where}.description is longer than {MAX_DESCRIPTION} characters")
    index, w = it.arrays["index"], it.arrays["manipulability"]
    if np.any(index <= 0) or np.any(index > 1) or np.any(w < 0):
        raise it.fail(f"{it.where}: index must lie in (0, 1] and manipulability be >= 0")
    return ReachabilityRecord(it.key, it.robot, it.arrays["centres"], index, w, float(res), desc)
