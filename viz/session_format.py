"""The session file format: writing a session archive, and reading one (bounded, validated).

A session file is a zip archive holding ``session.json`` (format name, version, metadata
and an index of everything) and one ``.npy`` member per array (little-endian float64,
read with ``allow_pickle=False``), plus ``robots/<i>.urdf`` for embedded URDFs. Full spec
in docs/viz.md. Files users exchange are hostile until checked; the pieces of the format
live in their own modules, all re-exported here:

- :mod:`pinarms.viz.session_schema`: the format's name and version and the table of kinds
  (:data:`KINDS`: a new kind is a record class, an encoder, a decoder and its array specs);
- :mod:`pinarms.viz.session_archive`: the bounded reader of the zip (:class:`SessionLimits`, the
  zip directory checked before :mod:`zipfile` parses it, ``session.json`` parsed under caps,
  members checked against the directory before a byte is read, arrays streamed);
- :mod:`pinarms.viz.session_document`: ``session.json``'s header and index, checked whole before
  the members are read;
- :mod:`pinarms.viz.mesh_paths`: meshes of embedded URDFs kept inside the allowed folders.

Every problem raises :class:`SessionFormatError` naming the file, the member or field, and
why.

Frames and units: positions in metres, angles in radians, times in seconds.
"""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path
from typing import Any, BinaryIO, Mapping

import numpy as np

from pinarms.files import atomic_write
from pinarms.errors import InvalidInput

from pinarms.viz.mesh_paths import check_mesh_paths
from pinarms.viz.session_archive import DEFAULT_LIMITS, JSON_MEMBER, SessionLimits, open_archive
from pinarms.viz.session_document import read_document
from pinarms.viz.session_records import (
    BoxObject,
    HistoryRecord,
    PointSet,
    RobotEntry,
    TrajectoryRecord,
    WorkspaceRecord,
    check_name,
)
from pinarms.viz.session_schema import FORMAT_NAME, FORMAT_VERSION, KINDS, Kind, SessionContents
from pinarms.viz.session_specs import ArraySpec, TextSpec

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


# ---------------------------------------------------------------------------- writing
def to_document(metadata: dict, tables: Mapping[str, Mapping[str, object]]) -> tuple[dict, dict[str, np.ndarray], dict[str, str]]:
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


def write_session(path: str | os.PathLike, metadata: dict, tables: Mapping[str, Mapping[str, object]]) -> Path:
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
def read_session(path: str | os.PathLike, limits: SessionLimits | None = None) -> SessionContents:
    """Read and validate a session file, bounded by ``limits`` (default :data:`DEFAULT_LIMITS`).

    Raises:
        SessionFormatError: anything wrong with the file (see the module docstring).
        InvalidInput: ``path`` does not exist or is a folder; ``limits`` is not a SessionLimits.
    """
    limits = DEFAULT_LIMITS if limits is None else limits
    if not isinstance(limits, SessionLimits):
        raise InvalidInput(f"limits must be a viz.SessionLimits, got {type(limits).__name__}")
    with open_archive(path, limits) as reader:
        return read_document(reader)
