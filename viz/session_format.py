"""The session file format: records, the table of member kinds, reading (bounded, validated) and writing.

A session file is a zip archive holding ``session.json`` (format name, version, metadata
and an index of everything) and one ``.npy`` member per array (little-endian float64,
read with ``allow_pickle=False``), plus ``robots/<i>.urdf`` for embedded URDFs. Full spec
in docs/viz.md. Files users exchange are hostile until checked, so the reader:

- looks at the zip's end-of-directory record before :mod:`zipfile` parses the directory
  (a directory of millions of entries is refused before it fills memory);
- parses ``session.json`` under a size cap, refusing NaN/Infinity, duplicate keys, lone
  surrogates and nesting deeper than :attr:`SessionLimits.max_json_depth`;
- checks every array reference of the index against the table below (dtype, rank,
  shared dimensions) and the zip directory (one entry per member, a known compression,
  a declared size that the index's shape explains and that deflate can produce from the
  stored bytes), and the total against :class:`SessionLimits`, **before reading a byte**;
- reads each member streaming into a preallocated array (the ``.npy`` header must repeat
  the index's dtype and shape; at most the declared bytes are ever inflated);
- caps text members (URDF) and refuses XML with a DOCTYPE or entity declarations.

Every problem raises :class:`SessionFormatError` naming the file, the member or field, and
why. The kinds of content (robots, objects, trajectories, ...) are rows of :data:`KINDS`:
a new kind is a record class, an encoder, a decoder and its array specs.

Frames and units: positions in metres, angles in radians, times in seconds.
"""

from __future__ import annotations

import json
import math
import os
import re
import struct
import threading
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any, BinaryIO, Callable, Mapping

import numpy as np

from pinarms.robots.errors import InvalidInput

from ._atomic import atomic_write
from .errors import SessionFormatError
from .names import NAME_RE

__all__ = [
    "FORMAT_NAME",
    "FORMAT_VERSION",
    "JSON_MEMBER",
    "SessionLimits",
    "DEFAULT_LIMITS",
    "RobotEntry",
    "BoxObject",
    "TrajectoryRecord",
    "WorkspaceRecord",
    "PointSet",
    "HistoryRecord",
    "ArraySpec",
    "TextSpec",
    "Kind",
    "KINDS",
    "SessionContents",
    "read_session",
    "write_session",
    "to_document",
    "check_name",
    "check_mesh_paths",
]

FORMAT_NAME = "pinarms-session"
FORMAT_VERSION = 1
JSON_MEMBER = "session.json"

POINT_KINDS = ("via", "target", "contact")
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


# ---------------------------------------------------------------------------- records
from .session_records import (  # noqa: E402  (the records: their own module, re-exported here)
    BoxObject,
    HistoryRecord,
    PointSet,
    RobotEntry,
    TrajectoryRecord,
    WorkspaceRecord,
    check_name,
)


# ---------------------------------------------------------------------------- the table of kinds
from .reach_record import decode_reachability, encode_reachability  # noqa: E402  (a kind defined in its own module)
from .line_record import decode_line, encode_line  # noqa: E402  (a belt line: its own module)


@dataclass(frozen=True)
class ArraySpec:
    """An array field of an item: ``shape`` entries are ints (fixed), or names of dimensions.

    A named dimension takes the first value met in the item and every other use must
    repeat it; ``"nq"`` is bound to the joint count of the item's robot. ``min_rows``
    bounds the first dimension from below. ``columns=True``: the field is a JSON object of
    named arrays of this shape (history columns), ``required`` names those that must exist.
    """

    field: str
    shape: tuple[int | str, ...]
    allow_inf: bool = False
    min_rows: int = 0
    columns: bool = False
    required: tuple[str, ...] = ()


@dataclass(frozen=True)
class TextSpec:
    """A text member of an item (UTF-8), referenced by the JSON field ``field`` (or null when ``optional``)."""

    field: str
    member: str  # pattern with {i}
    xml: bool = False


@dataclass(frozen=True)
class Kind:
    """One kind of session content: a list ``section`` of ``session.json``, a dict ``attr`` of the Session.

    ``encode(record)`` gives the item's JSON fields (without arrays and texts), its arrays
    ({field: array} or, for ``columns`` specs, {field: {column: array}}) and its texts
    ({field: text or None}). ``decode(item)`` builds the record from a validated
    :class:`_Item` (JSON fields checked with ``item.field``, arrays and texts already read).
    """

    section: str
    attr: str
    what: str
    key_field: str
    arrays: tuple[ArraySpec, ...]
    encode: Callable[[Any], tuple[dict, dict, dict]]
    decode: Callable[["_Item"], Any]
    texts: tuple[TextSpec, ...] = ()
    robot_ref: str | None = None  # "required" / "optional": the item's "robot" field names a session robot
    optional: bool = False  # the section may be absent (written only when it has items): older files lack it


def _encode_robot(e: RobotEntry) -> tuple[dict, dict, dict]:
    fields = {"key": e.key, "source": e.source, "name": e.name, "tcp_frame": e.tcp_frame,
              "joint_names": list(e.joint_names), "package_dirs": list(e.package_dirs)}
    if e.payload is not None:  # written only when there is one: sessions without stay as they were
        fields["payload"] = e.payload
    return fields, {"base_to_world": e.base_to_world}, {"urdf_member": e.urdf_text}


def _decode_robot(it: _Item) -> RobotEntry:
    source = it.field("source", str)
    if source not in ("registry", "urdf"):
        raise it.fail(f"{it.where}.source must be 'registry' or 'urdf', got {source!r}")
    if (it.texts.get("urdf_member") is None) != (source == "registry"):
        raise it.fail(f"{it.where} has source {source!r} but {'an' if source == 'registry' else 'no'} urdf_member")
    dirs = it.field("package_dirs", list)
    if not all(isinstance(d, str) for d in dirs):
        raise it.fail(f"{it.where}.package_dirs must be a list of strings")
    payload = None
    if "payload" in it.obj:
        from pinarms.robots.dynamics import InvalidPayload, Payload

        try:
            payload = Payload.from_dict(it.field("payload", dict)).as_dict()
        except InvalidPayload as exc:
            raise it.fail(f"{it.where}.payload: {exc}") from None
    return RobotEntry(key=it.key, source=source, name=it.field("name", str), tcp_frame=it.field("tcp_frame", str),
                      joint_names=it.joint_names, base_to_world=it.arrays["base_to_world"],
                      urdf_text=it.texts.get("urdf_member"), package_dirs=tuple(dirs), payload=payload)


def _encode_box(b: BoxObject) -> tuple[dict, dict, dict]:
    return {"name": b.name, "shape": "box", "color": list(b.color)}, {"size": b.size, "pose": b.pose}, {}


def _decode_box(it: _Item) -> BoxObject:
    shape = it.field("shape", str)
    if shape != "box":
        raise it.fail(f"{it.where}.shape {shape!r} is not known (this version knows 'box')")
    color = it.field("color", list)
    if len(color) != 4 or not all(isinstance(c, (int, float)) and not isinstance(c, bool) and 0 <= c <= 1
                                  for c in color):
        raise it.fail(f"{it.where}.color must be 4 RGBA numbers in [0, 1]")
    return BoxObject(it.key, it.arrays["size"], it.arrays["pose"], tuple(float(c) for c in color))


def _encode_trajectory(r: TrajectoryRecord) -> tuple[dict, dict, dict]:
    return ({"name": r.name, "robot": r.robot, "definition": r.definition},
            {"t": r.t, "q": r.q, "knot_times": r.knot_times}, {})


def _decode_trajectory(it: _Item) -> TrajectoryRecord:
    if "definition" not in it.obj or not (it.obj["definition"] is None or isinstance(it.obj["definition"], dict)):
        raise it.fail(f"{it.where}.definition must be a JSON object or null")
    t = it.arrays["t"]
    if np.any(np.diff(t) <= 0):
        raise it.fail(f"{it.where}.t must hold at least 2 strictly increasing instants")
    return TrajectoryRecord(it.key, it.robot, t, it.arrays["q"], it.arrays["knot_times"], it.obj["definition"])


def _encode_workspace(r: WorkspaceRecord) -> tuple[dict, dict, dict]:
    return {"name": r.name, "robot": r.robot}, {"points": r.points, "manipulability": r.manipulability}, {}


def _decode_workspace(it: _Item) -> WorkspaceRecord:
    return WorkspaceRecord(it.key, it.robot, it.arrays["points"], it.arrays["manipulability"])


def _encode_points(p: PointSet) -> tuple[dict, dict, dict]:
    return {"name": p.name, "kind": p.kind, "robot": p.robot}, {"points": p.points}, {}


def _decode_points(it: _Item) -> PointSet:
    kind = it.field("kind", str)
    if kind not in POINT_KINDS:
        raise it.fail(f"{it.where}.kind must be one of {POINT_KINDS}, got {kind!r}")
    return PointSet(it.key, kind, it.robot, it.arrays["points"])


def _encode_history(h: HistoryRecord) -> tuple[dict, dict, dict]:
    return {"name": h.name}, {"columns": dict(h.columns)}, {}


def _decode_history(it: _Item) -> HistoryRecord:
    return HistoryRecord(it.key, dict(it.arrays["columns"]))


#: the kinds of content, in file order (robots first: the others refer to them)
KINDS: tuple[Kind, ...] = (
    Kind("robots", "robots", "robot", "key", (ArraySpec("base_to_world", (4, 4)),), _encode_robot, _decode_robot,
         texts=(TextSpec("urdf_member", "robots/{i}.urdf", xml=True),)),
    Kind("objects", "objects", "object", "name", (ArraySpec("size", (3,)), ArraySpec("pose", (4, 4))),
         _encode_box, _decode_box),
    Kind("trajectories", "trajectories", "trajectory", "name",
         (ArraySpec("t", ("N",), min_rows=2), ArraySpec("q", ("N", "nq")), ArraySpec("knot_times", ("K",))),
         _encode_trajectory, _decode_trajectory, robot_ref="required"),
    Kind("workspaces", "workspaces", "workspace", "name",
         (ArraySpec("points", ("N", 3)), ArraySpec("manipulability", ("N",))),
         _encode_workspace, _decode_workspace, robot_ref="required"),
    Kind("points", "point_sets", "point set", "name", (ArraySpec("points", ("N", 3)),),
         _encode_points, _decode_points, robot_ref="optional"),
    Kind("histories", "histories", "history", "name",
         (ArraySpec("columns", ("G",), allow_inf=True, columns=True, required=("best",)),),
         _encode_history, _decode_history),
    Kind("reachability", "reachability", "reachability map", "name",
         (ArraySpec("centres", ("N", 3), min_rows=1), ArraySpec("index", ("N",)), ArraySpec("manipulability", ("N",))),
         encode_reachability, decode_reachability, robot_ref="required", optional=True),
    Kind("lines", "lines", "line", "name", (ArraySpec("belt_to_world", (4, 4)), ArraySpec("items", ("N", 9))),
         encode_line, decode_line, optional=True),
)


@dataclass
class SessionContents:
    """What a session file holds: ``metadata`` and one dict per kind (``tables[kind.attr][name] = record``)."""

    metadata: dict
    tables: dict[str, dict[str, Any]] = field(default_factory=dict)


# ---------------------------------------------------------------------------- writing
def to_document(metadata: dict, tables: Mapping[str, Mapping[str, Any]]) -> tuple[dict, dict[str, np.ndarray], dict[str, str]]:
    """The ``session.json`` document, the arrays by member name, and the text members."""
    arrays: dict[str, np.ndarray] = {}
    texts: dict[str, str] = {}
    doc: dict[str, Any] = {"format": FORMAT_NAME, "version": FORMAT_VERSION, "metadata": metadata}

    def ref(member: str, arr: np.ndarray) -> dict:
        arrays[member] = arr
        return {"member": member, "dtype": arr.dtype.str, "shape": list(arr.shape)}

    for kind in KINDS:
        items = []
        for i, rec in enumerate(tables.get(kind.attr, {}).values()):
            fields, arrs, txts = kind.encode(rec)
            for spec in kind.texts:
                text = txts.get(spec.field)
                member = None if text is None else spec.member.format(i=i)
                if member is not None:
                    texts[member] = text
                fields[spec.field] = member
            for spec in kind.arrays:
                value = arrs[spec.field]
                base = f"arrays/{kind.section}/{i}"
                if spec.columns:
                    fields[spec.field] = {k: ref(f"{base}/{c}.npy", v) for c, (k, v) in enumerate(value.items())}
                else:
                    fields[spec.field] = ref(f"{base}/{spec.field}.npy", value)
            items.append(fields)
        if items or not kind.optional:
            doc[kind.section] = items
    return doc, arrays, texts


def write_session(path: str | os.PathLike, metadata: dict, tables: Mapping[str, Mapping[str, Any]]) -> Path:
    """Write a session file at ``path`` (one zip, atomically, arrays streamed); return the path."""
    doc, arrays, texts = to_document(metadata, tables)
    try:
        payload = json.dumps(doc, indent=1, allow_nan=False, ensure_ascii=False).encode("utf-8")
    except (TypeError, ValueError) as exc:  # UnicodeEncodeError is a ValueError
        raise InvalidInput(f"the session cannot be written as JSON: {exc}") from exc

    def write(f: BinaryIO) -> None:
        with zipfile.ZipFile(f, "w", compression=zipfile.ZIP_DEFLATED) as zf:
            zf.writestr(JSON_MEMBER, payload)
            for member, text in texts.items():
                zf.writestr(member, text.encode("utf-8"))
            for member, arr in arrays.items():
                info = zipfile.ZipInfo(member, date_time=(1980, 1, 1, 0, 0, 0))
                info.compress_type = zipfile.ZIP_DEFLATED
                with zf.open(info, "w", force_zip64=arr.nbytes > 1 << 30) as out:
                    np.save(out, np.ascontiguousarray(arr), allow_pickle=False)

    return atomic_write(path, write)


# ---------------------------------------------------------------------------- reading
def _fail(path: Path, what: str) -> SessionFormatError:
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


def _check_json_values(doc: Any, path: Path, max_depth: int) -> None:
    """Depth, finite numbers and UTF-8-writable strings, without recursion."""
    stack = [(doc, 1)]
    while stack:
        obj, depth = stack.pop()
        if isinstance(obj, (dict, list)):
            if depth > max_depth:
                raise _fail(path, f"{JSON_MEMBER} nests deeper than {max_depth} levels")
            values = obj.values() if isinstance(obj, dict) else obj
            stack.extend((v, depth + 1) for v in values)
            if isinstance(obj, dict):
                stack.extend((k, depth) for k in obj)
        elif isinstance(obj, float) and not math.isfinite(obj):
            raise _fail(path, f"{JSON_MEMBER} holds a number too large for float64")
        elif isinstance(obj, str):
            try:
                obj.encode("utf-8")
            except UnicodeEncodeError:
                raise _fail(path, f"{JSON_MEMBER} holds a string with a lone surrogate ({obj[:40]!r})") from None


def _no_duplicate_keys(pairs: list[tuple[str, Any]]) -> dict:
    out = dict(pairs)
    if len(out) != len(pairs):
        seen: set = set()
        dup = next(k for k, _ in pairs if k in seen or seen.add(k))
        raise ValueError(f"duplicate key {dup!r} in one object")
    return out


def _bad_constant(name: str) -> Any:
    raise ValueError(f"{name} is not allowed (JSON has no NaN or Infinity)")


def _valid_member_name(member: str) -> bool:
    if not member or len(member) > 400 or "\\" in member or "\x00" in member or member.startswith("/"):
        return False
    return all(part not in ("", ".", "..") for part in member.split("/"))


@dataclass
class _ArrayRef:
    member: str
    shape: tuple[int, ...]
    allow_inf: bool
    where: str

    @property
    def nbytes(self) -> int:
        return math.prod(self.shape) * F8.itemsize


class _Item:
    """One item of a section while it is read: JSON object, where it is, its arrays and texts."""

    def __init__(self, reader: _Reader, kind: Kind, obj: Any, i: int) -> None:
        self.reader = reader
        self.kind = kind
        self.where = f"{kind.section}[{i}]"
        self.index = i
        if not isinstance(obj, dict):
            raise self.fail(f"{self.where} must be a JSON object")
        self.obj = obj
        self.key = reader.name_of(obj, kind.key_field, self.where)
        self.robot: str | None = None
        self.joint_names: tuple[str, ...] = ()
        self.refs: dict[str, Any] = {}  # field -> _ArrayRef or {column: _ArrayRef}
        self.text_members: dict[str, zipfile.ZipInfo | None] = {}
        self.arrays: dict[str, Any] = {}
        self.texts: dict[str, str | None] = {}

    def fail(self, what: str) -> SessionFormatError:
        return self.reader.fail(what)

    def field(self, key: str, types: type | tuple) -> Any:
        return self.reader.field(self.obj, key, types, self.where)


class _Reader:
    """Validating, bounded reader of one session archive; every problem becomes a SessionFormatError."""

    def __init__(self, path: Path, zf: zipfile.ZipFile, limits: SessionLimits) -> None:
        self.path = path
        self.zf = zf
        self.limits = limits
        self.total = 0
        self.used: set[str] = set()

    def fail(self, what: str) -> SessionFormatError:
        return _fail(self.path, what)

    # ------------------------------------------------------------ json fields
    def field(self, obj: Any, key: str, types: type | tuple, where: str) -> Any:
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

    def text_ref(self, member: Any, where: str) -> zipfile.ZipInfo:
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

    def array_ref(self, ref: Any, where: str, spec: ArraySpec, dims: dict[str, int]) -> _ArrayRef:
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
        arr_ref = _ArrayRef(member, tuple(shape), spec.allow_inf, where)
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

    def read_array(self, ref: _ArrayRef) -> np.ndarray:
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
        try:
            doc = json.loads(raw.decode("utf-8"), object_pairs_hook=_no_duplicate_keys, parse_constant=_bad_constant)
        except (UnicodeDecodeError, ValueError) as exc:  # JSONDecodeError and int digit limits are ValueErrors
            raise self.fail(f"{JSON_MEMBER} is not valid UTF-8 JSON ({str(exc)[:200]})") from None
        except RecursionError:
            raise self.fail(f"{JSON_MEMBER} nests deeper than {self.limits.max_json_depth} levels") from None
        _check_json_values(doc, self.path, self.limits.max_json_depth)
        return doc


def read_session(path: str | os.PathLike, limits: SessionLimits | None = None) -> SessionContents:
    """Read and validate a session file, bounded by ``limits`` (default :data:`DEFAULT_LIMITS`).

    Raises:
        SessionFormatError: anything wrong with the file (see the module docstring).
        InvalidInput: ``path`` does not exist or is a folder; ``limits`` is not a SessionLimits.
    """
    limits = DEFAULT_LIMITS if limits is None else limits
    if not isinstance(limits, SessionLimits):
        raise InvalidInput(f"limits must be a viz.SessionLimits, got {type(limits).__name__}")
    p = Path(path)
    if not p.is_file():
        raise InvalidInput(f"session file {str(p)!r} does not exist (or is not a file)")
    try:
        fp = open(p, "rb")
    except OSError as exc:
        raise SessionFormatError(f"cannot read session {str(p)!r}: {exc}") from None
    with fp:
        try:
            directory = _directory_size(fp)
        except (OSError, struct.error):
            directory = None
        if directory is None:
            raise _fail(p, "not a zip archive, or truncated (its directory is missing)")
        entries, cd_bytes = directory
        if entries > limits.max_members or cd_bytes > limits.max_members * 1024:
            raise _fail(p, f"its zip directory lists {entries:,} entries in {cd_bytes:,} bytes; a session has at most "
                           f"{limits.max_members:,} (limit max_members)")
        fp.seek(0)
        try:
            zf = zipfile.ZipFile(fp, "r")
        except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, ValueError, struct.error, NotImplementedError):
            raise _fail(p, "not a zip archive, or truncated (its directory is missing)") from None
        except OSError as exc:
            raise SessionFormatError(f"cannot read session {str(p)!r}: {exc}") from None
        with zf:
            names = zf.namelist()
            if len(names) > limits.max_members:
                raise _fail(p, f"it holds {len(names):,} members; at most {limits.max_members:,} (limit max_members)")
            if len(set(names)) != len(names):
                seen: set = set()
                dup = next(n for n in names if n in seen or seen.add(n))
                raise _fail(p, f"member {dup!r} appears twice in the zip directory")
            return _read(_Reader(p, zf, limits))


def _read(r: _Reader) -> SessionContents:
    doc = r.document()
    if not isinstance(doc, dict):
        raise r.fail(f"{JSON_MEMBER} must hold a JSON object")
    if doc.get("format") != FORMAT_NAME:
        raise r.fail(f"{JSON_MEMBER} has format {str(doc.get('format'))[:100]!r}, expected {FORMAT_NAME!r}")
    version = doc.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise r.fail(f"format version {str(version)[:40]!r} is not a positive integer")
    if version > FORMAT_VERSION:
        raise SessionFormatError(
            f"{str(r.path)!r} was written in session format version {version}, newer than this pinarms reads "
            f"(up to {FORMAT_VERSION}); upgrade pinarms to open it"
        )
    meta = r.field(doc, "metadata", dict, "session")
    for k, typ in (("title", str), ("created", str), ("pinarms_version", str), ("user", dict)):
        r.field(meta, k, typ, "metadata")
    out = SessionContents(metadata=meta)

    # pass 1: the index (names, references, declared shapes and sizes) before any member is read
    plan: list[tuple[Kind, list[_Item]]] = []
    robots_nq: dict[str, tuple[str, ...]] = {}
    for kind in KINDS:
        items: list[_Item] = []
        seen: set[str] = set()
        listed = r.field(doc, kind.section, list, "session") if (kind.section in doc or not kind.optional) else []
        for i, obj in enumerate(listed):
            it = _Item(r, kind, obj, i)
            if it.key in seen:
                raise r.fail(f"{kind.what} name {it.key!r} appears twice")
            seen.add(it.key)
            dims: dict[str, int] = {}
            if kind.section == "robots":
                joints = it.field("joint_names", list)
                if not joints or not all(isinstance(j, str) for j in joints):
                    raise r.fail(f"{it.where}.joint_names must be a non-empty list of strings")
                it.joint_names = tuple(joints)
                robots_nq[it.key] = it.joint_names
            if kind.robot_ref is not None:
                key = it.obj.get("robot") if kind.robot_ref == "optional" else it.field("robot", str)
                if key is not None:
                    if not isinstance(key, str) or key not in robots_nq:
                        raise r.fail(f"{it.where}.robot {str(key)[:100]!r} is not one of the session's robots "
                                     f"({', '.join(robots_nq) or 'none'})")
                    it.robot = key
                    dims["nq"] = len(robots_nq[key])
            for spec in kind.arrays:
                where = f"{it.where}.{spec.field}"
                if spec.columns:
                    cols = it.field(spec.field, dict)
                    for req in spec.required:
                        if req not in cols:
                            raise r.fail(f"{where} lacks {req!r}")
                    refs = {}
                    for col, ref in cols.items():
                        if not NAME_RE.match(col):
                            raise r.fail(f"{where} column name {col[:100]!r} is not a valid name")
                        refs[col] = r.array_ref(ref, f"{where}.{col}", spec, dims)
                    it.refs[spec.field] = refs
                else:
                    it.refs[spec.field] = r.array_ref(it.field(spec.field, dict), where, spec, dims)
            for tspec in kind.texts:
                member = it.obj.get(tspec.field)
                it.text_members[tspec.field] = None if member is None else r.text_ref(member, f"{it.where}.{tspec.field}")
            items.append(it)
        plan.append((kind, items))

    # pass 2: read members (bounded, streamed) and build the records
    for kind, items in plan:
        table: dict[str, Any] = {}
        for it in items:
            for tspec in kind.texts:
                info = it.text_members[tspec.field]
                it.texts[tspec.field] = None if info is None else r.read_text(info, tspec.xml)
            for fname, ref in it.refs.items():
                it.arrays[fname] = ({c: r.read_array(x) for c, x in ref.items()} if isinstance(ref, dict)
                                    else r.read_array(ref))
            table[it.key] = kind.decode(it)
        out.tables[kind.attr] = table
    return out


# ---------------------------------------------------------------------------- meshes of embedded URDFs
_MESH_SUFFIXES = (".stl", ".dae", ".obj", ".ply", ".glb", ".gltf", ".3ds", ".fbx")


def check_mesh_paths(urdf_text: str, package_dirs: tuple[str, ...], source: str, *,
                     recorded: tuple[str, ...] = ()) -> tuple[str, ...]:
    """Refuse an embedded URDF whose meshes may lie outside the allowed folders ``package_dirs``.

    ``package_dirs`` are the folders the *caller* allows (:func:`viz.load_session` passes the
    session file's own folder and its ``package_dirs`` argument); folders named inside the
    file (``recorded``, the ``package_dirs`` of ``session.json``) never widen them.
    Pinocchio resolves ``package://p`` (and ``model://p``) and relative paths ``p`` against
    each allowed folder, and uses absolute paths and ``file://`` URLs as they are. Each must
    name a mesh file (``.stl``, ``.dae``, ...) that lies, symbolic links followed, inside
    one of the allowed folders: ``..`` escapes, absolute paths elsewhere, other URL schemes
    and non-regular files (devices, FIFOs) are refused. A package-relative mesh found in no
    allowed folder is refused when the file names folders of its own that were not passed
    (the message says which to pass); otherwise it is left to the viewer (which reports it).
    Recorded folders that lie inside an allowed folder (links followed) are searched too.

    Returns:
        The folders to resolve meshes against: the recorded ones inside the allowed folders,
        then the allowed folders.

    Raises:
        SessionFormatError: naming the robot and the mesh path, and what to pass instead.
    """
    import xml.etree.ElementTree as ET

    if re.search(r"<!\s*(DOCTYPE|ENTITY)", urdf_text, re.IGNORECASE):
        raise SessionFormatError(f"{source}: the URDF declares a DOCTYPE or entities; entity expansion is refused")
    try:
        root = ET.fromstring(urdf_text)
    except ET.ParseError as exc:
        raise SessionFormatError(f"{source}: the embedded URDF is not well-formed XML ({exc})") from None
    roots = [Path(d).resolve() for d in package_dirs if isinstance(d, str) and d]
    where = f"the allowed folders {[str(b) for b in roots]}" if roots else "the allowed folders (none)"
    inside, unlisted = [], []
    for d in recorded:
        try:
            real = Path(d).resolve() if isinstance(d, str) and os.path.isabs(d) else None
        except (ValueError, OSError):  # a NUL byte, a path too long: never a folder to search
            real = None
        if real is not None and any(real.is_relative_to(b) for b in roots):
            inside.append(real)
        elif isinstance(d, str) and d:
            unlisted.append(d)
    bases = list(dict.fromkeys(inside + roots))
    how = ("if you trust that folder, pass it: viz.load_session(path, package_dirs=[...]) or "
           "--package-dir FOLDER on the command line")
    for mesh in root.iter("mesh"):
        name = mesh.get("filename", "")
        shown = repr(name[:200])
        scheme, sep, rest = name.partition("://")
        if not sep:
            scheme, rest = "", name
        if scheme not in ("", "package", "model", "file"):
            raise SessionFormatError(f"{source}: mesh {shown} uses the URL scheme {scheme!r}; only package://, "
                                     f"model://, file:// and plain paths are read")
        rel = PurePosixPath(rest)
        if rel.suffix.lower() not in _MESH_SUFFIXES:
            raise SessionFormatError(f"{source}: mesh {shown} is not a mesh file ({', '.join(_MESH_SUFFIXES)})")
        absolute = scheme == "file" or rel.is_absolute()
        if absolute:
            if not rel.is_absolute():
                raise SessionFormatError(f"{source}: mesh {shown} is a file:// URL without an absolute path")
            if not any(Path(rest).resolve().is_relative_to(b) for b in roots):
                raise SessionFormatError(f"{source}: mesh {shown} lies outside {where}; {how}")
            candidates = [Path(rest)]
        else:
            if ".." in rel.parts or not rel.parts:
                raise SessionFormatError(f"{source}: mesh {shown} leaves its package folder ('..')")
            # Pinocchio tries <dir>/<path>; some versions also <dir>/<path without its package name>
            tails = [rel.parts] + ([rel.parts[1:]] if scheme and len(rel.parts) > 1 else [])
            candidates = [base.joinpath(*tail) for base in bases for tail in tails]
        found = False
        for cand in candidates:
            if not os.path.lexists(cand):
                continue
            found = True
            real = cand.resolve()
            if not any(real.is_relative_to(base) for base in roots):
                raise SessionFormatError(f"{source}: mesh {shown} resolves to {str(real)!r}, outside {where}; {how}")
            if not real.is_file():
                raise SessionFormatError(f"{source}: mesh {shown} resolves to {str(real)!r}, which is not a "
                                         f"regular file")
        if not found and not absolute and unlisted:
            raise SessionFormatError(
                f"{source}: mesh {shown} is in none of {where}; the session file names the folder(s) "
                f"{[d[:200] for d in unlisted[:5]]}, which a session cannot allow by itself: {how}")
    return tuple(str(b) for b in bases)
