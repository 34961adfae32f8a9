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
raise :class:`ReachabilityFileError` naming the member and the problem.

The HDF5 library runs in a child process (:mod:`robots.reach._reach_worker`, started by
:mod:`robots.reach._reach_child`) bounded in address space (:data:`READER_MEMORY`), CPU time and
wall-clock time (``timeout`` for opening the file and checking its layout, then 1 s per
20 MB of data): a damaged file that makes libhdf5 loop is killed and refused. Before it
opens the map the child walls itself in (Landlock, :mod:`robots._sandbox`): it may read
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

from ..errors import InvalidInput, PinarmsError
from .orientations import MAX_ORIENTATIONS, OrientationSet
from .reach_write import FORMAT_NAME, FORMAT_VERSION, StreamWriter, write_map
from .reach_map import MAX_GRID_VOXELS, PoseSolutions, ReachabilityMap

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
_MAX_TEXT = 1_000_000
_MAX_JOINTS = 64
#: HDF5 filters a map file may use: deflate (gzip), shuffle, fletcher32, LZF.
_ALLOWED_FILTERS = {1, 2, 3, 32000}


class ReachabilityFileError(PinarmsError):
    """A reachability map file is not one pinarms can trust: what is wrong and where is in the message."""


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
                 "max_grid_voxels": MAX_GRID_VOXELS, "max_joints": _MAX_JOINTS, "max_orientations": MAX_ORIENTATIONS}
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
    p = Path(path)
    if not p.is_file():
        raise InvalidInput(f"reachability map file {str(p)!r} does not exist (or is not a file)")
    if isinstance(max_bytes, bool) or not isinstance(max_bytes, (int, np.integer)) or max_bytes <= 0:
        raise InvalidInput(f"max_bytes must be a positive integer, got {max_bytes!r}")
    if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not 0 < timeout <= 3600:
        raise InvalidInput(f"timeout must be a number of seconds in (0, 3600], got {timeout!r}")
    request = {"path": str(p.resolve()), "solutions": bool(solutions), "max_bytes": int(max_bytes),
               "limits": _CHILD_LIMITS}
    cpu = int(_STARTUP_TIMEOUT + timeout + max_bytes / _MIN_RATE) + 1
    attrs, arrays, wall = _receive(p, request, float(timeout), cpu)
    return _check(_Checker(p, attrs, arrays, wall), bool(solutions))


def _receive(p: Path, request: dict, timeout: float, cpu: int) -> tuple[dict, dict[str, np.ndarray], str]:
    """Run the reader child; its checked attributes and arrays, and the wall it was behind."""
    from ._reach_child import ChildGone, ChildTimeout, ReaderChild

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
        from ._reach_child import ChildGone

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
    from ._reach_worker import DATASETS, POSES

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


class _Checker:
    """The attributes and arrays the reader sent; each problem becomes a :class:`ReachabilityFileError`."""

    def __init__(self, path: Path, attrs: dict, arrays: dict[str, np.ndarray], wall: str = "") -> None:
        self.path, self.attrs, self.arrays, self.wall = path, attrs, arrays, wall

    def fail(self, what: str) -> ReachabilityFileError:
        return ReachabilityFileError(f"{str(self.path)!r} is not a valid pinarms reachability map: {what}")

    def attr(self, group: str, key: str, kind: type) -> Any:
        where = "the file" if group == "/" else group
        values = self.attrs.get(group)
        value = values.get(key) if isinstance(values, dict) else None
        ok = {str: lambda v: isinstance(v, str) and len(v) <= _MAX_TEXT, bool: lambda v: isinstance(v, bool),
              int: lambda v: isinstance(v, int) and not isinstance(v, bool),
              float: lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
              list: lambda v: isinstance(v, list) and len(v) <= 16 and all(isinstance(x, int) for x in v)}[kind]
        if not ok(value):
            raise self.fail(f"attribute {key!r} of {where} is missing or not a {kind.__name__}")
        return float(value) if kind is float else value

    def json(self, group: str, key: str, kind: type) -> Any:
        where = "the file" if group == "/" else group
        try:
            value = json.loads(self.attr(group, key, str))
        except (json.JSONDecodeError, RecursionError):
            raise self.fail(f"attribute {key!r} of {where} is not valid JSON") from None
        if not isinstance(value, kind):
            raise self.fail(f"attribute {key!r} of {where} must be a JSON {kind.__name__}")
        return value

    def finite(self, name: str, *, nan_ok: bool = False) -> np.ndarray:
        arr = self.arrays[name]
        bad = np.isinf(arr) if nan_ok else ~np.isfinite(arr)
        if np.any(bad):
            raise self.fail(f"dataset /{name} holds {'infinite' if nan_ok else 'NaN or infinite'} values")
        return arr


def _check(r: _Checker, want_solutions: bool) -> ReachabilityMap:
    fmt, version = r.attr("/", "format", str), r.attr("/", "version", int)
    if fmt != FORMAT_NAME or not 1 <= version <= FORMAT_VERSION:
        raise r.fail(f"format {fmt!r} version {version} is not this pinarms' map format")
    sha = r.attr("/", "urdf_sha256", str)
    if len(sha) != 64 or any(c not in "0123456789abcdef" for c in sha):
        raise r.fail("urdf_sha256 is not a SHA-256 hex digest")
    solver = r.attr("/", "solver", str)
    if solver not in ("analytic", "numerical"):
        raise r.fail(f"solver must be 'analytic' or 'numerical', got {solver!r}")
    manip = r.attr("/", "manipulability", str)
    if manip not in ("full", "position"):
        raise r.fail(f"manipulability must be 'full' or 'position', got {manip!r}")
    resolution = r.attr("/", "resolution", float)
    if not (np.isfinite(resolution) and resolution > 0):
        raise r.fail(f"resolution must be a positive length in m, got {resolution!r}")
    shape = r.attr("/", "shape", list)
    if len(shape) != 3 or min(shape) < 1 or math.prod(shape) > MAX_GRID_VOXELS:
        raise r.fail(f"shape must be 3 positive integers with at most {MAX_GRID_VOXELS} voxels, got {shape}")
    joint_names = r.json("/robot", "joint_names", list)
    nq = len(joint_names)
    if not (1 <= nq <= _MAX_JOINTS) or not all(isinstance(j, str) and 0 < len(j) <= 200 for j in joint_names):
        raise r.fail(f"/robot joint_names must list 1 to {_MAX_JOINTS} joint names")
    lower, upper = r.finite("robot/joint_lower"), r.finite("robot/joint_upper")
    if lower.size != nq:
        raise r.fail(f"dataset /robot/joint_lower holds {lower.size} limits for the {nq} joint names")
    if np.any(lower > upper):
        raise r.fail("/robot joint limits have lower > upper")
    oset = _check_orientations(r)
    flat, reached, index, best = _check_voxels(r, oset, math.prod(shape))
    sols = _check_poses(r, flat, reached, lower, upper) if want_solutions and "poses/voxel" in r.arrays else None
    return ReachabilityMap(
        robot=r.attr("/", "robot", str), urdf_sha256=sha, tcp_frame=r.attr("/", "tcp_frame", str),
        joint_names=tuple(joint_names), joint_lower=lower, joint_upper=upper, solver=solver,
        manipulability_kind=manip, origin=r.finite("grid/origin"), resolution=resolution,
        shape=(int(shape[0]), int(shape[1]), int(shape[2])), orientations=oset, voxels=flat, reached=reached,
        index=index, best_manipulability=best, solutions=sols, parameters=r.json("/", "parameters", dict),
        reader_wall=r.wall,
    )


def _check_orientations(r: _Checker) -> OrientationSet:
    kind = r.attr("/orientations", "kind", str)
    if kind not in ("so3", "tool_axis"):
        raise r.fail(f"/orientations kind must be 'so3' or 'tool_axis', got {kind!r}")
    roll_free = r.attr("/orientations", "roll_free", bool)
    n_groups = r.attr("/orientations", "n_groups", int)
    oparams = r.json("/orientations", "parameters", dict)
    rot = r.finite("orientations/rotations")
    M = rot.shape[0]
    if not (1 <= M <= MAX_ORIENTATIONS) or not (1 <= n_groups <= MAX_ORIENTATIONS):
        raise r.fail(f"/orientations holds {M} rotations in {n_groups} groups; expected 1 to {MAX_ORIENTATIONS}")
    ortho = np.abs(rot @ np.swapaxes(rot, 1, 2) - np.eye(3)).max()
    if ortho > 1e-9 or np.any(np.linalg.det(rot) < 0.0):
        raise r.fail("/orientations/rotations holds a matrix that is not a proper rotation")
    group = r.arrays["orientations/group"].astype(np.int64)  # M ≤ 10⁵ entries
    if np.any(group < 0) or np.any(group >= n_groups) or np.any(np.diff(group) < 0) or np.unique(group).size != n_groups:
        raise r.fail("/orientations/group must number the directions 0..n_groups-1 in order, each used")
    directions, tool_axis = r.finite("orientations/directions"), r.finite("orientations/tool_axis")
    if directions.shape[0] != n_groups:
        raise r.fail(f"dataset /orientations/directions holds {directions.shape[0]} rows for {n_groups} groups")
    if kind == "so3" and (n_groups != M or roll_free):
        raise r.fail("/orientations of kind 'so3' must have one group per rotation and roll_free false")
    return OrientationSet(kind, rot, group, n_groups, roll_free, tool_axis, directions, oparams)


def _check_voxels(r: _Checker, o: OrientationSet, n_grid: int) -> tuple[np.ndarray, ...]:
    flat = r.arrays["voxels/flat"]
    V = flat.size
    if V and (flat[0] < 0 or flat[-1] >= n_grid or np.any(flat[1:] <= flat[:-1])):
        raise r.fail(f"/voxels/flat must be strictly increasing flat indices in [0, {n_grid})")
    index = r.finite("voxels/index")
    best = r.finite("voxels/best_manipulability", nan_ok=True)
    reached_u1 = r.arrays["voxels/reached"]
    if reached_u1.size and reached_u1.max() > 1:
        raise r.fail("/voxels/reached must hold only 0 and 1")
    reached = reached_u1.view(bool)  # 0/1 bytes are valid booleans: no copy
    M, G = reached.shape[1], o.n_groups
    if o.roll_free:
        per_group = np.zeros((V, G), dtype=bool)
        for k in range(M):
            per_group[:, o.group[k]] |= reached[:, k]
        expect = per_group.sum(axis=1) / G
    else:
        expect = np.count_nonzero(reached, axis=1) / M
    if not np.array_equal(expect, index):
        row = int(np.flatnonzero(expect != index)[0])
        raise r.fail(f"/voxels/index does not follow from /voxels/reached (row {row}: {index[row]!r} vs {expect[row]!r})")
    any_reached = reached.any(axis=1)
    if np.any(np.isnan(best) == any_reached) or np.any(best[any_reached] < 0):
        raise r.fail("/voxels/best_manipulability must be >= 0 where a pose is reached and NaN elsewhere")
    n_reached = r.attrs["/"].get("n_reached")  # optional (files of pinarms 0.1 lack it)
    if n_reached is not None and (not isinstance(n_reached, int) or n_reached != int(np.count_nonzero(reached))):
        raise r.fail(f"the file declares n_reached = {n_reached} but /voxels/reached marks "
                     f"{int(np.count_nonzero(reached))} poses")
    return flat, reached, index, best


def _check_poses(r: _Checker, flat: np.ndarray, reached: np.ndarray, lower: np.ndarray,
                 upper: np.ndarray) -> PoseSolutions:
    pv, po_i4 = r.arrays["poses/voxel"], r.arrays["poses/orientation"]
    q, w = r.finite("poses/q"), r.finite("poses/manipulability")
    K, (V, M) = pv.size, reached.shape
    rows = np.searchsorted(flat, pv)
    po = po_i4.astype(np.int64)
    ok = (rows < V) & (po >= 0) & (po < M)
    ok[ok] &= flat[rows[ok]] == pv[ok]
    if not ok.all():
        raise r.fail(f"/poses entry {int(np.flatnonzero(~ok)[0])} names a voxel or orientation the map does not have")
    key = rows * M + po
    del rows, po, ok
    hit = reached.reshape(-1)[key]
    if not hit.all():
        raise r.fail(f"/poses entry {int(np.flatnonzero(~hit)[0])} stores a solution of a pose marked unreached")
    seen = np.zeros(V * M, dtype=bool)
    seen[key] = True
    if int(np.count_nonzero(seen)) != K or K != int(np.count_nonzero(reached)):
        raise r.fail("/poses must hold exactly one solution per reached pose")
    del seen, key
    out = (q < lower - 1e-9) | (q > upper + 1e-9)
    if out.any():
        raise r.fail(f"/poses/q entry {int(np.flatnonzero(out.any(axis=1))[0])} lies outside the joint limits")
    if np.any(w < 0):
        raise r.fail("/poses/manipulability holds a negative value")
    return PoseSolutions(pv, po_i4, q, w)
