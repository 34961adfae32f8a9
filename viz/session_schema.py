"""The schema of a session document: the format's name and version, and the table of kinds.

Each kind of content (robots, objects, trajectories, workspaces, point sets, histories,
reachability maps, belt lines, deltas) is a row of :data:`KINDS`: its list in ``session.json``,
the :class:`pinarms.viz.Session` attribute holding its records, its arrays (:class:`~.session_specs.ArraySpec`:
dtype float64, shapes with named dimensions shared within an item), its text members
(:class:`~.session_specs.TextSpec`), whether it refers to a robot, and an encoder and a decoder. A new kind
is a record class, a row and two small functions; the reader
(:mod:`pinarms.viz.session_document`, :mod:`pinarms.viz.session_archive`) applies its bounds to it unchanged.

Frames and units: positions in metres, angles in radians, times in seconds.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from pinarms.viz.delta_record import decode_delta, encode_delta  # a delta and its motion: its own module
from pinarms.viz.line_record import decode_line, encode_line  # a belt line: its own module
from pinarms.viz.reach_record import decode_reachability, encode_reachability  # a kind defined in its own module
from pinarms.viz.session_records import (
    BoxObject,
    HistoryRecord,
    PointSet,
    RobotEntry,
    TrajectoryRecord,
    WorkspaceRecord,
)

from pinarms.viz.session_specs import ArraySpec, SessionItemView, TextSpec

__all__ = ["FORMAT_NAME", "FORMAT_VERSION", "POINT_KINDS", "Kind", "KINDS", "SessionContents"]

FORMAT_NAME = "pinarms-session"
FORMAT_VERSION = 1

POINT_KINDS = ("via", "target", "contact")


@dataclass(frozen=True)
class Kind:
    """One kind of session content: a list ``section`` of ``session.json``, a dict ``attr`` of the Session.

    ``encode(record)`` gives the item's JSON fields (without arrays and texts), its arrays
    ({field: array} or, for ``columns`` specs, {field: {column: array}}) and its texts
    ({field: text or None}). ``decode(item)`` builds the record from a validated
    :class:`~.session_specs.SessionItemView` (JSON fields checked with ``item.field``, arrays and texts already read).
    """

    section: str
    attr: str
    what: str
    key_field: str
    arrays: tuple[ArraySpec, ...]
    encode: Callable[[Any], tuple[dict, dict, dict]]
    decode: Callable[["SessionItemView"], Any]
    texts: tuple[TextSpec, ...] = ()
    robot_ref: str | None = None  # "required" / "optional": the item's "robot" field names a session robot
    optional: bool = False  # the section may be absent (written only when it has items): older files lack it


def _encode_robot(e: RobotEntry) -> tuple[dict, dict, dict]:
    fields = {"key": e.key, "source": e.source, "name": e.name, "tcp_frame": e.tcp_frame,
              "joint_names": list(e.joint_names), "package_dirs": list(e.package_dirs)}
    if e.payload is not None:  # written only when there is one: sessions without stay as they were
        fields["payload"] = e.payload
    return fields, {"base_to_world": e.base_to_world}, {"urdf_member": e.urdf_text}


def _decode_robot(it: SessionItemView) -> RobotEntry:
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
        from pinarms.robots.payload import InvalidPayload, Payload

        try:
            payload = Payload.from_dict(it.field("payload", dict)).as_dict()
        except InvalidPayload as exc:
            raise it.fail(f"{it.where}.payload: {exc}") from None
    return RobotEntry(key=it.key, source=source, name=it.field("name", str), tcp_frame=it.field("tcp_frame", str),
                      joint_names=it.joint_names, base_to_world=it.arrays["base_to_world"],
                      urdf_text=it.texts.get("urdf_member"), package_dirs=tuple(dirs), payload=payload)


def _encode_box(b: BoxObject) -> tuple[dict, dict, dict]:
    return {"name": b.name, "shape": "box", "color": list(b.color)}, {"size": b.size, "pose": b.pose}, {}


def _decode_box(it: SessionItemView) -> BoxObject:
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


def _decode_trajectory(it: SessionItemView) -> TrajectoryRecord:
    if "definition" not in it.obj or not (it.obj["definition"] is None or isinstance(it.obj["definition"], dict)):
        raise it.fail(f"{it.where}.definition must be a JSON object or null")
    t = it.arrays["t"]
    if np.any(np.diff(t) <= 0):
        raise it.fail(f"{it.where}.t must hold at least 2 strictly increasing instants")
    return TrajectoryRecord(it.key, it.robot, t, it.arrays["q"], it.arrays["knot_times"], it.obj["definition"])


def _encode_workspace(r: WorkspaceRecord) -> tuple[dict, dict, dict]:
    return {"name": r.name, "robot": r.robot}, {"points": r.points, "manipulability": r.manipulability}, {}


def _decode_workspace(it: SessionItemView) -> WorkspaceRecord:
    return WorkspaceRecord(it.key, it.robot, it.arrays["points"], it.arrays["manipulability"])


def _encode_points(p: PointSet) -> tuple[dict, dict, dict]:
    return {"name": p.name, "kind": p.kind, "robot": p.robot}, {"points": p.points}, {}


def _decode_points(it: SessionItemView) -> PointSet:
    kind = it.field("kind", str)
    if kind not in POINT_KINDS:
        raise it.fail(f"{it.where}.kind must be one of {POINT_KINDS}, got {kind!r}")
    return PointSet(it.key, kind, it.robot, it.arrays["points"])


def _encode_history(h: HistoryRecord) -> tuple[dict, dict, dict]:
    return {"name": h.name}, {"columns": dict(h.columns)}, {}


def _decode_history(it: SessionItemView) -> HistoryRecord:
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
    Kind("deltas", "deltas", "delta", "name",
         (ArraySpec("base_to_world", (4, 4)), ArraySpec("t", ("N",), min_rows=1), ArraySpec("actuated", ("N", "A"))),
         encode_delta, decode_delta, optional=True),
)


@dataclass
class SessionContents:
    """What a session file holds: ``metadata`` and one dict per kind (``tables[kind.attr][name] = record``)."""

    metadata: dict
    tables: dict[str, dict[str, Any]] = field(default_factory=dict)
