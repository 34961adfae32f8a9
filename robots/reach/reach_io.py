"""Reachability maps in HDF5 files (h5py): written atomically, checked on load like a hostile file.

Layout (format ``pinarms-reachability``, version :data:`FORMAT_VERSION`), SI units::

    /                      attrs: format, version, pinarms_version, robot, urdf_sha256, tcp_frame,
                                  solver, manipulability, resolution [m], shape (3,), parameters (JSON),
                                  n_reached (count of reached poses; optional when reading)
    /robot/joint_lower     (nq,) f8 [rad or m]     attrs: joint_names (JSON list)
    /robot/joint_upper     (nq,) f8
    /grid/origin           (3,) f8  corner of voxel [0, 0, 0] [m]; voxel (i, j, k) has flat index (i·ny + j)·nz + k
    /orientations/rotations (M, 3, 3) f8  tool frame → base      attrs: kind, roll_free, n_groups, parameters (JSON)
    /orientations/group    (M,) i4
    /orientations/directions (G, 3) f8
    /orientations/tool_axis (3,) f8
    /voxels/flat           (V,) i8  strictly increasing flat indices of the computed voxels
    /voxels/index          (V,) f8  reachability index
    /voxels/best_manipulability (V,) f8 (NaN: nothing reached)
    /voxels/reached        (V, M) u1 (0 or 1)
    /poses/voxel           (K,) i8   optional: one stored IK solution per reached pose
    /poses/orientation     (K,) i4
    /poses/q               (K, nq) f8
    /poses/manipulability  (K,) f8

Loading (:func:`load_reachability`) trusts nothing: a file that is not HDF5 or is truncated,
a missing or extra-typed member, a link to another file or a soft link, a dataset stored
outside the file (external storage, virtual datasets), an unknown compression filter, an
array larger than ``max_bytes`` in memory, a shape that disagrees with the others, NaN where
numbers are needed, indices out of range, a rotation that is not a rotation, an index that
does not follow from the reached bits, or a stored solution outside the joint limits all
raise :class:`ReachabilityFileError` naming the member and the problem (the checks of the
content are :mod:`pinarms.robots.reach.reach_check`; this module writes, and reads through a child).

The HDF5 library runs in a child process (:mod:`pinarms.robots.reach._reach_worker`, started by
:mod:`pinarms.robots.reach._reach_child`) bounded in address space (:data:`READER_MEMORY`), CPU time and
wall-clock time (``timeout`` for opening the file and checking its layout, then 1 s per
20 MB of data): a damaged file that makes libhdf5 loop is killed and refused. Before it
opens the map the child walls itself in (Landlock, :mod:`pinarms.robots._sandbox`): it may read
only the map file and Python's folders and write or execute nothing;
:attr:`ReachabilityMap.reader_wall` says which wall was up. Before any
data is read, the declared dtypes and shapes are checked against each other (joints,
orientations, voxels, stored solutions ≤ V·M and = ``n_reached``) and against
``max_bytes``, and the storage against what a writer produces (fill value 0, every chunk
written, chunks ≤ 16 MiB and ≤ 2²⁰ of them). The arrays come back as raw bytes into arrays
sized here; nothing is unpickled.
"""

from __future__ import annotations

import json
import math
import os
import signal
import time
from pathlib import Path
from typing import Any

import numpy as np

from pinarms.files import check_regular

from pinarms.errors import InvalidInput
from pinarms.robots.reach.orientations import MAX_ORIENTATIONS
from pinarms.robots.reach.reach_check import MAX_JOINTS, MapChecker, ReachabilityFileError, check_map
from pinarms.robots.reach.reach_write import FORMAT_NAME, FORMAT_VERSION, StreamWriter, write_map
from pinarms.robots.reach.reach_map import MAX_GRID_VOXELS, ReachabilityMap

__all__ = [
    "ReachabilityFileError",
    "StreamWriter",
    "save_reachability",
    "load_reachability",
    "FORMAT_NAME",
    "FORMAT_VERSION",
    "DEFAULT_MAX_BYTES",
    "DEFAULT_TIMEOUT",
    "READER_MEMORY",
]

#: Largest total size of the arrays :func:`load_reachability` accepts by default [bytes].
DEFAULT_MAX_BYTES = 4 * 1024**3
#: HDF5 filters a map file may use: deflate (gzip), shuffle, fletcher32, LZF.
_ALLOWED_FILTERS = {1, 2, 3, 32000}


def save_reachability(reach_map: ReachabilityMap, path: str | os.PathLike) -> Path:
    """Write ``reach_map`` to ``path`` (HDF5, written to a temporary file then renamed); return the path.

    Raises:
        InvalidInput: not a :class:`ReachabilityMap`, or the target folder does not exist / the
            target is a folder.
    """
    if not isinstance(reach_map, ReachabilityMap):
        raise InvalidInput(f"save_reachability needs a ReachabilityMap, got {type(reach_map).__name__}")
    return write_map(reach_map, path)


# ----------------------------------------------------------------------------- reading
#: Default bound [s] on opening a map and checking its declared layout (the child's start excluded).
DEFAULT_TIMEOUT = 2.0
_STARTUP_TIMEOUT = 60.0  # s: the reader's interpreter starting (no file is open yet)
_MIN_RATE = 20e6  # bytes/s: the slowest data rate accepted before the reader is deemed stuck
#: Address space of the reader process [bytes]: it streams data in slices, so this does not grow with the map.
READER_MEMORY = 448 * 2**20
_CHILD_LIMITS = {"max_chunk_bytes": 16 * 2**20, "max_chunks": 1 << 20, "slice_bytes": 16 * 2**20,
                 "max_grid_voxels": MAX_GRID_VOXELS, "max_joints": MAX_JOINTS, "max_orientations": MAX_ORIENTATIONS}
_MAX_MANIFEST = 32 * 2**20


def load_reachability(path: str | os.PathLike, *, solutions: bool = True, max_bytes: int = DEFAULT_MAX_BYTES,
                      timeout: float = DEFAULT_TIMEOUT) -> ReachabilityMap:
    """Read and check a map written by :func:`save_reachability` (see the module doc for the checks).

    The HDF5 library runs in a child process limited to :data:`READER_MEMORY` of address
    space and a CPU time, killed when it overruns ``timeout`` while opening the file and
    checking its declared layout, or ``timeout + bytes / 20 MB/s`` while reading the data;
    its arrays come back as raw bytes of the dtype and shape checked here.

    Args:
        solutions: also read the stored IK solution of every reached pose (``/poses``).
        max_bytes: refuse files whose arrays would take more memory than this [bytes].
        timeout: bound [s] on opening the file and checking its layout (see above).

    Raises:
        InvalidInput: ``path`` is not an existing file, or ``max_bytes`` / ``timeout`` is not positive.
        ReachabilityFileError: anything wrong with the file's content, a reader that runs
            over its time or memory.
    """
    check_regular(path, "reachability map file")  # a FIFO or a device is refused before the reader opens it
    p = Path(path)
    if isinstance(max_bytes, bool) or not isinstance(max_bytes, (int, np.integer)) or max_bytes <= 0:
        raise InvalidInput(f"max_bytes must be a positive integer, got {max_bytes!r}")
    if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not 0 < timeout <= 3600:
        raise InvalidInput(f"timeout must be a number of seconds in (0, 3600], got {timeout!r}")
    request = {"path": str(p.resolve()), "solutions": bool(solutions), "max_bytes": int(max_bytes),
               "limits": _CHILD_LIMITS}
    cpu = int(_STARTUP_TIMEOUT + timeout + max_bytes / _MIN_RATE) + 1
    attrs, arrays, wall = _receive(p, request, float(timeout), cpu)
    return check_map(MapChecker(p, attrs, arrays, wall), bool(solutions))


def _receive(p: Path, request: dict, timeout: float, cpu: int) -> tuple[dict, dict[str, np.ndarray], str]:
    """Run the reader child; its checked attributes and arrays, and the wall it was behind."""
    from pinarms.robots.reach._reach_child import ChildGone, ChildTimeout, ReaderChild

    shown = str(p)
    stage = "starting the reader"
    try:
        with ReaderChild(READER_MEMORY, cpu) as child:
            child.send(request)
            deadline = time.monotonic() + _STARTUP_TIMEOUT
            _expect(p, child, child.frame(deadline), b"R", deadline)
            stage = "opening it and checking its layout"
            deadline = time.monotonic() + timeout
            tag, size = child.frame(deadline)
            _expect(p, child, (tag, size), b"M", deadline)
            manifest = _manifest(p, child.payload(size, _MAX_MANIFEST, deadline), request)
            total = sum(a.nbytes for a in manifest["arrays"].values())
            stage = f"reading its {total / 1e6:.1f} MB of data"
            deadline = time.monotonic() + timeout + total / _MIN_RATE
            for arr in manifest["arrays"].values():
                view = memoryview(arr.reshape(-1)).cast("B") if arr.size else memoryview(b"")
                pos = 0
                while pos < len(view):
                    tag, size = child.frame(deadline)
                    _expect(p, child, (tag, size), b"D", deadline)
                    if size > len(view) - pos:
                        raise ChildGone("oversized")
                    child.read_into(view[pos: pos + size], deadline)
                    pos += size
            _expect(p, child, child.frame(deadline), b"K", deadline)
            child.finish(time.monotonic() + 5.0)
    except ChildTimeout:
        bound = {"starting the reader": f"{_STARTUP_TIMEOUT:g} s", "opening it and checking its layout": f"{timeout:g} s"}
        raise ReachabilityFileError(
            f"{shown!r} is not a valid pinarms reachability map: {stage} did not finish in time "
            f"({bound.get(stage, f'{timeout:g} s + 1 s per 20 MB')}; a damaged HDF5 file can make the library loop "
            "forever), so the reader was stopped; if it is a large valid map on a busy machine, pass a larger timeout"
        ) from None
    except ChildGone as exc:
        raise ReachabilityFileError(f"{shown!r} is not a valid pinarms reachability map: {_gone(exc.args[0])} while "
                                    f"{stage}") from None
    return manifest["attrs"], manifest["arrays"], manifest["wall"]


def _gone(status: Any) -> str:
    if status == "oversized":
        return "the reader sent more data than the checked layout holds"
    if isinstance(status, int) and status < 0:
        name = {signal.SIGXCPU: "its CPU time", signal.SIGKILL: "a hard limit", signal.SIGSEGV: "a crash",
                signal.SIGABRT: "an abort in the HDF5 library"}.get(-status, f"signal {-status}")
        return f"the reader process was stopped by {name} (more than {READER_MEMORY / 2**20:.0f} MiB or a damaged file)"
    return f"the reader process ended early (status {status})"


def _expect(p: Path, child: Any, frame: tuple[bytes, int], want: bytes, deadline: float) -> None:
    """Raise the child's refusal (``E``) or a protocol error unless ``frame`` has tag ``want``."""
    tag, size = frame
    if tag == want:
        return
    if tag != b"E":
        from pinarms.robots.reach._reach_child import ChildGone

        child.close()
        raise ChildGone(f"unexpected frame {tag!r}")
    try:
        err = json.loads(child.payload(size, 1 << 16, deadline).decode("utf-8"))
        kind, message = str(err["kind"]), str(err["message"])
    except (ValueError, KeyError, TypeError, UnicodeDecodeError):
        kind, message = "refused", "the reader's answer was malformed"
    child.close()
    if kind == "newer":
        raise ReachabilityFileError(
            f"{str(p)!r} was written in reachability format version {message[:20]}, newer than this pinarms reads "
            f"(up to {FORMAT_VERSION}); upgrade pinarms to open it"
        )
    if kind == "memory":
        message = f"reading it needs more than the reader's {READER_MEMORY / 2**20:.0f} MiB"
    raise ReachabilityFileError(f"{str(p)!r} is not a valid pinarms reachability map: {message}")


def _manifest(p: Path, raw: bytes, request: dict) -> dict:
    """The child's manifest, checked again (names, dtypes, shapes, shared sizes, budget); arrays allocated."""
    from pinarms.robots.reach._reach_worker import DATASETS, POSES

    def bad(what: str) -> ReachabilityFileError:
        return ReachabilityFileError(f"{str(p)!r} is not a valid pinarms reachability map: the reader's answer {what}")

    try:
        doc = json.loads(raw.decode("utf-8"))
        attrs, listed, wall = doc["attrs"], doc["arrays"], doc.get("wall", "")
    except (ValueError, KeyError, TypeError, UnicodeDecodeError, RecursionError):
        raise bad("is malformed") from None
    table = list(DATASETS) + (list(POSES) if request["solutions"] and len(listed) > len(DATASETS) else [])
    if not isinstance(attrs, dict) or not isinstance(listed, list) or len(listed) != len(table):
        raise bad("lists other members than a map has")
    if not isinstance(wall, str) or len(wall) > 100:
        raise bad("names its wall wrongly")
    dims: dict[str, int] = {}
    arrays: dict[str, np.ndarray] = {}
    total = 0
    for entry, (name, dtype, shape) in zip(listed, table):
        got = entry.get("shape") if isinstance(entry, dict) else None
        if (entry.get("name"), entry.get("dtype")) != (name, np.dtype(dtype).str) or not isinstance(got, list) or \
                len(got) != len(shape) or not all(isinstance(v, int) and 0 <= v < 2**40 for v in got):
            raise bad(f"describes /{name} wrongly")
        for want, v in zip(shape, got):
            expected = dims.setdefault(want, v) if isinstance(want, str) else want
            if expected != v:
                raise bad(f"gives /{name} the shape {got}, which disagrees with the other members")
        total += math.prod(got) * np.dtype(dtype).itemsize
        if total > request["max_bytes"]:
            raise bad(f"declares more than max_bytes = {request['max_bytes']}")
        arrays[name] = np.empty(tuple(got), dtype=dtype)
    return {"attrs": attrs, "arrays": arrays, "wall": wall}
