"""Writing reachability map files (HDF5, format ``pinarms-reachability``): atomically, chunk by chunk.

The layout is described in :mod:`pinarms.robots.reach.reach_io`, which also reads and checks the files.
This module writes them and imports nothing of the map's module (it reads the map's fields),
so :class:`pinarms.robots.reach.reachability.ReachabilityMap` and the streamed computation
(``ReachabilityRequest(out=...)``) use it without an import circle.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from pinarms.files import discard, publish, temporary_for

from pinarms.errors import InvalidInput
from pinarms.robots.reach.reach_digest import PosesDigest, map_checksum

__all__ = ["StreamWriter", "write_map", "FORMAT_NAME", "FORMAT_VERSION"]

FORMAT_NAME = "pinarms-reachability"
FORMAT_VERSION = 1
_GZIP = {"compression": "gzip", "compression_opts": 4, "shuffle": True}


def _version() -> str:
    try:
        return importlib.metadata.version("pinarms")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover - bare checkout
        return "unknown"


# ----------------------------------------------------------------------------- writing
def _write_dataset(group: Any, name: str, data: np.ndarray) -> None:
    data = np.ascontiguousarray(data)
    opts = _GZIP if data.size >= 4096 else {}
    group.create_dataset(name, data=data, **opts)


def _write(h5: Any, m: Any, poses: str | None = None) -> None:
    """Every member of map ``m``; ``poses``: the checksum of solutions streamed before (else of ``m``'s own)."""
    if poses is None and m.solutions is not None:
        digest = PosesDigest()
        digest.update(m.solutions.voxel, m.solutions.orientation, m.solutions.q, m.solutions.manipulability)
        poses = digest.hexdigest()
    h5.attrs["format"] = FORMAT_NAME
    h5.attrs["version"] = FORMAT_VERSION
    h5.attrs["pinarms_version"] = _version()
    h5.attrs["robot"] = m.robot
    h5.attrs["urdf_sha256"] = m.urdf_sha256
    h5.attrs["tcp_frame"] = m.tcp_frame
    h5.attrs["solver"] = m.solver
    h5.attrs["manipulability"] = m.manipulability_kind
    h5.attrs["resolution"] = float(m.resolution)
    h5.attrs["shape"] = np.asarray(m.shape, dtype="<i8")
    h5.attrs["parameters"] = json.dumps(m.parameters, allow_nan=False, sort_keys=True)
    h5.attrs["n_reached"] = int(m.n_reached)  # the reader checks /poses' declared rows against it
    h5.attrs["checksum"] = map_checksum(m)  # the loader recomputes both from what it read
    if poses is not None:
        h5.attrs["poses_checksum"] = poses
    g = h5.create_group("robot")
    g.attrs["joint_names"] = json.dumps(list(m.joint_names))
    _write_dataset(g, "joint_lower", np.asarray(m.joint_lower, dtype="<f8"))
    _write_dataset(g, "joint_upper", np.asarray(m.joint_upper, dtype="<f8"))
    _write_dataset(h5.create_group("grid"), "origin", np.asarray(m.origin, dtype="<f8"))
    o = m.orientations
    g = h5.create_group("orientations")
    g.attrs["kind"] = o.kind
    g.attrs["roll_free"] = bool(o.roll_free)
    g.attrs["n_groups"] = int(o.n_groups)
    g.attrs["parameters"] = json.dumps(o.parameters, allow_nan=False, sort_keys=True)
    _write_dataset(g, "rotations", np.asarray(o.rotations, dtype="<f8"))
    _write_dataset(g, "group", np.asarray(o.group, dtype="<i4"))
    _write_dataset(g, "directions", np.asarray(o.directions, dtype="<f8"))
    _write_dataset(g, "tool_axis", np.asarray(o.tool_axis, dtype="<f8"))
    g = h5.create_group("voxels")
    _write_dataset(g, "flat", np.asarray(m.voxels, dtype="<i8"))
    _write_dataset(g, "index", np.asarray(m.index, dtype="<f8"))
    _write_dataset(g, "best_manipulability", np.asarray(m.best_manipulability, dtype="<f8"))
    _write_dataset(g, "reached", np.asarray(m.reached, dtype="u1"))
    if m.solutions is not None:
        s = m.solutions
        g = h5.create_group("poses")
        _write_dataset(g, "voxel", np.asarray(s.voxel, dtype="<i8"))
        _write_dataset(g, "orientation", np.asarray(s.orientation, dtype="<i4"))
        _write_dataset(g, "q", np.asarray(s.q, dtype="<f8").reshape(-1, m.nq))
        _write_dataset(g, "manipulability", np.asarray(s.manipulability, dtype="<f8"))


class StreamWriter:
    """Writes a map whose stored solutions arrive chunk by chunk (``ReachabilityRequest(out=...)``).

    :meth:`append` adds solutions to extendable, chunked, gzip datasets under ``/poses`` of a
    temporary file; :meth:`finish` writes the rest of the map and renames the file to its
    target; :meth:`abort` removes the temporary file. Memory: one chunk's solutions.
    """

    def __init__(self, path: str | os.PathLike, nq: int) -> None:
        import h5py

        self.target, self.tmp = temporary_for(path)
        self.nq = int(nq)
        self.count = 0
        self.digest = PosesDigest()
        self.h5 = h5py.File(self.tmp, "w")
        g = self.h5.create_group("poses")
        rows = 1 << 16
        g.create_dataset("voxel", shape=(0,), maxshape=(None,), dtype="<i8", chunks=(rows,), **_GZIP)
        g.create_dataset("orientation", shape=(0,), maxshape=(None,), dtype="<i4", chunks=(rows,), **_GZIP)
        g.create_dataset("q", shape=(0, self.nq), maxshape=(None, self.nq), dtype="<f8", chunks=(rows // 8, self.nq),
                         **_GZIP)
        g.create_dataset("manipulability", shape=(0,), maxshape=(None,), dtype="<f8", chunks=(rows,), **_GZIP)

    def append(self, voxel: np.ndarray, orientation: np.ndarray, q: np.ndarray, w: np.ndarray) -> None:
        """Add ``K`` solutions: grid flat indices, orientation indices, ``q (K, nq)``, manipulabilities."""
        k = int(np.asarray(voxel).size)
        if k == 0:
            return
        g = self.h5["poses"]
        end = self.count + k
        for name, data in (("voxel", np.asarray(voxel, "<i8")), ("orientation", np.asarray(orientation, "<i4")),
                           ("q", np.asarray(q, "<f8").reshape(k, self.nq)), ("manipulability", np.asarray(w, "<f8"))):
            g[name].resize(end, axis=0)
            g[name][self.count : end] = data
        self.digest.update(voxel, orientation, np.asarray(q, "<f8").reshape(k, self.nq), w)
        self.count = end

    def finish(self, reach_map: Any) -> Path:
        """Write the map's other members, close and rename the file; return the target path."""
        if reach_map.solutions is not None:
            raise InvalidInput("a streamed map keeps its solutions in the file, not in memory")
        if self.count != reach_map.n_reached:
            raise InvalidInput(f"{self.count} solutions were streamed for {reach_map.n_reached} reached poses")
        _write(self.h5, reach_map, self.digest.hexdigest())
        self.h5.close()
        publish(self.tmp, self.target)
        return self.target

    def abort(self) -> None:
        """Close and remove the temporary file (the target is left as it was)."""
        try:
            self.h5.close()
        finally:
            discard(self.tmp)


def write_map(reach_map: Any, path: str | os.PathLike) -> Path:
    """Write ``reach_map`` to ``path`` (HDF5, written to a temporary file then renamed); return the path.

    ``reach_map`` is a :class:`pinarms.robots.reach.reachability.ReachabilityMap` (checked by
    :func:`pinarms.robots.reach.reach_io.save_reachability`, the public entry).

    Raises:
        InvalidInput: the target folder does not exist / the target is a folder.
    """
    import h5py

    target, tmp = temporary_for(path)
    try:
        with h5py.File(tmp, "w") as h5:
            _write(h5, reach_map)
        publish(tmp, target)
    except BaseException:
        discard(tmp)
        raise
    return target
