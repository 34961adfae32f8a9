"""The task map file (``.npz``): written by :meth:`~.task_maps.TaskMap.save`, read back behind bounds.

A zip archive of ``.npy`` members (no pickle): ``du``, ``w``, ``approach``, ``leave``,
``branch_approach``, ``branch_leave`` (float64), ``scalars`` (track, release, speed, mass,
build seconds), ``branches``, ``fixture_infeasible`` (int64), ``station`` and ``checksum``
(text): the SHA-256 of every value (:func:`map_checksum`), checked on load, so a flipped byte
is found instead of silently changing a pick time. Since maps measure their dependence on the
item's yaw: ``yaw_scalars`` (yaw period [rad], measured yaw spread) and, for a map with a yaw
coordinate, ``yaw`` (ny,) and ``yaw_approach``, ``yaw_leave`` (ny, nb, nu, nw) (float64), in the
checksum after the others; a file without them (written before) reads as a map without a yaw
coordinate whose yaw dependence was never measured.

Reading (:func:`read_map_file`): a regular file of at most :data:`MAX_FILE_BYTES`; the zip's
end record read first (at most :data:`MAX_MEMBERS` members); each member's declared size
checked against :data:`MAX_MEMBER_BYTES` and the total against :data:`MAX_TOTAL_BYTES` before
a byte is inflated, then inflated up to its declared size only; each ``.npy`` header parsed
and its shape checked against the bytes it holds before any array is made. Every fault is a
:class:`~.errors.TaskMapError` naming the file and the member.
"""

from __future__ import annotations

import hashlib
import io
import os
import struct
import zipfile
from typing import Any

import numpy as np

from pinarms.files import open_regular
from pinarms.optim.line.errors import TaskMapError
from pinarms.optim.line.task_map_checks import MAX_MAP_VALUES

__all__ = ["map_checksum", "map_members", "read_map_file", "MAX_FILE_BYTES", "MAX_MEMBER_BYTES", "MAX_TOTAL_BYTES",
           "MAX_MEMBERS"]

#: Largest task map file read [bytes].
MAX_FILE_BYTES = 64 * 2**20
#: Largest member, uncompressed [bytes]: a full table and its ``.npy`` header.
MAX_MEMBER_BYTES = 8 * MAX_MAP_VALUES + 4096
#: All members together, uncompressed [bytes]: six tables at most (two per yaw layers, branches, best).
MAX_TOTAL_BYTES = 6 * MAX_MEMBER_BYTES + 2**21
#: Most members in the archive.
MAX_MEMBERS = 16
_FLOATS = ("du", "w", "approach", "leave", "scalars", "branch_approach", "branch_leave")
_YAW_FLOATS = ("yaw_scalars", "yaw", "yaw_approach", "yaw_leave")  # after the others: old files keep their checksum
_INTS = ("branches", "fixture_infeasible")
_TEXTS = ("station", "checksum")
_NEEDED = ("du", "w", "approach", "leave", "scalars", "station")


def map_checksum(fields: dict[str, Any]) -> str:
    """SHA-256 (hex) of a map's values: name, dtype, shape and little-endian bytes of each field."""
    h = hashlib.sha256(b"pinarms-task-map-1")
    for key in (*_FLOATS, *_INTS, *(k for k in _YAW_FLOATS if k in fields)):
        a = np.ascontiguousarray(fields[key], dtype="<i8" if key in _INTS else "<f8")
        h.update(f"|{key}|{a.shape}|".encode())
        h.update(a.tobytes())
    h.update(b"|station|" + str(fields["station"]).encode("utf-8", "surrogatepass"))
    return h.hexdigest()


def map_members(m: Any) -> dict[str, np.ndarray]:
    """The arrays a :class:`~.task_maps.TaskMap` is saved as, with their checksum."""
    fields = {"du": m.du, "w": m.w, "approach": m.approach, "leave": m.leave,
              "scalars": np.array([m.track, m.release, m.speed, m.mass, m.build_seconds]),
              "branch_approach": m.branch_approach if m.branch_approach is not None else m.approach[None],
              "branch_leave": m.branch_leave if m.branch_leave is not None else m.leave[None],
              "branches": np.array(m.branches, dtype=np.int64), "fixture_infeasible": np.array(m.fixture_infeasible,
                                                                                                  dtype=np.int64),
              "station": np.array(m.station)}
    if m.yaw is not None or not np.isnan(m.yaw_spread):  # a map read from an older file is written as it was
        fields["yaw_scalars"] = np.array([m.yaw_period, m.yaw_spread])
    if m.yaw is not None:
        fields.update(yaw=m.yaw, yaw_approach=m.yaw_approach, yaw_leave=m.yaw_leave)
    return {**fields, "checksum": np.array(map_checksum(fields))}


def read_map_file(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """The members of a task map file as arrays, every bound above checked (module doc); the
    checksum compared by the caller with the values it builds."""
    with open_regular(path, "task map file", error=TaskMapError) as fh:
        size = os.fstat(fh.fileno()).st_size
        if size > MAX_FILE_BYTES:
            raise TaskMapError(f"task map file {str(path)!r} is {size} bytes; the limit is {MAX_FILE_BYTES} bytes")
        _check_directory(fh, size, path)
        try:
            with zipfile.ZipFile(fh) as z:
                infos = _checked_infos(z, path)
                return {name: _array(_inflate(z, info, path), name, path) for name, info in infos.items()}
        except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, OSError, NotImplementedError, RuntimeError,
                struct.error) as exc:
            raise _bad(path, f"a damaged zip archive ({exc})") from None


def _bad(path: Any, what: str) -> TaskMapError:
    return TaskMapError(f"{str(path)!r} is not a task map file: {what}; rebuild the map (build_task_map, "
                        "TaskMap.save)")


def _check_directory(fh: Any, size: int, path: Any) -> None:
    """The zip end record (no comment: TaskMap.save writes none) read before zipfile parses anything."""
    if size < 22:
        raise _bad(path, "not a zip archive (too short)")
    fh.seek(size - 22)
    end = fh.read(22)
    fh.seek(0)
    if end[:4] != b"PK\x05\x06":
        raise _bad(path, "not a zip archive, or truncated (its end record is missing)")
    entries = struct.unpack("<H", end[10:12])[0]
    if entries > MAX_MEMBERS:
        raise _bad(path, f"its zip directory lists {entries} members; a task map has at most {MAX_MEMBERS}")


def _checked_infos(z: zipfile.ZipFile, path: Any) -> dict[str, zipfile.ZipInfo]:
    """Member name (without ``.npy``) -> its entry; names, counts and declared sizes checked."""
    infos = z.infolist()
    if len(infos) > MAX_MEMBERS:
        raise _bad(path, f"{len(infos)} members; a task map has at most {MAX_MEMBERS}")
    out: dict[str, zipfile.ZipInfo] = {}
    total = 0
    for info in infos:
        name = info.filename[:-4] if info.filename.endswith(".npy") else ""
        if name not in (*_FLOATS, *_YAW_FLOATS, *_INTS, *_TEXTS) or name in out:
            raise _bad(path, f"unexpected or repeated member {info.filename!r}")
        if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            raise _bad(path, f"member {info.filename!r} is compressed with method {info.compress_type}")
        if info.file_size > MAX_MEMBER_BYTES:
            raise _bad(path, f"member {info.filename!r} declares {info.file_size} bytes; a member holds at most "
                             f"{MAX_MEMBER_BYTES}")
        total += info.file_size
        out[name] = info
    if total > MAX_TOTAL_BYTES:
        raise _bad(path, f"its members declare {total} bytes in all; a task map holds at most {MAX_TOTAL_BYTES}")
    missing = [n for n in _NEEDED if n not in out]
    if missing:
        raise _bad(path, f"member {missing[0]}.npy is missing")
    return out


def _inflate(z: zipfile.ZipFile, info: zipfile.ZipInfo, path: Any) -> bytes:
    """The member's bytes, inflated up to its declared size only (zipfile stops there and checks the CRC)."""
    with z.open(info) as f:
        data = f.read(info.file_size + 1)
    if len(data) != info.file_size:
        raise _bad(path, f"member {info.filename!r} holds {len(data)} bytes, its entry says {info.file_size}")
    return data


def _array(data: bytes, name: str, path: Any) -> np.ndarray:
    """The ``.npy`` member ``name`` as an array: its header parsed and its shape checked against its bytes first."""
    buf = io.BytesIO(data)
    try:
        version = np.lib.format.read_magic(buf)
        shape, fortran, dtype = (np.lib.format.read_array_header_1_0(buf) if version == (1, 0)
                                 else np.lib.format.read_array_header_2_0(buf))
    except (ValueError, SyntaxError, TypeError) as exc:
        raise _bad(path, f"member {name}.npy has no valid .npy header ({exc})") from None
    want = "<f8" if name in (*_FLOATS, *_YAW_FLOATS) else "<i8" if name in _INTS else None
    if (dtype.str != want) if want else (dtype.kind != "U" or dtype.itemsize > 4 * 256 or shape != ()):
        raise _bad(path, f"member {name}.npy has dtype {dtype.str} and shape {shape}")
    count = int(np.prod(shape, dtype=object))
    if count * dtype.itemsize != len(data) - buf.tell():
        raise _bad(path, f"member {name}.npy declares shape {shape} but holds {len(data) - buf.tell()} bytes")
    a = np.frombuffer(data, dtype=dtype, count=count, offset=buf.tell())
    return a.reshape(shape, order="F" if fortran else "C").copy()
