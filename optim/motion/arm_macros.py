"""Example-robot-data arms as xacro macros, so that cell files can place them like the built-in arms.

The built-in arms of pinarms are xacro macros (``prefix``, ``parent``, ``xyz``, ``rpy``). The
arms of example-robot-data (UR5, Panda, ...) ship as plain URDFs whose names carry no
prefix. :func:`arm_macro_text` turns one of them into a macro **at load time** (nothing of
example-robot-data is copied into pinarms): every link and joint name gets ``${prefix}``
(a leading ``panda_`` of the Panda's own names is replaced by it), the registry's frozen
joints (the Panda's fingers) become fixed joints, ``<transmission>``/``<gazebo>`` elements
are dropped, the arm's base is bolted to ``parent`` at ``xyz``/``rpy``
(the arm's root link is renamed ``${prefix}base_link``: the cell names the arm after it,
prefix ``"panda_"`` → arm ``"panda"``) and a
``${prefix}tcp`` frame is fixed at the registry's tool frame (the Panda's ``panda_hand_tcp``,
the UR's ``tool0``). Meshes keep their ``package://example-robot-data/...`` names: load
the cell with ``packages={"example-robot-data": <its share folder>}``
(:func:`example_packages` gives both packages).

The Panda is taken from ``panda_collision.urdf`` (collision geometry of spheres and
cylinders, the description example-robot-data ships for collision checking); the others
from the registry's URDF.
"""

from __future__ import annotations

import tempfile
import xml.etree.ElementTree as ET
from functools import lru_cache
from pathlib import Path

from pinarms.files import write_text
from pinarms.robots import registry
from pinarms.errors import RobotNotFound

__all__ = ["MACRO_ARMS", "PACKAGE", "arm_macro_text", "example_packages"]

#: Registry arms that cell files can place with ``$(find pinarms_examples)/<name>.xacro``.
MACRO_ARMS = ("panda", "ur3", "ur5", "ur10")

#: Name of the package holding the generated macros (``$(find pinarms_examples)``).
PACKAGE = "pinarms_examples"

_SOURCE = {"panda": "panda_description/urdf/panda_collision.urdf"}
_STRIP = {"panda": "panda_"}
_KEEP_LINK = ("visual", "collision", "inertial")
_KEEP_JOINT = ("parent", "child", "origin", "axis", "limit", "mimic", "dynamics")


def _rename(name: str, strip: str, root: str) -> str:
    if name == root:
        return "${prefix}base_link"
    return "${prefix}" + (name[len(strip):] if strip and name.startswith(strip) else name)


def arm_macro_text(name: str) -> str:
    """xacro text of the macro ``<xacro:NAME prefix parent xyz rpy/>`` for registry arm ``name``."""
    if name not in MACRO_ARMS:
        raise RobotNotFound(f"no macro for {name!r}; example arms with a macro: {', '.join(MACRO_ARMS)}")
    entry = registry.info(name)
    share = registry.example_robot_data_share()
    path = share / "robots" / _SOURCE.get(name, entry.urdf_relpath)
    root = ET.parse(path).getroot()
    strip = _STRIP.get(name, "")
    joints = root.findall("joint")
    links = root.findall("link")
    children = {j.find("child").get("link") for j in joints}
    roots = [lk.get("name") for lk in links if lk.get("name") not in children]
    frozen = set(entry.frozen_joints)
    # a "world" root with one fixed joint (some URDFs bolt themselves to a world link): drop it
    drop_links = {r for r in roots if r == "world"}
    drop_joints = {j.get("name") for j in joints if j.find("parent").get("link") in drop_links}
    arm_root = next(j.find("child").get("link") for j in joints if j.get("name") in drop_joints) if drop_joints \
        else roots[0]
    macro = ET.Element("xacro:macro", {"name": name, "params": "prefix:='' parent:='' xyz:='0 0 0' rpy:='0 0 0'"})
    base = "${prefix}base_link"

    def rename(n: str) -> str:
        return _rename(n, strip, arm_root)

    cond = ET.SubElement(macro, "xacro:if", {"value": "${parent != ''}"})
    mount = ET.SubElement(cond, "joint", {"name": "${prefix}base_mount", "type": "fixed"})
    ET.SubElement(mount, "parent", {"link": "${parent}"})
    ET.SubElement(mount, "child", {"link": base})
    ET.SubElement(mount, "origin", {"xyz": "${xyz}", "rpy": "${rpy}"})
    for link in links:
        if link.get("name") in drop_links:
            continue
        new = ET.SubElement(macro, "link", {"name": rename(link.get("name"))})
        for child in link:
            if child.tag in _KEEP_LINK:
                new.append(child)
    for joint in joints:
        if joint.get("name") in drop_joints:
            continue
        mimic = joint.find("mimic")
        fixed = joint.get("name") in frozen or (mimic is not None and mimic.get("joint") in frozen)
        new = ET.SubElement(macro, "joint", {"name": rename(joint.get("name")),
                                             "type": "fixed" if fixed else joint.get("type")})
        for child in joint:
            if child.tag not in _KEEP_JOINT or (fixed and child.tag in ("axis", "limit", "mimic", "dynamics")):
                continue
            if child.tag in ("parent", "child"):
                child = ET.Element(child.tag, {"link": rename(child.get("link"))})
            elif child.tag == "mimic":
                child = ET.Element("mimic", {**child.attrib, "joint": rename(child.get("joint"))})
            new.append(child)
    tcp = ET.SubElement(macro, "link", {"name": "${prefix}tcp"})
    del tcp
    j = ET.SubElement(macro, "joint", {"name": "${prefix}tcp_joint", "type": "fixed"})
    ET.SubElement(j, "parent", {"link": rename(entry.tcp)})
    ET.SubElement(j, "child", {"link": "${prefix}tcp"})
    robot = ET.Element("robot", {"xmlns:xacro": "http://www.ros.org/wiki/xacro"})
    robot.append(ET.Comment(f" Generated by pinarms from example-robot-data's {path.name} at load time; not a copy. "))
    robot.append(macro)
    ET.indent(robot)
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


@lru_cache(maxsize=1)
def _macro_dir() -> Path:
    folder = Path(tempfile.mkdtemp(prefix="pinarms-examples-"))
    for name in MACRO_ARMS:
        write_text(folder / f"{name}.xacro", arm_macro_text(name))
    return folder


def example_packages() -> dict[str, Path]:
    """``{"pinarms_examples": folder of the generated macros, "example-robot-data": its share folder}``."""
    return {PACKAGE: _macro_dir(), "example-robot-data": registry.example_robot_data_share()}
