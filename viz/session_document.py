"""Validation of a session document: ``session.json``'s header, its index of items, then their members.

Reading is two passes over the kinds of :data:`pinarms.viz.session_schema.KINDS`: first the index
(names, robot references, every array's declared dtype and shape, every member's zip entry
and size, the total against the limits) **before any member is read**; then the members,
bounded and streamed (:class:`pinarms.viz.session_archive.ArchiveReader`), and each kind's decoder
builds its records. Every problem raises :class:`SessionFormatError` naming the file, the
item or member, and why.
"""

from __future__ import annotations

import zipfile
from typing import Any

from pinarms.viz.errors import SessionFormatError
from pinarms.viz.names import NAME_RE
from pinarms.viz.session_archive import JSON_MEMBER, ArchiveReader
from pinarms.viz.session_schema import FORMAT_NAME, FORMAT_VERSION, KINDS, Kind, SessionContents

__all__ = ["SessionItem", "read_document"]


class SessionItem:
    """One item of a section while it is read: JSON object, where it is, its arrays and texts."""

    def __init__(self, reader: ArchiveReader, kind: Kind, obj: Any, i: int) -> None:
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
        self.refs: dict[str, Any] = {}  # field -> ArrayRef or {column: ArrayRef}
        self.text_members: dict[str, zipfile.ZipInfo | None] = {}
        self.arrays: dict[str, Any] = {}
        self.texts: dict[str, str | None] = {}

    def fail(self, what: str) -> SessionFormatError:
        """The error naming the file and ``what`` is wrong with this item."""
        return self.reader.fail(what)

    def field(self, key: str, types: type | tuple) -> Any:
        """The item's JSON field ``key``, of one of ``types``."""
        return self.reader.field(self.obj, key, types, self.where)


def read_document(r: ArchiveReader) -> SessionContents:
    """The metadata and records of the archive read by ``r``: the index checked whole, then the members read."""
    doc = r.document()
    _check_header(r, doc)
    meta = r.field(doc, "metadata", dict, "session")
    for k, typ in (("title", str), ("created", str), ("pinarms_version", str), ("user", dict)):
        r.field(meta, k, typ, "metadata")
    return _read_members(r, SessionContents(metadata=meta), _index(r, doc))


def _check_header(r: ArchiveReader, doc: Any) -> None:
    """``session.json`` is an object of this format, in a version this pinarms reads."""
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


def _index(r: ArchiveReader, doc: dict) -> list[tuple[Kind, list[SessionItem]]]:
    """Pass 1: every item of every kind (names, references, declared shapes and sizes), before any member is read."""
    plan: list[tuple[Kind, list[SessionItem]]] = []
    robots_nq: dict[str, tuple[str, ...]] = {}
    for kind in KINDS:
        items: list[SessionItem] = []
        seen: set[str] = set()
        listed = r.field(doc, kind.section, list, "session") if (kind.section in doc or not kind.optional) else []
        for i, obj in enumerate(listed):
            it = SessionItem(r, kind, obj, i)
            if it.key in seen:
                raise r.fail(f"{kind.what} name {it.key!r} appears twice")
            seen.add(it.key)
            _index_item(r, it, robots_nq)
            items.append(it)
        plan.append((kind, items))
    return plan


def _index_item(r: ArchiveReader, it: SessionItem, robots_nq: dict[str, tuple[str, ...]]) -> None:
    """Check one item's joints (a robot, recorded in ``robots_nq``), its robot, array and text references."""
    kind = it.kind
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
    _index_arrays(r, it, dims)
    for tspec in kind.texts:
        member = it.obj.get(tspec.field)
        it.text_members[tspec.field] = None if member is None else r.text_ref(member, f"{it.where}.{tspec.field}")


def _index_arrays(r: ArchiveReader, it: SessionItem, dims: dict[str, int]) -> None:
    """Check the item's array references (one per field, or a JSON object of named columns) against its kind."""
    for spec in it.kind.arrays:
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


def _read_members(r: ArchiveReader, out: SessionContents,
                  plan: list[tuple[Kind, list[SessionItem]]]) -> SessionContents:
    """Pass 2: read the members (bounded, streamed) and build each kind's records into ``out``."""
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
