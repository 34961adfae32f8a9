"""The bounded reader of a session archive: limits, the zip directory, members, ``session.json``.

A session file is a zip archive holding ``session.json`` and one ``.npy`` member per array
(little-endian float64) plus text members (embedded URDFs). Files users exchange are hostile
until checked, so :func:`open_archive` and :class:`ArchiveReader`:

- look at the zip's end-of-directory record before :mod:`zipfile` parses the directory
  (a directory of millions of entries is refused before it fills memory);
- parse ``session.json`` under a size cap, refusing NaN/Infinity, duplicate keys, lone
  surrogates and nesting deeper than :attr:`SessionLimits.max_json_depth`
  (:mod:`pinarms.viz.session_json`);
- check each member reference against the zip directory (one entry per member, a known
  compression, a declared size that the reference's shape explains and that deflate can
  produce from the stored bytes) and the total against :class:`SessionLimits`, before
  reading a byte;
- read each array streaming into a preallocated array (the ``.npy`` header must repeat
  the declared dtype and shape; at most the declared bytes are ever inflated, never with
  pickle);
- cap text members and refuse XML with a DOCTYPE or entity declarations.

Every problem raises :class:`SessionFormatError` naming the file, the member or field, and why.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import struct
import threading
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO, Iterator

import numpy as np

from pinarms.files import open_regular
from pinarms.errors import InvalidInput

from pinarms.viz.errors import SessionFormatError
from pinarms.viz.names import NAME_RE
from pinarms.viz.session_json import JSON_MEMBER, parse_document

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.viz.session_specs import ArraySpec

__all__ = ["JSON_MEMBER", "F8", "SessionLimits", "DEFAULT_LIMITS", "ArrayRef", "ArchiveReader", "open_archive",
           "invalid_session"]

F8 = np.dtype("<f8")

MiB = 1 << 20


@dataclass(frozen=True)
class SessionLimits:
    """What :func:`read_session` accepts before reading anything (bytes are uncompressed sizes).

    Attributes:
        max_total_bytes: all arrays and texts of the session together.
        max_array_bytes: one array member (its data, header excluded).
        max_text_bytes: one text member (an embedded URDF).
        max_json_bytes: ``session.json``.
        max_json_depth: nesting of ``session.json`` (objects and lists).
        max_members: entries of the zip directory.
    """

    max_total_bytes: int = 1024 * MiB
    max_array_bytes: int = 512 * MiB
    max_text_bytes: int = 16 * MiB
    max_json_bytes: int = 64 * MiB
    max_json_depth: int = 64
    max_members: int = 20_000

    def __post_init__(self) -> None:
        for k in ("max_total_bytes", "max_array_bytes", "max_text_bytes", "max_json_bytes", "max_json_depth",
                  "max_members"):
            v = getattr(self, k)
            if isinstance(v, bool) or not isinstance(v, int) or v <= 0:
                raise InvalidInput(f"SessionLimits.{k} must be a positive integer, got {v!r}")


DEFAULT_LIMITS = SessionLimits()

#: the largest expansion deflate can produce (258 bytes from 2 bits): about 1032 : 1
_DEFLATE_MAX_RATIO = 1032
#: room for an .npy header (numpy pads it to 64 bytes; ours are < 200 bytes)
_NPY_HEADER_MAX = 4096
#: numpy parses a .npy header with ``ast``, which CPython 3.11 cannot run from several threads at once
#: ("AST constructor recursion depth mismatch", CPython gh-106905): one header at a time.
_NPY_HEADER_LOCK = threading.Lock()
_TAIL_MAX = 22 + 0xFFFF  # end-of-central-directory record plus the longest comment


def invalid_session(path: Path, what: str) -> SessionFormatError:
    """The error saying that the file at ``path`` is not a valid session, and why."""
    return SessionFormatError(f"{str(path)!r} is not a valid pinarms session: {what}")


def _directory_size(fp: BinaryIO) -> tuple[int, int] | None:
    """(entries, bytes) of the zip's central directory from its end record, or None when there is none."""
    fp.seek(0, os.SEEK_END)
    size = fp.tell()
    tail_len = min(size, _TAIL_MAX)
    fp.seek(size - tail_len)
    tail = fp.read(tail_len)
    pos = tail.rfind(b"PK\x05\x06")
    if pos < 0 or len(tail) - pos < 22:
        return None
    _, _, _, _, entries, cd_size, _, _ = struct.unpack("<4s4H2LH", tail[pos: pos + 22])
    if (entries == 0xFFFF or cd_size == 0xFFFFFFFF) and pos >= 20 and tail[pos - 20: pos - 16] == b"PK\x06\x07":
        (z64_offset,) = struct.unpack("<Q", tail[pos - 12: pos - 4])
        if z64_offset + 56 <= size:
            fp.seek(z64_offset)
            rec = fp.read(56)
            if rec[:4] == b"PK\x06\x06":
                entries, cd_size = struct.unpack("<QQ", rec[32:48])
    return entries, cd_size


def _valid_member_name(member: str) -> bool:
    if not member or len(member) > 400 or "\\" in member or "\x00" in member or member.startswith("/"):
        return False
    return all(part not in ("", ".", "..") for part in member.split("/"))


@dataclass
class ArrayRef:
    """An array member as ``session.json`` declares it, checked against the zip directory (not read yet)."""

    member: str
    shape: tuple[int, ...]
    allow_inf: bool
    where: str

    @property
    def nbytes(self) -> int:
        return math.prod(self.shape) * F8.itemsize


class ArchiveReader:
    """Validating, bounded reader of one session archive; every problem becomes a SessionFormatError."""

    def __init__(self, path: Path, zf: zipfile.ZipFile, limits: SessionLimits) -> None:
        self.path = path
        self.zf = zf
        self.limits = limits
        self.total = 0
        self.used: set[str] = set()

    def fail(self, what: str) -> SessionFormatError:
        return invalid_session(self.path, what)

    # ------------------------------------------------------------ json fields
    def field(self, obj: object, key: str, types: type | tuple, where: str) -> Any:
        if not isinstance(obj, dict):
            raise self.fail(f"{where} must be a JSON object")
        if key not in obj:
            raise self.fail(f"{where} lacks the field {key!r}")
        value = obj[key]
        allowed = types if isinstance(types, tuple) else (types,)
        if not isinstance(value, allowed) or (isinstance(value, bool) and bool not in allowed):
            raise self.fail(f"{where}.{key} has the wrong type ({type(value).__name__})")
        return value

    def name_of(self, obj: dict, key: str, where: str) -> str:
        name = self.field(obj, key, str, where)
        if not NAME_RE.match(name):
            raise self.fail(f"{where}.{key} {name!r} is not a valid name")
        return name

    # ------------------------------------------------------------ members
    def info(self, member: str, where: str) -> zipfile.ZipInfo:
        """The zip entry of ``member``: present once, referenced once, a known compression, a plausible size."""
        if not _valid_member_name(member):
            raise self.fail(f"{where} names member {member[:100]!r}, which is not a plain relative path inside the archive")
        if member in self.used:
            raise self.fail(f"member {member!r} is referenced twice ({where})")
        self.used.add(member)
        try:
            info = self.zf.getinfo(member)
        except KeyError:
            raise self.fail(f"member {member!r} is missing (the file is incomplete)") from None
        if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            raise self.fail(f"member {member!r} uses compression method {info.compress_type}; sessions use deflate")
        if info.flag_bits & 0x1:
            raise self.fail(f"member {member!r} is encrypted")
        if info.compress_type == zipfile.ZIP_STORED and info.compress_size != info.file_size:
            raise self.fail(f"member {member!r} is stored uncompressed but declares {info.file_size} bytes "
                            f"from {info.compress_size}")
        if info.file_size > (info.compress_size + 1) * _DEFLATE_MAX_RATIO:
            raise self.fail(f"member {member!r} declares {info.file_size:,} bytes from {info.compress_size:,} "
                            f"compressed bytes, more than deflate can produce (a forged zip directory)")
        return info

    def charge(self, nbytes: int, member: str) -> None:
        self.total += nbytes
        if self.total > self.limits.max_total_bytes:
            raise self.fail(f"its members add up to more than {self.limits.max_total_bytes:,} bytes at {member!r} "
                            f"(limit max_total_bytes; raise it with load_session(..., limits=SessionLimits(...)) "
                            f"if you trust this file)")

    def read_bytes(self, member: str, info: zipfile.ZipInfo, cap: int, what: str) -> bytes:
        if info.file_size > cap:
            raise self.fail(f"member {member!r} declares {info.file_size:,} bytes, more than the {cap:,} allowed "
                            f"for {what}")
        try:
            with self.zf.open(info) as f:
                data = f.read(cap + 1)
                if len(data) != info.file_size:
                    raise self.fail(f"member {member!r} holds another size than its zip entry declares")
                return data
        except SessionFormatError:
            raise
        except (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError, NotImplementedError) as exc:
            raise self.fail(f"member {member!r} is corrupt ({exc})") from None

    def text_ref(self, member: object, where: str) -> zipfile.ZipInfo:
        """Check a text member's entry and size before reading (cap :attr:`SessionLimits.max_text_bytes`)."""
        if not isinstance(member, str):
            raise self.fail(f"{where} must be a member name or null")
        info = self.info(member, where)
        if info.file_size > self.limits.max_text_bytes:
            raise self.fail(f"member {member!r} declares {info.file_size:,} bytes, more than the "
                            f"{self.limits.max_text_bytes:,} allowed for a text member (limit max_text_bytes)")
        self.charge(info.file_size, member)
        return info

    def read_text(self, info: zipfile.ZipInfo, xml: bool) -> str:
        member = info.filename
        try:
            text = self.read_bytes(member, info, self.limits.max_text_bytes, "a text member").decode("utf-8")
        except UnicodeDecodeError:
            raise self.fail(f"member {member!r} is not UTF-8 text") from None
        if xml and re.search(r"<!\s*(DOCTYPE|ENTITY)", text, re.IGNORECASE):
            raise self.fail(f"member {member!r} declares a DOCTYPE or entities; sessions embed plain URDF "
                            f"(entity expansion is refused)")
        return text

    def array_ref(self, ref: object, where: str, spec: ArraySpec, dims: dict[str, int]) -> ArrayRef:
        member = self.field(ref, "member", str, where)
        dtype = self.field(ref, "dtype", str, where)
        shape = self.field(ref, "shape", list, where)
        if dtype != F8.str:
            raise self.fail(f"{where} declares dtype {dtype!r}; this version stores float64 ({F8.str!r}) only")
        if not all(isinstance(s, int) and not isinstance(s, bool) and 0 <= s < 1 << 62 for s in shape):
            raise self.fail(f"{where}.shape must be a list of non-negative integers, got {str(shape)[:100]}")
        want = "(" + ", ".join(str(d) for d in spec.shape) + ("," if len(spec.shape) == 1 else "") + ")"
        if len(shape) != len(spec.shape):
            raise self.fail(f"{where} (member {member!r}) has shape {tuple(shape)}, expected {want}")
        bound = dict(dims)
        for s, d in zip(shape, spec.shape):
            if isinstance(d, str) and d not in bound:
                bound[d] = s
            expected = bound[d] if isinstance(d, str) else d
            if s != expected:
                exp = "(" + ", ".join(str(bound.get(x, x)) for x in spec.shape) + ("," if len(shape) == 1 else "") + ")"
                raise self.fail(f"member {member!r} has shape {tuple(shape)}, expected {exp}")
        if shape and shape[0] < spec.min_rows:
            raise self.fail(f"{where} holds {shape[0]} rows; at least {spec.min_rows} are needed")
        dims.update(bound)
        arr_ref = ArrayRef(member, tuple(shape), spec.allow_inf, where)
        nbytes = arr_ref.nbytes
        if nbytes > self.limits.max_array_bytes:
            raise self.fail(f"member {member!r} declares shape {tuple(shape)} ({nbytes:,} bytes), more than the "
                            f"{self.limits.max_array_bytes:,} allowed for one array (limit max_array_bytes)")
        info = self.info(member, where)
        if not nbytes <= info.file_size <= nbytes + _NPY_HEADER_MAX:
            raise self.fail(f"member {member!r} holds {info.file_size:,} bytes in the zip directory, but "
                            f"session.json's shape {tuple(shape)} needs {nbytes:,} bytes plus a header")
        self.charge(info.file_size, member)
        return arr_ref

    def read_array(self, ref: ArrayRef) -> np.ndarray:
        """The member as a read-only float64 array, streamed: at most its declared bytes are inflated."""
        member = ref.member
        try:
            with self.zf.open(member) as f:
                try:
                    with _NPY_HEADER_LOCK:
                        version = np.lib.format.read_magic(f)
                        if version == (1, 0):
                            shape, fortran, dtype = np.lib.format.read_array_header_1_0(f, max_header_size=_NPY_HEADER_MAX)
                        elif version == (2, 0):
                            shape, fortran, dtype = np.lib.format.read_array_header_2_0(f, max_header_size=_NPY_HEADER_MAX)
                        else:
                            raise ValueError(f"unknown .npy version {version}")
                except (ValueError, EOFError, SyntaxError, TypeError, OverflowError) as exc:
                    raise self.fail(f"member {member!r} is not a readable .npy array ({exc})") from None
                if dtype.hasobject:
                    raise self.fail(f"member {member!r} is not a readable .npy array (an object array: pickled data "
                                    f"is never loaded)")
                if dtype != F8:
                    raise self.fail(f"member {member!r} has dtype {dtype}, expected float64")
                if tuple(shape) != ref.shape:
                    raise self.fail(f"member {member!r} has shape {tuple(shape)}, but session.json says {ref.shape}")
                arr = np.empty(ref.shape[::-1] if fortran else ref.shape, dtype=F8)
                view = memoryview(arr.reshape(-1)).cast("B")
                pos, n = 0, len(view)
                while pos < n:
                    chunk = f.read(min(n - pos, 4 * MiB))
                    if not chunk:
                        raise self.fail(f"member {member!r} ends after {pos:,} of its {n:,} data bytes")
                    view[pos: pos + len(chunk)] = chunk
                    pos += len(chunk)
                if f.read(1):
                    raise self.fail(f"member {member!r} holds more bytes than its shape {ref.shape} needs")
        except SessionFormatError:
            raise
        except (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError, NotImplementedError) as exc:
            raise self.fail(f"member {member!r} is corrupt ({exc})") from None
        if fortran:
            arr = arr.T
        bad = np.isnan(arr).any() if ref.allow_inf else not np.isfinite(arr).all()
        if bad:
            raise self.fail(f"member {member!r} holds NaN{'' if ref.allow_inf else ' or infinite'} values")
        arr = np.ascontiguousarray(arr)
        arr.flags.writeable = False
        return arr

    # ------------------------------------------------------------ session.json
    def document(self) -> dict:
        info = self.zf.NameToInfo.get(JSON_MEMBER)
        if info is None:
            raise self.fail(f"member {JSON_MEMBER!r} is missing (the file is incomplete)")
        self.info(JSON_MEMBER, "the archive")
        raw = self.read_bytes(JSON_MEMBER, info, self.limits.max_json_bytes, JSON_MEMBER)
        return parse_document(raw, self.fail, self.limits.max_json_depth)

@contextlib.contextmanager
def open_archive(path: str | os.PathLike, limits: SessionLimits) -> Iterator[ArchiveReader]:
    """The reader of the session archive at ``path``, its zip directory checked against ``limits``.

    The directory's size is read from its end record before :mod:`zipfile` parses it; then
    the number of members and their names (each once) are checked.

    Raises:
        SessionFormatError: not a zip, truncated, too many members, a member twice.
        InvalidInput: ``path`` does not exist or is a folder.
    """
    p = Path(path)
    try:  # checked on the open file: a FIFO, a device or a folder is refused unread
        fp = open_regular(p, "session file", error=InvalidInput)
    except OSError as exc:
        raise SessionFormatError(f"cannot read session {str(p)!r}: {exc}") from None
    with fp:
        try:
            directory = _directory_size(fp)
        except (OSError, struct.error):
            directory = None
        if directory is None:
            raise invalid_session(p, "not a zip archive, or truncated (its directory is missing)")
        entries, cd_bytes = directory
        if entries > limits.max_members or cd_bytes > limits.max_members * 1024:
            raise invalid_session(p, f"its zip directory lists {entries:,} entries in {cd_bytes:,} bytes; a session "
                                     f"has at most {limits.max_members:,} (limit max_members)")
        fp.seek(0)
        try:
            zf = zipfile.ZipFile(fp, "r")
        except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, ValueError, struct.error, NotImplementedError):
            raise invalid_session(p, "not a zip archive, or truncated (its directory is missing)") from None
        except OSError as exc:
            raise SessionFormatError(f"cannot read session {str(p)!r}: {exc}") from None
        with zf:
            names = zf.namelist()
            if len(names) > limits.max_members:
                raise invalid_session(p, f"it holds {len(names):,} members; at most {limits.max_members:,} "
                                         f"(limit max_members)")
            if len(set(names)) != len(names):
                seen: set = set()
                dup = next(n for n in names if n in seen or seen.add(n))
                raise invalid_session(p, f"member {dup!r} appears twice in the zip directory")
            yield ArchiveReader(p, zf, limits)
