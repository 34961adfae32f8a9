"""Checksums of a reachability map's values, stored in its file and compared on load.

HDF5 stores small datasets uncompressed and without a checksum: a flipped byte in
``/voxels/best_manipulability`` once changed the map silently. :func:`map_checksum` is the
SHA-256 of every value of a :class:`~pinarms.robots.reach.reachability.ReachabilityMap` except its
stored solutions (attributes, limits, grid, orientations, voxels); :class:`PosesDigest` that
of the stored solutions, fed chunk by chunk as they are written (the streamed writer) or at
once (a map in memory, or the solutions read back). The writer stores both as the root
attributes ``checksum`` and ``poses_checksum``; the loader recomputes them from what it read.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["map_checksum", "PosesDigest"]

_POSES = (("voxel", "<i8"), ("orientation", "<i4"), ("q", "<f8"), ("manipulability", "<f8"))


def _feed(h: Any, name: str, values: Any, dtype: str) -> None:
    a = np.ascontiguousarray(values, dtype=dtype)
    h.update(f"|{name}|{dtype}|{a.shape}|".encode())
    h.update(memoryview(a.reshape(-1)).cast("B") if a.size else b"")


def map_checksum(m: Any) -> str:
    """SHA-256 (hex) of the values of map ``m`` but its stored solutions (module doc)."""
    o = m.orientations
    h = hashlib.sha256(b"pinarms-reachability-values-1")
    head = {"robot": m.robot, "urdf_sha256": m.urdf_sha256, "tcp_frame": m.tcp_frame, "solver": m.solver,
            "manipulability": m.manipulability_kind, "resolution": float(m.resolution).hex(),
            "shape": [int(s) for s in m.shape], "joint_names": list(m.joint_names), "parameters": m.parameters,
            "kind": o.kind, "roll_free": bool(o.roll_free), "n_groups": int(o.n_groups), "o_parameters": o.parameters}
    h.update(json.dumps(head, sort_keys=True, allow_nan=False).encode())
    for name, values, dtype in (("joint_lower", m.joint_lower, "<f8"), ("joint_upper", m.joint_upper, "<f8"),
                                ("origin", m.origin, "<f8"), ("rotations", o.rotations, "<f8"),
                                ("group", o.group, "<i4"), ("directions", o.directions, "<f8"),
                                ("tool_axis", o.tool_axis, "<f8"), ("flat", m.voxels, "<i8"), ("index", m.index, "<f8"),
                                ("best_manipulability", m.best_manipulability, "<f8"), ("reached", m.reached, "u1")):
        _feed(h, name, values, dtype)
    return h.hexdigest()


class PosesDigest:
    """SHA-256 of stored solutions, fed in order: the same for one call or for many chunks."""

    def __init__(self) -> None:
        self._h = {name: hashlib.sha256(f"pinarms-reachability-poses-1|{name}".encode()) for name, _ in _POSES}

    def update(self, voxel: ArrayLike, orientation: ArrayLike, q: ArrayLike, manipulability: ArrayLike) -> None:
        for (name, dtype), values in zip(_POSES, (voxel, orientation, q, manipulability)):
            a = np.ascontiguousarray(values, dtype=dtype)
            if a.size:
                self._h[name].update(memoryview(a.reshape(-1)).cast("B"))

    def hexdigest(self) -> str:
        return hashlib.sha256("".join(self._h[name].hexdigest() for name, _ in _POSES).encode()).hexdigest()
