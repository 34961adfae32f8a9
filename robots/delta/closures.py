"""Loop closures of a closed-chain arm, kept in pinarms' own small XML file next to its URDF.

A URDF is a tree; a delta robot is that tree opened at the platform plus one ball joint per
leg that the tree cannot hold. Each such joint is a :class:`LoopClosure` between two frames
of the tree (``frame1`` on one branch, ``frame2`` on another) and is written as::

    <loop_closures robot="delta_flexpicker" version="1">
      <closure name="leg1" type="point" frame1="leg1_ball" frame2="platform_ball1"/>
      ...
    </loop_closures>

``type="point"``: the two frames' origins coincide (a ball joint, 3 equations);
``type="frame"``: the two frames coincide (a weld, 6 equations).
:func:`constraint_models` turns them into Pinocchio's ``RigidConstraintModel`` objects
(``CONTACT_3D`` / ``CONTACT_6D``, ``LOCAL`` reference frame).

The file may come from anyone: :func:`read_closures` reads a regular file of at most
:data:`MAX_CLOSURES_BYTES`, refuses a DOCTYPE or entity declarations, unknown elements or
attributes, more than :data:`MAX_CLOSURES` closures, empty, overlong or duplicate names, an
unknown ``type`` or a frame closed onto itself, each with a :class:`ClosuresFileError` that
names the file and what to change (docs/files.md, "Loop-closures file").
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin

from pinarms.files import read_bounded_text, write_text

from pinarms.errors import ModelError
from pinarms.robots.urdf_checks import refuse_dtd
from pinarms.robots.delta.errors import ClosuresFileError

__all__ = ["LoopClosure", "ClosureSet", "MAX_CLOSURES", "MAX_CLOSURES_BYTES", "CLOSURE_TYPES", "parse_closures",
           "read_closures", "closures_to_xml", "write_closures", "constraint_models"]

#: Largest loop-closures file read [bytes].
MAX_CLOSURES_BYTES = 256 * 1024
#: Most closures one file may hold.
MAX_CLOSURES = 64
#: Closure kinds and the number of scalar equations each stands for.
CLOSURE_TYPES = {"point": 3, "frame": 6}
_NAME = re.compile(r"^[A-Za-z0-9_.:/-]{1,200}$")
_VERSION = "1"


@dataclass(frozen=True)
class LoopClosure:
    """One loop closure: ``frame1``'s and ``frame2``'s origins (``point``) or whole frames (``frame``) coincide."""

    name: str
    frame1: str
    frame2: str
    kind: str = "point"

    @property
    def n_equations(self) -> int:
        """Scalar equations of the closure (3 for a ball joint, 6 for a weld)."""
        return CLOSURE_TYPES[self.kind]


@dataclass(frozen=True)
class ClosureSet:
    """The loop closures of one arm (``robot`` is its URDF's ``<robot name>``)."""

    robot: str
    closures: tuple[LoopClosure, ...]


def _check_name(value: str | None, what: str, source: str) -> str:
    if value is None or not _NAME.match(value):
        raise ClosuresFileError(f"{source}: {what} {value!r} must be 1 to 200 characters of letters, digits and _.:/-")
    return value


def parse_closures(text: str, source: str = "<string>") -> ClosureSet:
    """The :class:`ClosureSet` written in ``text`` (the XML format above).

    Raises:
        ClosuresFileError: anything the format does not allow (the message names ``source``).
    """
    if not isinstance(text, str):
        raise ClosuresFileError(f"{source}: the closures must be XML text, got {type(text).__name__}")
    try:
        refuse_dtd(text, source)
        root = ET.fromstring(text)
    except ModelError as exc:
        raise ClosuresFileError(str(exc).replace("URDF uses", "a loop-closures file uses")) from None
    except ET.ParseError as exc:
        raise ClosuresFileError(f"{source} is not well-formed XML: {exc}") from None
    if root.tag != "loop_closures":
        raise ClosuresFileError(f"{source}: the root element is <{root.tag}>, expected <loop_closures>")
    extra = set(root.attrib) - {"robot", "version"}
    if extra or root.get("version") != _VERSION:
        raise ClosuresFileError(f"{source}: <loop_closures> takes robot=\"...\" version=\"{_VERSION}\" only "
                                f"(got {dict(root.attrib)!r})")
    robot = _check_name(root.get("robot"), "robot name", source)
    children = list(root)
    if not children:
        raise ClosuresFileError(f"{source} holds no <closure>: a closed chain needs at least one")
    if len(children) > MAX_CLOSURES:
        raise ClosuresFileError(f"{source} holds {len(children)} elements; at most {MAX_CLOSURES} closures are read")
    closures, seen = [], set()
    for el in children:
        if el.tag != "closure" or len(el) or (el.text or "").strip():
            raise ClosuresFileError(f"{source}: only empty <closure .../> elements may appear, found <{el.tag}>")
        extra = set(el.attrib) - {"name", "type", "frame1", "frame2"}
        if extra:
            raise ClosuresFileError(f"{source}: <closure> has unknown attribute(s) {sorted(extra)}; "
                                    "it takes name, type, frame1, frame2")
        name = _check_name(el.get("name"), "closure name", source)
        if name in seen:
            raise ClosuresFileError(f"{source}: closure name {name!r} appears twice; give each closure its own name")
        seen.add(name)
        kind = el.get("type", "point")
        if kind not in CLOSURE_TYPES:
            raise ClosuresFileError(f"{source}: closure {name!r} has type {kind!r}; use one of {sorted(CLOSURE_TYPES)}")
        f1 = _check_name(el.get("frame1"), f"closure {name!r} frame1", source)
        f2 = _check_name(el.get("frame2"), f"closure {name!r} frame2", source)
        if f1 == f2:
            raise ClosuresFileError(f"{source}: closure {name!r} joins frame {f1!r} to itself; name two frames")
        closures.append(LoopClosure(name, f1, f2, kind))
    return ClosureSet(robot, tuple(closures))


def read_closures(path: str | os.PathLike) -> ClosureSet:
    """Read a loop-closures file (a regular file of at most :data:`MAX_CLOSURES_BYTES`).

    Raises:
        ClosuresFileError: missing, not a regular file, too large, not UTF-8 or not the format.
    """
    text = read_bounded_text(path, MAX_CLOSURES_BYTES, "loop-closures file", error=ClosuresFileError)
    return parse_closures(text, source=str(path))


def closures_to_xml(closure_set: ClosureSet, comment: str = "") -> str:
    """The file text of ``closure_set`` (deterministic: same set, same bytes)."""
    lines = ['<?xml version="1.0"?>']
    if comment:
        lines.append(f"<!-- {comment.replace('--', '- -')} -->")
    lines.append(f'<loop_closures robot="{closure_set.robot}" version="{_VERSION}">')
    for c in closure_set.closures:
        lines.append(f'  <closure name="{c.name}" type="{c.kind}" frame1="{c.frame1}" frame2="{c.frame2}"/>')
    lines.append("</loop_closures>")
    return "\n".join(lines) + "\n"


def write_closures(path: str | os.PathLike, closure_set: ClosureSet, comment: str = "") -> Path:
    """Write ``closure_set`` to ``path`` atomically; return the path."""
    parse_closures(closures_to_xml(closure_set), source="closures to write")  # only what reads back is written
    return write_text(path, closures_to_xml(closure_set, comment))


def constraint_models(model: pin.Model, closure_set: ClosureSet, source: str = "loop-closures file"
                      ) -> list[pin.RigidConstraintModel]:
    """Pinocchio's constraint models of ``closure_set`` on ``model``, one per closure, in file order.

    Each is a ``RigidConstraintModel`` between the parent joints of ``frame1`` and ``frame2`` at
    the frames' placements, expressed ``LOCAL`` (its ``name`` is the closure's name).

    Raises:
        ClosuresFileError: a frame is not in ``model`` (the message lists a few that are).
    """
    out = []
    for c in closure_set.closures:
        ids = []
        for frame in (c.frame1, c.frame2):
            if not model.existFrame(frame):
                known = ", ".join(f.name for f in list(model.frames)[1:8])
                raise ClosuresFileError(f"{source}: closure {c.name!r} names frame {frame!r}, which the model "
                                        f"{model.name!r} lacks (its frames include {known}, ...)")
            ids.append(model.getFrameId(frame))
        f1, f2 = (model.frames[i] for i in ids)
        if f1.parentJoint == f2.parentJoint:
            raise ClosuresFileError(f"{source}: closure {c.name!r} joins two frames of the same body; "
                                    "a loop closure joins two branches of the tree")
        kind = pin.ContactType.CONTACT_3D if c.kind == "point" else pin.ContactType.CONTACT_6D
        cm = pin.RigidConstraintModel(kind, model, f1.parentJoint, f1.placement, f2.parentJoint, f2.placement,
                                      pin.ReferenceFrame.LOCAL)
        cm.name = c.name
        out.append(cm)
    return out
