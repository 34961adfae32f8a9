"""An arm's keys in a cell description: its tool point, its frozen joints, its named states and its hold pose.

Two steps, one before and one after the cell is built:

- :func:`rewrite_arm` edits the arm file's tree before it is prefixed into the cell URDF:
  each frozen joint becomes a fixed joint whose origin is the joint's origin composed with
  its motion at the frozen value (a ``<mimic>`` of it too, at ``multiplier * value +
  offset``), which is what Pinocchio's ``buildReducedModel`` does to a model, written
  into the URDF so that every reader of the cell's text (sessions, exports, MuJoCo) sees
  the same arm; a tool point becomes a link ``tcp`` fixed to its link at its offset.
- :func:`arm_with_keys` checks the named states and the hold pose against the built arm
  (the number of values, the joint limits) and gives the :class:`~.components.CellArm`
  its ``states``, ``hold``, ``frozen`` and ``tcp_choice``.
"""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET
from typing import Any

import numpy as np
import pinocchio as pin

from pinarms.errors import ArmStateError, CellError
from pinarms.robots.cell.components import CellArm
from pinarms.robots.cell.compose_file import ArmPlacement, ToolPoint

__all__ = ["rewrite_arm", "arm_with_keys", "tcp_choice"]

_MOVABLE = ("revolute", "continuous", "prismatic")
_JOINT_ONLY = ("mimic", "limit", "axis", "dynamics", "safety_controller", "calibration")


def _floats(text: str | None, default: tuple[float, ...]) -> np.ndarray:
    """Three finite numbers from an attribute (``"0 0 0.1"``), else ``default``; ValueError otherwise."""
    out = np.array([float(v) for v in text.split()] if text else default, dtype=float)
    if out.shape != (3,) or not np.all(np.isfinite(out)):
        raise ValueError(f"{text!r} is not three finite numbers")
    return out


def _origin(joint: ET.Element) -> pin.SE3:
    origin = joint.find("origin")
    xyz = _floats(None if origin is None else origin.get("xyz"), (0.0, 0.0, 0.0))
    rpy = _floats(None if origin is None else origin.get("rpy"), (0.0, 0.0, 0.0))
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)


def _set_origin(el: ET.Element, placement: pin.SE3) -> None:
    origin = el.find("origin")
    if origin is None:
        origin = ET.Element("origin")
        el.insert(0, origin)
    origin.set("xyz", " ".join(repr(float(v)) for v in placement.translation))
    origin.set("rpy", " ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(placement.rotation)))


def _limits_of(joint: ET.Element) -> tuple[float, float] | None:
    limit = joint.find("limit")
    if joint.get("type") == "continuous" or limit is None or limit.get("lower") is None:
        return None
    return float(limit.get("lower")), float(limit.get("upper", "0"))


def _fix(joint: ET.Element, value: float) -> None:
    """Turn a movable joint into a fixed one at ``value`` [rad or m]: origin ∘ motion(value)."""
    axis = _floats(joint.find("axis").get("xyz") if joint.find("axis") is not None else None, (1.0, 0.0, 0.0))
    if axis.shape != (3,) or not np.all(np.isfinite(axis)) or not np.linalg.norm(axis) > 0.0:
        raise ValueError(f"joint {joint.get('name')!r} has axis {axis.tolist()}, not a non-zero 3-vector")
    axis = axis / np.linalg.norm(axis)
    if joint.get("type") == "prismatic":
        motion = pin.SE3(np.eye(3), value * axis)
    else:
        motion = pin.SE3(pin.AngleAxis(value, axis).matrix(), np.zeros(3))
    _set_origin(joint, _origin(joint) * motion)
    joint.set("type", "fixed")
    for child in list(joint):
        if child.tag in _JOINT_ONLY:
            joint.remove(child)


def _freeze(root: ET.Element, freeze: tuple[tuple[str, float], ...], source: str) -> None:
    joints = {j.get("name"): j for j in root.findall("joint")}
    movable = [name for name, j in joints.items() if j.get("type") in _MOVABLE]
    values = dict(freeze)
    for name, value in freeze:
        if name not in movable:
            raise CellError(f"{source}: freeze names joint {name!r}, which is not a movable joint of the arm; its "
                            f"movable joints: {', '.join(movable)}")
        mimic = joints[name].find("mimic")
        if mimic is not None:
            raise CellError(f"{source}: freeze names joint {name!r}, which mimics {mimic.get('joint')!r}: freeze that one")
        bounds = _limits_of(joints[name])
        if bounds is not None and not bounds[0] - 1e-12 <= value <= bounds[1] + 1e-12:
            raise ArmStateError(f"{source}: freeze {name} = {value:g} is outside its limits [{bounds[0]:g}, "
                                f"{bounds[1]:g}]")
    for name, joint in joints.items():
        mimic = joint.find("mimic")
        if mimic is not None and mimic.get("joint") in values:
            followed = values[mimic.get("joint")]
            _fix(joint, float(mimic.get("multiplier", "1")) * followed + float(mimic.get("offset", "0")))
    for name, value in freeze:
        _fix(joints[name], value)


def _add_tool_point(root: ET.Element, tcp: ToolPoint, source: str) -> None:
    links = [ln.get("name") for ln in root.findall("link")]
    if tcp.link not in links:
        raise CellError(f"{source}: tcp link {tcp.link!r} is not a link of the arm; its links: "
                        f"{', '.join(links[:60])}{' ...' if len(links) > 60 else ''}")
    taken = [n for n in ("tcp",) if n in links] + [j.get("name") for j in root.findall("joint")
                                                    if j.get("name") == "tcp_joint"]
    if taken:
        raise CellError(f"{source}: the arm file already has {taken[0]!r}; leave out the tcp key (its link 'tcp' is "
                        "the tool point) or rename it in the file")
    root.append(ET.Element("link", {"name": "tcp"}))
    joint = ET.SubElement(root, "joint", {"name": "tcp_joint", "type": "fixed"})
    ET.SubElement(joint, "parent", {"link": tcp.link})
    ET.SubElement(joint, "child", {"link": "tcp"})
    _set_origin(joint, pin.SE3(pin.rpy.rpyToMatrix(*tcp.rpy), np.array(tcp.xyz, dtype=float)))


def rewrite_arm(root: ET.Element, placement: ArmPlacement, source: str) -> None:
    """Apply ``placement``'s ``freeze`` and ``tcp`` to the arm file's tree ``root`` (in place, names unprefixed).

    Raises:
        CellError: a frozen joint or tcp link the arm does not have, a frozen mimic joint, a
            tcp key on a file that has its own ``tcp`` link.
        ArmStateError: a frozen value outside its joint's limits.
    """
    try:
        if placement.freeze:
            _freeze(root, tuple(placement.freeze), source)
        if placement.tcp is not None:
            _add_tool_point(root, placement.tcp, source)
    except (ValueError, IndexError) as exc:  # an origin, axis or limit that is not numbers
        raise CellError(f"{source}: cannot apply freeze/tcp: a joint's origin, axis or limit is not a valid list of "
                        f"numbers ({exc})") from exc


def _fmt(values: Any) -> str:
    return "(" + ", ".join(f"{float(v):.5g}" for v in values) + ")"


def tcp_choice(arm: CellArm, placement: ArmPlacement | None) -> str:
    """How the arm's tool point was chosen, in words (``"flange + xyz (0.05, 0, 0) m, rpy (0, 0, 0) rad"``)."""
    tcp = None if placement is None else placement.tcp
    if tcp is not None:
        if not any(tcp.xyz) and not any(tcp.rpy):
            return tcp.link
        return f"{tcp.link} + xyz {_fmt(tcp.xyz)} m, rpy {_fmt(tcp.rpy)} rad"
    frame = arm.robot.tcp_frame
    if frame == "tcp":
        return "tcp (the arm file's tcp link)"
    return f"{frame} (the last link; no tcp given)"


def _values(arm: CellArm, values: tuple[float, ...], what: str, source: str) -> np.ndarray:
    robot = arm.robot
    q = np.asarray(values, dtype=float)
    if q.shape != (robot.nq,):
        raise ArmStateError(f"{source}: arm {arm.name!r}: {what} needs {robot.nq} values (joints "
                            f"{', '.join(robot.joint_names)}), got {q.size}")
    bad = [f"{n} = {v:g} outside [{lo:g}, {hi:g}]" for n, v, lo, hi in zip(robot.joint_names, q, robot.lower, robot.upper)
           if not lo - 1e-9 <= v <= hi + 1e-9]
    if bad:
        raise ArmStateError(f"{source}: arm {arm.name!r}: {what} is outside the joint limits: {'; '.join(bad)}")
    return q


def arm_with_keys(arm: CellArm, placement: ArmPlacement | None, source: str) -> CellArm:
    """``arm`` with its named states, hold pose, frozen joints and tcp choice from ``placement``.

    Without a placement (a xacro or URDF cell) the arm has no states, holds at its neutral
    configuration and freezes nothing.

    Raises:
        ArmStateError: a state or hold with the wrong number of values or outside the limits,
            or a hold naming a state the arm does not have.
    """
    states: dict[str, np.ndarray] = {}
    hold = arm.robot.neutral
    if placement is not None:
        for name, values in placement.states:
            states[name] = _values(arm, values, f"state {name!r}", source)
        if isinstance(placement.hold, str):
            if placement.hold not in states:
                raise ArmStateError(f"{source}: arm {arm.name!r}: hold {placement.hold!r} is not a named state; "
                                    f"states: {', '.join(states) or 'none (add states = {{ ... }})'}")
            hold = states[placement.hold]
        elif placement.hold is not None:
            hold = _values(arm, tuple(placement.hold), "the hold pose", source)
    for q in (*states.values(), hold):
        q.setflags(write=False)
    return dataclasses.replace(arm, states=states, hold=hold, frozen=dict(() if placement is None else placement.freeze),
                               tcp_choice=tcp_choice(arm, placement))
