"""Reachability maps in HDF5 files (h5py): written atomically, checked on load like a hostile file.

Layout (format ``pinarms-reachability``, version :data:`FORMAT_VERSION`), SI units::

    /                      attrs: format, version, pinarms_version, robot, urdf_sha256, tcp_frame,
                                  solver, manipulability, resolution [m], shape (3,), parameters (JSON)
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
raise :class:`ReachabilityFileError` naming the member and the problem. Nothing is read
before its declared size has been checked.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from .errors import InvalidInput, PinarmsError
from .orientations import MAX_ORIENTATIONS, OrientationSet
from .reachability import MAX_GRID_VOXELS, PoseSolutions, ReachabilityMap

__all__ = [
    "ReachabilityFileError",
    "StreamWriter",
    "save_reachability",
    "load_reachability",
    "FORMAT_NAME",
    "FORMAT_VERSION",
    "DEFAULT_MAX_BYTES",
]

FORMAT_NAME = "pinarms-reachability"
FORMAT_VERSION = 1
#: Largest total size of the arrays :func:`load_reachability` accepts by default [bytes].
DEFAULT_MAX_BYTES = 4 * 1024**3
_MAX_TEXT = 1_000_000
_MAX_JOINTS = 64
#: HDF5 filters a map file may use: deflate (gzip), shuffle, fletcher32, LZF.
_ALLOWED_FILTERS = {1, 2, 3, 32000}
_GZIP = {"compression": "gzip", "compression_opts": 4, "shuffle": True}


class ReachabilityFileError(PinarmsError):
    """A reachability map file is not one pinarms can trust: what is wrong and where is in the message."""


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


def _write(h5: Any, m: ReachabilityMap) -> None:
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


def _temporary(path: str | os.PathLike) -> tuple[Path, str]:
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise InvalidInput(f"cannot write {str(target)!r}: folder {str(folder)!r} does not exist; create it first")
    if target.is_dir():
        raise InvalidInput(f"cannot write {str(target)!r}: it is a folder; give a file name")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=folder)
    os.close(fd)
    return target, tmp


def _publish(tmp: str, target: Path) -> None:
    with open(tmp, "rb+") as f:
        os.fsync(f.fileno())
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    os.replace(tmp, target)


class StreamWriter:
    """Writes a map whose stored solutions arrive chunk by chunk (``reachability_map(out=...)``).

    :meth:`append` adds solutions to extendable, chunked, gzip datasets under ``/poses`` of a
    temporary file; :meth:`finish` writes the rest of the map and renames the file to its
    target; :meth:`abort` removes the temporary file. Memory: one chunk's solutions.
    """

    def __init__(self, path: str | os.PathLike, nq: int) -> None:
        import h5py

        self.target, self.tmp = _temporary(path)
        self.nq = int(nq)
        self.count = 0
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
        self.count = end

    def finish(self, reach_map: ReachabilityMap) -> Path:
        """Write the map's other members, close and rename the file; return the target path."""
        if reach_map.solutions is not None:
            raise InvalidInput("a streamed map keeps its solutions in the file, not in memory")
        if self.count != reach_map.n_reached:
            raise InvalidInput(f"{self.count} solutions were streamed for {reach_map.n_reached} reached poses")
        _write(self.h5, reach_map)
        self.h5.close()
        _publish(self.tmp, self.target)
        return self.target

    def abort(self) -> None:
        """Close and remove the temporary file (the target is left as it was)."""
        try:
            self.h5.close()
        finally:
            try:
                os.unlink(self.tmp)
            except FileNotFoundError:
                pass


def save_reachability(reach_map: ReachabilityMap, path: str | os.PathLike) -> Path:
    """Write ``reach_map`` to ``path`` (HDF5, written to a temporary file then renamed); return the path.

    Raises:
        InvalidInput: not a :class:`ReachabilityMap`, or the target folder does not exist / the
            target is a folder.
    """
    import h5py

    if not isinstance(reach_map, ReachabilityMap):
        raise InvalidInput(f"save_reachability needs a ReachabilityMap, got {type(reach_map).__name__}")
    target, tmp = _temporary(path)
    try:
        with h5py.File(tmp, "w") as h5:
            _write(h5, reach_map)
        _publish(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return target


# ----------------------------------------------------------------------------- reading
class _Reader:
    """Checks every member of one open file; each problem becomes a :class:`ReachabilityFileError`."""

    def __init__(self, path: Path, h5: Any, max_bytes: int) -> None:
        self.path = path
        self.h5 = h5
        self.budget = int(max_bytes)

    def fail(self, what: str) -> ReachabilityFileError:
        return ReachabilityFileError(f"{str(self.path)!r} is not a valid pinarms reachability map: {what}")

    def node(self, name: str) -> Any:
        import h5py

        parts = name.strip("/").split("/")
        where = self.h5
        for i, part in enumerate(parts):
            sub = "/".join(parts[: i + 1])
            try:
                link = where.get(part, getlink=True)
            except Exception as exc:  # a damaged B-tree raises from the library
                raise self.fail(f"member /{sub} cannot be read ({type(exc).__name__}: {exc})") from None
            if link is None:
                raise self.fail(f"member /{sub} is missing")
            if not isinstance(link, h5py.HardLink):
                raise self.fail(f"member /{sub} is a {type(link).__name__} (links to other objects or files are refused)")
            try:
                where = where[part]
            except Exception as exc:
                raise self.fail(f"member /{sub} cannot be opened ({type(exc).__name__}: {exc})") from None
        return where

    def has(self, name: str) -> bool:
        try:
            return self.h5.get(name.strip("/"), getlink=True) is not None
        except Exception:
            return False

    def attr(self, obj: Any, key: str, kind: type, where: str) -> Any:
        try:
            if key not in obj.attrs:
                raise self.fail(f"attribute {key!r} of {where} is missing")
            value = obj.attrs[key]
        except ReachabilityFileError:
            raise
        except Exception as exc:
            raise self.fail(f"attribute {key!r} of {where} cannot be read ({type(exc).__name__}: {exc})") from None
        if kind is str:
            if isinstance(value, bytes):
                try:
                    value = value.decode("utf-8")
                except UnicodeDecodeError:
                    raise self.fail(f"attribute {key!r} of {where} is not UTF-8 text") from None
            if not isinstance(value, str) or len(value) > _MAX_TEXT:
                raise self.fail(f"attribute {key!r} of {where} must be text of at most {_MAX_TEXT} characters")
            return value
        if kind is bool:
            if isinstance(value, (bool, np.bool_)):
                return bool(value)
            raise self.fail(f"attribute {key!r} of {where} must be a boolean")
        if kind is int:
            if isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
                return int(value)
            raise self.fail(f"attribute {key!r} of {where} must be an integer")
        if kind is float:
            if isinstance(value, (float, int, np.floating, np.integer)) and not isinstance(value, (bool, np.bool_)):
                return float(value)
            raise self.fail(f"attribute {key!r} of {where} must be a number")
        arr = np.asarray(value)
        if arr.dtype.kind not in "iu" or arr.size > 16:
            raise self.fail(f"attribute {key!r} of {where} must be a short integer array")
        return arr.astype(np.int64)

    def json(self, obj: Any, key: str, where: str, kind: type) -> Any:
        text = self.attr(obj, key, str, where)
        try:
            value = json.loads(text)
        except (json.JSONDecodeError, RecursionError):
            raise self.fail(f"attribute {key!r} of {where} is not valid JSON") from None
        if not isinstance(value, kind):
            raise self.fail(f"attribute {key!r} of {where} must be a JSON {kind.__name__}")
        return value

    def array(self, name: str, dtype: str, shape: tuple[int | None, ...]) -> np.ndarray:
        """Read dataset ``name`` after checking storage, filters, dtype, shape and the byte budget."""
        import h5py

        d = self.node(name)
        if not isinstance(d, h5py.Dataset):
            raise self.fail(f"member /{name.strip('/')} is not a dataset")
        where = f"dataset /{name.strip('/')}"
        try:
            if d.is_virtual:
                raise self.fail(f"{where} is a virtual dataset (data from other files is refused)")
            if d.external:
                raise self.fail(f"{where} keeps its data in external files (refused)")
            plist = d.id.get_create_plist()
            filters = [plist.get_filter(i)[0] for i in range(plist.get_nfilters())]
            actual_dtype, actual_shape = d.dtype, d.shape
        except ReachabilityFileError:
            raise
        except Exception as exc:
            raise self.fail(f"{where} cannot be inspected ({type(exc).__name__}: {exc})") from None
        bad = [f for f in filters if f not in _ALLOWED_FILTERS]
        if bad:
            raise self.fail(f"{where} uses HDF5 filter(s) {bad}; only gzip, shuffle, fletcher32 and lzf are accepted")
        if actual_dtype != np.dtype(dtype):
            raise self.fail(f"{where} has dtype {actual_dtype}, expected {np.dtype(dtype)}")
        if actual_shape is None or len(actual_shape) != len(shape) or any(
            s is not None and s != a for s, a in zip(shape, actual_shape)
        ):
            want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
            raise self.fail(f"{where} has shape {actual_shape}, expected {want}")
        nbytes = int(np.prod(actual_shape, dtype=np.float64)) * np.dtype(dtype).itemsize
        if nbytes > self.budget:
            raise self.fail(
                f"{where} would take {nbytes / 1e6:.1f} MB in memory, more than the {self.budget / 1e6:.1f} MB left of "
                "max_bytes; pass a larger max_bytes if you trust the file"
            )
        self.budget -= nbytes
        try:
            arr = np.empty(actual_shape, dtype=dtype)
            if arr.size:
                d.read_direct(arr)
        except Exception as exc:  # truncated chunk, checksum mismatch, corrupt deflate stream, ...
            raise self.fail(f"{where} cannot be read: the file is truncated or corrupt ({type(exc).__name__}: {exc})") from None
        return arr

    def finite(self, arr: np.ndarray, name: str, *, nan_ok: bool = False) -> np.ndarray:
        bad = np.isinf(arr) if nan_ok else ~np.isfinite(arr)
        if np.any(bad):
            raise self.fail(f"dataset {name} holds {'infinite' if nan_ok else 'NaN or infinite'} values")
        return arr


def load_reachability(path: str | os.PathLike, *, solutions: bool = True, max_bytes: int = DEFAULT_MAX_BYTES) -> ReachabilityMap:
    """Read and check a map written by :func:`save_reachability` (see the module doc for the checks).

    Args:
        solutions: also read the stored IK solution of every reached pose (``/poses``).
        max_bytes: refuse files whose arrays would take more memory than this [bytes].

    Raises:
        InvalidInput: ``path`` is not an existing file, or ``max_bytes`` is not positive.
        ReachabilityFileError: anything wrong with the file's content.
    """
    import h5py

    p = Path(path)
    if not p.is_file():
        raise InvalidInput(f"reachability map file {str(p)!r} does not exist (or is not a file)")
    if isinstance(max_bytes, bool) or not isinstance(max_bytes, (int, np.integer)) or max_bytes <= 0:
        raise InvalidInput(f"max_bytes must be a positive integer, got {max_bytes!r}")
    try:
        h5 = h5py.File(p, "r")
    except Exception as exc:  # OSError for a truncated or non-HDF5 file
        raise ReachabilityFileError(
            f"{str(p)!r} is not a valid pinarms reachability map: not an HDF5 file, or truncated ({' '.join(str(exc).split())})"
        ) from None
    with h5:
        return _read(_Reader(p, h5, max_bytes), solutions)


def _read(r: _Reader, want_solutions: bool) -> ReachabilityMap:
    root = r.h5
    fmt = r.attr(root, "format", str, "the file")
    if fmt != FORMAT_NAME:
        raise r.fail(f"format is {fmt!r}, expected {FORMAT_NAME!r}")
    version = r.attr(root, "version", int, "the file")
    if version < 1:
        raise r.fail(f"format version {version} is not a positive integer")
    if version > FORMAT_VERSION:
        raise ReachabilityFileError(
            f"{str(r.path)!r} was written in reachability format version {version}, newer than this pinarms reads "
            f"(up to {FORMAT_VERSION}); upgrade pinarms to open it"
        )
    robot = r.attr(root, "robot", str, "the file")
    sha = r.attr(root, "urdf_sha256", str, "the file")
    if len(sha) != 64 or any(c not in "0123456789abcdef" for c in sha):
        raise r.fail("urdf_sha256 is not a SHA-256 hex digest")
    tcp = r.attr(root, "tcp_frame", str, "the file")
    solver = r.attr(root, "solver", str, "the file")
    if solver not in ("analytic", "numerical"):
        raise r.fail(f"solver must be 'analytic' or 'numerical', got {solver!r}")
    manip = r.attr(root, "manipulability", str, "the file")
    if manip not in ("full", "position"):
        raise r.fail(f"manipulability must be 'full' or 'position', got {manip!r}")
    resolution = r.attr(root, "resolution", float, "the file")
    if not (np.isfinite(resolution) and resolution > 0):
        raise r.fail(f"resolution must be a positive length in m, got {resolution!r}")
    shape = r.attr(root, "shape", np.ndarray, "the file")
    if shape.shape != (3,) or np.any(shape < 1):
        raise r.fail(f"shape must be 3 positive integers, got {shape.tolist()}")
    n_grid = int(np.prod(shape.astype(np.float64)))
    if n_grid > MAX_GRID_VOXELS:
        raise r.fail(f"the grid has {n_grid} voxels, more than {MAX_GRID_VOXELS}")
    shape_t = tuple(int(v) for v in shape)
    params = r.json(root, "parameters", "the file", dict)

    joint_names = r.json(r.node("robot"), "joint_names", "/robot", list)
    nq = len(joint_names)
    if not (1 <= nq <= _MAX_JOINTS) or not all(isinstance(j, str) and 0 < len(j) <= 200 for j in joint_names):
        raise r.fail(f"/robot joint_names must list 1 to {_MAX_JOINTS} joint names")
    lower = r.finite(r.array("robot/joint_lower", "<f8", (nq,)), "/robot/joint_lower")
    upper = r.finite(r.array("robot/joint_upper", "<f8", (nq,)), "/robot/joint_upper")
    if np.any(lower > upper):
        raise r.fail("/robot joint limits have lower > upper")
    origin = r.finite(r.array("grid/origin", "<f8", (3,)), "/grid/origin")

    og = r.node("orientations")
    kind = r.attr(og, "kind", str, "/orientations")
    if kind not in ("so3", "tool_axis"):
        raise r.fail(f"/orientations kind must be 'so3' or 'tool_axis', got {kind!r}")
    roll_free = r.attr(og, "roll_free", bool, "/orientations")
    n_groups = r.attr(og, "n_groups", int, "/orientations")
    oparams = r.json(og, "parameters", "/orientations", dict)
    if not (1 <= n_groups <= MAX_ORIENTATIONS):
        raise r.fail(f"/orientations n_groups must be in [1, {MAX_ORIENTATIONS}], got {n_groups}")
    rot = r.finite(r.array("orientations/rotations", "<f8", (None, 3, 3)), "/orientations/rotations")
    M = rot.shape[0]
    if not (1 <= M <= MAX_ORIENTATIONS):
        raise r.fail(f"/orientations/rotations holds {M} rotations; expected 1 to {MAX_ORIENTATIONS}")
    ortho = np.abs(rot @ np.swapaxes(rot, 1, 2) - np.eye(3)).max()
    if ortho > 1e-9 or np.any(np.linalg.det(rot) < 0.0):
        raise r.fail("/orientations/rotations holds a matrix that is not a proper rotation")
    group = r.array("orientations/group", "<i4", (M,)).astype(np.int64)
    if np.any(group < 0) or np.any(group >= n_groups) or np.any(np.diff(group) < 0) or np.unique(group).size != n_groups:
        raise r.fail("/orientations/group must number the directions 0..n_groups-1 in order, each used")
    directions = r.finite(r.array("orientations/directions", "<f8", (n_groups, 3)), "/orientations/directions")
    tool_axis = r.finite(r.array("orientations/tool_axis", "<f8", (3,)), "/orientations/tool_axis")
    if kind == "so3" and (n_groups != M or roll_free):
        raise r.fail("/orientations of kind 'so3' must have one group per rotation and roll_free false")
    oset = OrientationSet(kind, rot, group, n_groups, roll_free, tool_axis, directions, oparams)

    flat = r.array("voxels/flat", "<i8", (None,))
    V = flat.size
    if V and (flat[0] < 0 or flat[-1] >= n_grid or np.any(np.diff(flat) <= 0)):
        raise r.fail(f"/voxels/flat must be strictly increasing flat indices in [0, {n_grid})")
    index = r.finite(r.array("voxels/index", "<f8", (V,)), "/voxels/index")
    best = r.finite(r.array("voxels/best_manipulability", "<f8", (V,)), "/voxels/best_manipulability", nan_ok=True)
    reached_u1 = r.array("voxels/reached", "u1", (V, M))
    if np.any(reached_u1 > 1):
        raise r.fail("/voxels/reached must hold only 0 and 1")
    reached = reached_u1.astype(bool)
    if roll_free:
        per_group = np.zeros((V, n_groups), dtype=bool)
        for k in range(M):
            per_group[:, group[k]] |= reached[:, k]
        expect = per_group.sum(axis=1) / n_groups
    else:
        expect = reached.sum(axis=1) / M
    if not np.array_equal(expect, index):
        row = int(np.flatnonzero(expect != index)[0])
        raise r.fail(f"/voxels/index does not follow from /voxels/reached (row {row}: {index[row]!r} vs {expect[row]!r})")
    any_reached = reached.any(axis=1)
    if np.any(np.isnan(best) == any_reached) or np.any(best[any_reached] < 0):
        raise r.fail("/voxels/best_manipulability must be >= 0 where a pose is reached and NaN elsewhere")

    sols = None
    if want_solutions and r.has("poses"):
        pv = r.array("poses/voxel", "<i8", (None,))
        K = pv.size
        po = r.array("poses/orientation", "<i4", (K,)).astype(np.int64)
        q = r.finite(r.array("poses/q", "<f8", (K, nq)), "/poses/q")
        w = r.finite(r.array("poses/manipulability", "<f8", (K,)), "/poses/manipulability")
        rows = np.searchsorted(flat, pv)
        ok = (rows < V) & (po >= 0) & (po < M)
        ok[ok] &= flat[rows[ok]] == pv[ok]
        if not ok.all():
            raise r.fail(f"/poses entry {int(np.flatnonzero(~ok)[0])} names a voxel or orientation the map does not have")
        if not reached[rows, po].all():
            raise r.fail(f"/poses entry {int(np.flatnonzero(~reached[rows, po])[0])} stores a solution of a pose marked unreached")
        key = rows * M + po
        if np.unique(key).size != K or K != int(reached.sum()):
            raise r.fail("/poses must hold exactly one solution per reached pose")
        out = (q < lower - 1e-9) | (q > upper + 1e-9)
        if out.any():
            raise r.fail(f"/poses/q entry {int(np.flatnonzero(out.any(axis=1))[0])} lies outside the joint limits")
        if np.any(w < 0):
            raise r.fail("/poses/manipulability holds a negative value")
        sols = PoseSolutions(pv, po.astype(np.int32), q, w)

    return ReachabilityMap(
        robot=robot, urdf_sha256=sha, tcp_frame=tcp, joint_names=tuple(joint_names), joint_lower=lower,
        joint_upper=upper, solver=solver, manipulability_kind=manip, origin=origin, resolution=resolution,
        shape=shape_t, orientations=oset, voxels=flat, reached=reached, index=index, best_manipulability=best,
        solutions=sols, parameters=params,
    )
