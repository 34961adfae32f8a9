"""Inspect and read one reachability map file inside a bounded child process (run by :mod:`pinarms.robots.reach.reach_io`).

This file runs as a script (``python -I _reach_worker.py``) in a child process whose address
space, CPU time and file writes the parent limits and whose wall-clock time it bounds. It
imports only the standard library, NumPy and h5py, and loads ``robots/_sandbox.py`` (one folder
up) by path, never pinarms (nor Pinocchio); the parent imports it only for the tables below.

Before the map is opened by h5py the process walls itself in (:func:`enter_wall`, with
Landlock): it can then read only the map file and Python's own folders, and write, create,
remove or execute nothing, whatever a damaged file makes libhdf5 do.

Protocol: one JSON request on stdin ``{"path", "solutions", "max_bytes", "limits": {...}}``;
on stdout a sequence of frames ``tag (1 byte) + length (4 bytes, little-endian) + payload``:

- ``R`` (empty): the interpreter is up with h5py imported; the file is opened only after this frame.
- ``M`` (JSON): the attributes, the arrays to come (name, dtype, shape) and the wall the
  reader is behind, sent once every declared layout is checked, before any data is read.
- ``D`` (raw bytes): the next bytes of the current array, arrays in the manifest's order,
  C order, the dtype of the manifest (little-endian). No Python object is ever pickled.
- ``E`` (JSON ``{"message": ...}``): the file is refused; ``K`` (empty): every array was sent.

Checks before any data is read (each refusal names the member): links other than hard
links, virtual datasets, external storage, filters other than gzip/shuffle/fletcher32/lzf,
the dtype, the shape against the fixed sizes and the sizes shared between members (the
joints of ``/robot``, the orientations ``M``, the groups, the voxels ``V`` at most the grid's,
the stored solutions ``K`` at most ``V·M`` and equal to the ``n_reached`` attribute when
present), the total bytes against the budget, and the storage: a fill value other than
zero, chunks larger than ``max_chunk_bytes`` or more than ``max_chunks`` of them, and
chunks or contiguous data never written are refused (a map writer writes every byte).
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import stat
import struct
import sys
from pathlib import Path

FORMAT_NAME = "pinarms-reachability"
FORMAT_VERSION = 1
MAX_TEXT = 1_000_000

#: (group, attribute, kind, required), read in this order; kind is str, int, float, bool or "ints"
ATTRIBUTES = (
    ("/", "robot", "str", True), ("/", "urdf_sha256", "str", True), ("/", "tcp_frame", "str", True),
    ("/", "solver", "str", True), ("/", "manipulability", "str", True), ("/", "resolution", "float", True),
    ("/", "shape", "ints", True), ("/", "parameters", "str", True), ("/", "n_reached", "int", False),
    ("/", "checksum", "str", False), ("/", "poses_checksum", "str", False),
    ("/robot", "joint_names", "str", True),
    ("/orientations", "kind", "str", True), ("/orientations", "roll_free", "bool", True),
    ("/orientations", "n_groups", "int", True), ("/orientations", "parameters", "str", True),
)
#: (member, dtype, shape): ints are fixed sizes, letters sizes shared between members
#: (nq: joints, M: orientations, G: groups, V: computed voxels, K: stored solutions)
DATASETS = (
    ("robot/joint_lower", "<f8", ("nq",)), ("robot/joint_upper", "<f8", ("nq",)), ("grid/origin", "<f8", (3,)),
    ("orientations/rotations", "<f8", ("M", 3, 3)), ("orientations/group", "<i4", ("M",)),
    ("orientations/directions", "<f8", ("G", 3)), ("orientations/tool_axis", "<f8", (3,)),
    ("voxels/flat", "<i8", ("V",)), ("voxels/index", "<f8", ("V",)), ("voxels/best_manipulability", "<f8", ("V",)),
    ("voxels/reached", "|u1", ("V", "M")),
)
POSES = (
    ("poses/voxel", "<i8", ("K",)), ("poses/orientation", "<i4", ("K",)), ("poses/q", "<f8", ("K", "nq")),
    ("poses/manipulability", "<f8", ("K",)),
)
ALLOWED_FILTERS = {1: "gzip", 2: "shuffle", 3: "fletcher32", 32000: "lzf"}


class Refused(Exception):
    """The file is not a map pinarms reads; the message says what and where."""


class Newer(Exception):
    """The file is written in a newer format version (the argument)."""


def _send(tag: bytes, payload: bytes | memoryview = b"") -> None:
    out = sys.stdout.buffer
    out.write(tag + struct.pack("<I", len(payload)))
    if len(payload):
        out.write(payload)
    out.flush()


def _attr(h5, group: str, key: str, kind: str, required: bool):
    where = "the file" if group == "/" else group
    try:
        obj = h5 if group == "/" else h5[group.strip("/")]
        if key not in obj.attrs:
            if required:
                raise Refused(f"attribute {key!r} of {where} is missing")
            return None
        value = obj.attrs[key]
    except Refused:
        raise
    except Exception as exc:
        raise Refused(f"attribute {key!r} of {where} cannot be read ({type(exc).__name__}: {exc})") from None
    return _typed(value, key, kind, where)


def _typed(value, key: str, kind: str, where: str):
    import numpy as np

    if kind == "str":
        if isinstance(value, bytes):
            try:
                value = value.decode("utf-8")
            except UnicodeDecodeError:
                raise Refused(f"attribute {key!r} of {where} is not UTF-8 text") from None
        if not isinstance(value, str) or len(value) > MAX_TEXT:
            raise Refused(f"attribute {key!r} of {where} must be text of at most {MAX_TEXT} characters")
        try:
            value.encode("utf-8")
        except UnicodeEncodeError:  # lone surrogates from undecodable bytes
            raise Refused(f"attribute {key!r} of {where} is not UTF-8 text") from None
        return value
    if kind == "bool":
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        raise Refused(f"attribute {key!r} of {where} must be a boolean")
    if kind == "int":
        if isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
            return int(value)
        raise Refused(f"attribute {key!r} of {where} must be an integer")
    if kind == "float":
        if isinstance(value, (float, int, np.floating, np.integer)) and not isinstance(value, (bool, np.bool_)):
            return float(value)
        raise Refused(f"attribute {key!r} of {where} must be a number")
    arr = np.asarray(value)
    if arr.dtype.kind not in "iu" or arr.size > 16:
        raise Refused(f"attribute {key!r} of {where} must be a short integer array")
    return [int(v) for v in arr.reshape(-1)] if arr.ndim else [int(arr)]


def _dataset(h5, name: str):
    import h5py

    parts = name.split("/")
    where = h5
    for i, part in enumerate(parts):
        sub = "/".join(parts[: i + 1])
        try:
            link = where.get(part, getlink=True)
        except Exception as exc:  # a damaged B-tree raises from the library
            raise Refused(f"member /{sub} cannot be read ({type(exc).__name__}: {exc})") from None
        if link is None:
            raise Refused(f"member /{sub} is missing")
        if not isinstance(link, h5py.HardLink):
            raise Refused(f"member /{sub} is a {type(link).__name__} (links to other objects or files are refused)")
        try:
            where = where[part]
        except Exception as exc:
            raise Refused(f"member /{sub} cannot be opened ({type(exc).__name__}: {exc})") from None
    if not isinstance(where, h5py.Dataset):
        raise Refused(f"member /{name} is not a dataset")
    return where


class _Layout:
    """Checks the declared layout of every member; binds the shared sizes; counts the budget."""

    def __init__(self, h5, max_bytes: int, limits: dict, dims: dict, bounds: dict) -> None:
        self.h5, self.budget, self.limits, self.dims, self.bounds = h5, int(max_bytes), limits, dims, bounds

    def check(self, name: str, dtype: str, shape: tuple) -> dict:
        import numpy as np

        d = _dataset(self.h5, name)
        where = f"dataset /{name}"
        try:
            if d.is_virtual:
                raise Refused(f"{where} is a virtual dataset (data from other files is refused)")
            if d.external:
                raise Refused(f"{where} keeps its data in external files (refused)")
            plist = d.id.get_create_plist()
            filters = [plist.get_filter(i)[0] for i in range(plist.get_nfilters())]
            actual_dtype, actual_shape, chunks = d.dtype, d.shape, d.chunks
        except Refused:
            raise
        except Exception as exc:
            raise Refused(f"{where} cannot be inspected ({type(exc).__name__}: {exc})") from None
        bad = [f for f in filters if f not in ALLOWED_FILTERS]
        if bad:
            raise Refused(f"{where} uses HDF5 filter(s) {bad}; only gzip, shuffle, fletcher32 and lzf are accepted")
        if actual_dtype != np.dtype(dtype):
            raise Refused(f"{where} has dtype {actual_dtype}, expected {np.dtype(dtype)}")
        fixed = [s if isinstance(s, int) else self.dims.get(s) for s in shape]
        if actual_shape is None or len(actual_shape) != len(shape) or any(
            s is not None and s != a for s, a in zip(fixed, actual_shape)
        ):
            want = "(" + ", ".join(str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
            raise Refused(f"{where} has shape {actual_shape}, expected {want}")
        nbytes = math.prod(actual_shape) * np.dtype(dtype).itemsize
        if nbytes > self.budget:
            raise Refused(
                f"{where} would take {nbytes / 1e6:.1f} MB in memory, more than the {self.budget / 1e6:.1f} MB left of "
                "max_bytes; pass a larger max_bytes if you trust the file"
            )
        self.budget -= nbytes
        for s, a in zip(shape, actual_shape):
            if isinstance(s, str) and s not in self.dims:
                low, high, why = self.bounds[s]()
                if not low <= a <= high:
                    raise Refused(f"{where} declares {a} {why}")
                self.dims[s] = a
        self._storage(d, where, nbytes, chunks, np.dtype(dtype))
        return {"name": name, "dtype": np.dtype(dtype).str, "shape": list(actual_shape), "nbytes": nbytes,
                "chunk_rows": int(chunks[0]) if chunks and len(chunks) else 1}

    def _storage(self, d, where: str, nbytes: int, chunks, dtype) -> None:
        import numpy as np

        try:
            fill = d.fillvalue
            stored = d.id.get_storage_size()
        except Exception as exc:
            raise Refused(f"{where} cannot be inspected ({type(exc).__name__}: {exc})") from None
        if fill is not None and np.asarray(fill).tobytes() != bytes(dtype.itemsize):
            raise Refused(f"{where} declares the fill value {np.asarray(fill).item()!r}; maps are written with 0 "
                          "(a fill value makes chunks that were never written read as data)")
        if nbytes == 0:
            return
        if chunks is None:
            if stored != nbytes:
                raise Refused(f"{where} stores {stored} bytes for the {nbytes} its shape needs (never written, or cut)")
            return
        chunk_bytes = math.prod(chunks) * dtype.itemsize
        if chunk_bytes > self.limits["max_chunk_bytes"]:
            raise Refused(f"{where} has chunks of {chunk_bytes / 1e6:.1f} MB, more than the "
                          f"{self.limits['max_chunk_bytes'] / 1e6:.0f} MB a map reader accepts")
        declared = math.prod(-(-s // c) for s, c in zip(d.shape, chunks))
        if declared > self.limits["max_chunks"]:
            raise Refused(f"{where} is split into {declared} chunks, more than the {self.limits['max_chunks']} "
                          "a map reader accepts")
        try:
            written = d.id.get_num_chunks()
        except Exception as exc:
            raise Refused(f"{where} has a damaged chunk index ({type(exc).__name__}: {exc})") from None
        if written != declared:
            raise Refused(f"{where} declares {declared} chunks but {written} are written (a map writer writes them all)")


def _inspect(h5, req: dict) -> tuple[dict, list]:
    """Attributes and the checked layout of every member to read, before any data is read."""
    fmt = _attr(h5, "/", "format", "str", True)
    if fmt != FORMAT_NAME:
        raise Refused(f"format is {fmt!r}, expected {FORMAT_NAME!r}")
    version = _attr(h5, "/", "version", "int", True)
    if version < 1:
        raise Refused(f"format version {version} is not a positive integer")
    if version > FORMAT_VERSION:
        raise Newer(version)
    attrs: dict = {"/": {"format": fmt, "version": version}, "/robot": {}, "/orientations": {}}
    for group, key, kind, required in ATTRIBUTES:
        attrs[group][key] = _attr(h5, group, key, kind, required)
    shape = attrs["/"]["shape"]
    n_grid = math.prod(shape) if len(shape) == 3 and min(shape) >= 1 else 0
    if n_grid == 0 or n_grid > req["limits"]["max_grid_voxels"]:
        raise Refused(f"shape must be 3 positive integers with at most {req['limits']['max_grid_voxels']} voxels, "
                      f"got {shape} (more than allowed, or not positive)")
    try:
        joints = json.loads(attrs["/robot"]["joint_names"])
    except (ValueError, RecursionError):
        raise Refused("attribute 'joint_names' of /robot is not valid JSON") from None
    max_joints, max_m = req["limits"]["max_joints"], req["limits"]["max_orientations"]
    if not isinstance(joints, list) or not 1 <= len(joints) <= max_joints:
        raise Refused(f"/robot joint_names must list 1 to {max_joints} joint names")
    n_groups = attrs["/orientations"]["n_groups"]
    if not 1 <= n_groups <= max_m:
        raise Refused(f"/orientations n_groups must be in [1, {max_m}], got {n_groups}")
    n_reached = attrs["/"]["n_reached"]
    dims = {"nq": len(joints), "G": n_groups}
    bounds = {
        "M": lambda: (1, max_m, f"orientations; expected 1 to {max_m}"),
        "V": lambda: (0, n_grid, f"voxels, more than the {n_grid} of the grid"),
        "K": lambda: ((0, dims["V"] * dims["M"], f"stored solutions, more than the {dims['V'] * dims['M']} poses "
                       f"of /voxels/reached") if n_reached is None else
                      (n_reached, n_reached, f"stored solutions, but the file declares n_reached = {n_reached}")),
    }
    if n_reached is not None and not 0 <= n_reached <= n_grid * max_m:
        raise Refused(f"attribute 'n_reached' of the file must be a count of poses, got {n_reached}")
    layout = _Layout(h5, req["max_bytes"], req["limits"], dims, bounds)
    arrays = [layout.check(name, dtype, shape) for name, dtype, shape in DATASETS]
    if n_reached is not None and n_reached > dims["V"] * dims["M"]:
        raise Refused(f"attribute 'n_reached' of the file is {n_reached}, more than the {dims['V'] * dims['M']} "
                      "poses of /voxels/reached")
    if req["solutions"] and "poses" in h5:
        arrays += [layout.check(name, dtype, shape) for name, dtype, shape in POSES]
    return attrs, arrays


def _stream(h5, arrays: list, slice_bytes: int) -> None:
    """Send every array in slices of whole chunk rows; check the solution count before /poses."""
    import numpy as np

    reached = None
    for spec in arrays:
        if spec["name"].startswith("poses/") and reached is not None and spec["shape"][0] != reached:
            raise Refused(f"/poses holds {spec['shape'][0]} solutions for the {reached} reached poses of "
                          "/voxels/reached (one per reached pose)")
        if spec["nbytes"] == 0:
            continue
        d = h5[spec["name"]]
        shape, dtype = spec["shape"], np.dtype(spec["dtype"])
        row_bytes = max(1, math.prod(shape[1:]) * dtype.itemsize)
        band = spec["chunk_rows"]
        rows = max(1, slice_bytes // row_bytes)
        rows = rows // band * band if rows >= band else rows
        count = 0
        whole = np.empty([min(rows, shape[0]), *shape[1:]], dtype=dtype)
        for start in range(0, shape[0], rows):
            stop = min(start + rows, shape[0])
            buf = whole[: stop - start]
            try:
                d.read_direct(buf, source_sel=np.s_[start:stop])
            except MemoryError:
                raise
            except Exception as exc:  # truncated chunk, checksum mismatch, corrupt deflate stream, ...
                raise Refused(f"dataset /{spec['name']} cannot be read: the file is truncated or corrupt "
                              f"({type(exc).__name__}: {exc})") from None
            if spec["name"] == "voxels/reached":
                count += int(np.count_nonzero(buf))
            _send(b"D", memoryview(buf).cast("B"))
        if spec["name"] == "voxels/reached":
            reached = count


def _load_sandbox():
    """``robots/_sandbox.py`` (one folder up), loaded by path (this script imports no pinarms module)."""
    path = Path(__file__).resolve().parent.parent / "_sandbox.py"
    spec = importlib.util.spec_from_file_location("pinarms_reach_child_sandbox", path)
    sandbox = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(sandbox)
    return sandbox


def enter_wall(path: str) -> tuple[str, object]:
    """Wall this process in before the map is parsed; which wall is up and what h5py is to open.

    The map is opened first (without blocking; anything but a regular file is refused). Under
    Landlock the process may then read only that file and Python's folders, and h5py opens
    it by name. Without Landlock a root process drops to the user ``nobody``, which may not
    reach the map's folder: h5py then reads the file object opened before.
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as exc:
        raise Refused(f"it cannot be opened ({exc.strerror})") from None
    handle = os.fdopen(fd, "rb", buffering=0)
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        handle.close()
        raise Refused("it is not a regular file")
    wall = _load_sandbox().enter_wall([path])
    if wall.startswith("user nobody"):
        return wall, handle
    handle.close()
    return wall, path


def main() -> None:
    import h5py  # imported before the ready frame: the parent's bound on the file's inspection starts there

    _send(b"R")
    req = json.loads(sys.stdin.buffer.read(1 << 20))
    try:
        wall, source = enter_wall(req["path"])
        try:
            h5 = h5py.File(source, "r", rdcc_nbytes=req["limits"]["max_chunk_bytes"] * 2, rdcc_w0=1.0)
        except Exception as exc:  # OSError for a truncated or non-HDF5 file
            raise Refused(f"not an HDF5 file, or truncated ({' '.join(str(exc).split())})") from None
        with h5:
            attrs, arrays = _inspect(h5, req)
            manifest = {"attrs": attrs, "arrays": arrays, "wall": wall}
            _send(b"M", json.dumps(manifest, ensure_ascii=False).encode("utf-8"))
            _stream(h5, arrays, req["limits"]["slice_bytes"])
        _send(b"K")
    except Refused as exc:
        _refuse("refused", str(exc))
    except Newer as exc:
        _refuse("newer", str(exc.args[0]))
    except MemoryError:
        _refuse("memory", "")
    except RecursionError:
        _refuse("refused", "its structure nests too deeply")
    except Exception as exc:  # anything else the library raises on a damaged file
        _refuse("refused", f"it cannot be read ({type(exc).__name__}: {str(exc)[:2000]})")


def _refuse(kind: str, message: str) -> None:
    _send(b"E", json.dumps({"kind": kind, "message": message[:4000]}).encode("utf-8"))


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)  # skip the interpreter's teardown (h5py's finalisers): the parent is waiting
