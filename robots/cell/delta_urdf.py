"""A delta's part of a cell URDF: its actuated joints only, for the cell's joint vector.

A delta cannot be written as a URDF tree (its forearms close loops at the platform), and a
tree opened at the platform would carry passive joints that a cell's joint vector must not
hold. So a composed cell gets, for a delta placed in its description (``delta = "..."``),
only what the joint vector needs: ``<prefix>base_link`` fixed to the world at the delta's
pose, the three motors ``<prefix>leg{i}_motor`` (revolute, at the motor axes, the delta's
limits) each carrying an empty ``<prefix>leg{i}_upper_arm`` link, and with a fourth axis the
revolute ``<prefix>tool`` about the base's z axis (the telescopic shaft's motor sits on the
base; its angle turns the tool about the tool axis). None of these links has collision
geometry: every body of the delta (base, upper arms, the six rods, the platform, the tool) is
posed from the closed form at the motor angles (:mod:`.delta_arm`) and checked by
:mod:`.delta_pairs`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from pinarms.errors import CellError, RobotNotFound
from pinarms.robots.cell.compose_file import ArmPlacement
from pinarms.robots.delta import DeltaRobot, load_delta
from pinarms.robots.delta.geometry import LEG_COUNT, motor_joint

__all__ = ["delta_elements", "placed_delta"]


def placed_delta(arm: ArmPlacement) -> DeltaRobot:
    """The shipped delta ``arm.delta`` names; :class:`CellError` naming the arm and the shipped deltas otherwise."""
    try:
        return load_delta(str(arm.delta))
    except RobotNotFound as exc:
        raise CellError(f"arm {arm.name!r}: {exc}") from None


def _fmt(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def _link(name: str) -> ET.Element:
    link = ET.Element("link", {"name": name})
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "mass", {"value": "1e-6"})
    ET.SubElement(inertial, "inertia", {"ixx": "1e-9", "ixy": "0", "ixz": "0", "iyy": "1e-9", "iyz": "0", "izz": "1e-9"})
    return link


def _joint(name: str, parent: str, child: str, xyz, rpy, axis, limit: tuple[float, float, float, float]) -> ET.Element:
    joint = ET.Element("joint", {"name": name, "type": "revolute"})
    ET.SubElement(joint, "origin", {"xyz": _fmt(xyz), "rpy": _fmt(rpy)})
    ET.SubElement(joint, "parent", {"link": parent})
    ET.SubElement(joint, "child", {"link": child})
    ET.SubElement(joint, "axis", {"xyz": _fmt(axis)})
    lo, hi, vel, eff = limit
    ET.SubElement(joint, "limit", {"lower": repr(lo), "upper": repr(hi), "velocity": repr(vel), "effort": repr(eff)})
    return joint


def delta_elements(arm: ArmPlacement) -> list[ET.Element]:
    """The links and joints of delta ``arm`` in a cell URDF (module doc), prefixed ``<name>_``, and its mount."""
    delta = placed_delta(arm)
    g, lim, model = delta.geometry, delta.limits, delta.model
    prefix = arm.name + "_"
    base = prefix + "base_link"
    out = [_link(base)]
    for i in range(1, LEG_COUNT + 1):
        az = g.azimuths[i - 1]
        origin = model.jointPlacements[model.getJointId(motor_joint(i))].translation
        out.append(_joint(prefix + motor_joint(i), base, f"{prefix}leg{i}_upper_arm", origin, (0.0, 0.0, az), (0, 1, 0),
                          (lim.lower, lim.upper, lim.velocity, lim.torque)))
        out.append(_link(f"{prefix}leg{i}_upper_arm"))
    if delta.tool_q is not None:
        jid = model.getJointId("tool")
        iv = model.joints[jid].idx_v
        out.append(_joint(prefix + "tool", base, prefix + "tool_shaft", (0, 0, 0), (0, 0, 0), (0, 0, 1),
                          (float(model.lowerPositionLimit[delta.tool_q]), float(model.upperPositionLimit[delta.tool_q]),
                           float(model.velocityLimit[iv]), float(model.effortLimit[iv]))))
        out.append(_link(prefix + "tool_shaft"))
    if any(el.get("name") == "world" for el in out):
        raise CellError(f"arm {arm.name!r}: a delta's link may not be called 'world'")
    mount = ET.Element("joint", {"name": f"{prefix}mount_joint", "type": "fixed"})
    ET.SubElement(mount, "origin", {"xyz": _fmt(arm.xyz), "rpy": _fmt(arm.rpy)})
    ET.SubElement(mount, "parent", {"link": "world"})
    ET.SubElement(mount, "child", {"link": base})
    return out + [mount]
