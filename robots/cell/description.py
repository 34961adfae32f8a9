"""What a cell URDF holds: which links are arms, which are fixtures (plain XML, no Pinocchio).

Rules (docs/cells.md, "How a cell file is read"):

- The URDF has one root link (the world). A link is *static* when the chain from the root
  to it is made of fixed joints only.
- An **arm** is a static link with at least one movable child joint (its *base*), with
  every link below those movable joints, and the static links fixed below the base. The
  built-in macros name the base ``<prefix>base_link``: the arm's name is the prefix
  without its trailing ``_`` (``left_base_link`` → ``left``); a base with another name
  gives its own name.
- A **fixture** is any other static link with collision geometry; static links without
  geometry (``world``, mounting frames) are plain frames.
- Link and joint names must be unique; joints may be fixed, revolute, continuous or
  prismatic (``<mimic>`` allowed).
- ``<disable_collisions link1="A" link2="B" reason="..."/>`` (the SRDF element, at the top
  level of the cell URDF) declares two links in contact by design: their pairs are never
  checked (:mod:`.pairs`, reason ``declared``). Pinocchio ignores the element.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

from pinarms.errors import CellError
from pinarms.robots.pair_rules import declared_pairs

__all__ = ["ArmSpec", "CellSpec", "describe", "arm_urdf", "MOVABLE_JOINTS"]

#: URDF joint types that move (the rest: fixed).
MOVABLE_JOINTS = {"revolute", "continuous", "prismatic"}
_KINDS = MOVABLE_JOINTS | {"fixed"}


@dataclass(frozen=True)
class ArmSpec:
    """One arm of a cell URDF.

    Attributes:
        name: the arm's name (prefix without its trailing ``_``, or the base link's name).
        prefix: what every link and joint name of the arm starts with (``""`` if not all do).
        base_link: the arm's base (a static link).
        links: the arm's links (base first, then in document order).
        joints: the joints between them (document order).
    """

    name: str
    prefix: str
    base_link: str
    links: tuple[str, ...]
    joints: tuple[str, ...]


@dataclass(frozen=True)
class CellSpec:
    """The arms, fixtures and frames of a cell URDF (see the module doc)."""

    name: str
    root_link: str
    arms: tuple[ArmSpec, ...]
    fixtures: tuple[str, ...]
    frames: tuple[str, ...]
    declared: tuple[tuple[str, str, str], ...] = ()


def _unique(root: ET.Element, tag: str, source: str) -> dict[str, ET.Element]:
    out: dict[str, ET.Element] = {}
    for el in root.findall(tag):
        name = el.get("name")
        if not name:
            raise CellError(f"{source}: a <{tag}> has no name")
        if name in out:
            raise CellError(
                f"{source}: duplicate {tag} name {name!r}; give every arm its own prefix "
                f"(<xacro:... prefix=\"left_\"/>) and every fixture its own name"
            )
        out[name] = el
    return out


def describe(root: ET.Element, source: str) -> CellSpec:
    """Split a cell URDF (its ``<robot>`` element) into arms, fixtures and frames.

    Raises:
        CellError: duplicate names, a joint naming a missing link, several roots, an
            unsupported joint type, or no arm.
    """
    if root.tag != "robot":
        raise CellError(f"{source}: root element is <{root.tag}>, expected <robot>")
    links = _unique(root, "link", source)
    joints = _unique(root, "joint", source)
    parent_of, children, root_link = _tree(links, joints, source)
    kind_of = {j: joints[j].get("type") for j in joints}
    child_of = {j: joints[j].find("child").get("link") for j in joints}

    static: list[str] = []  # links reached through fixed joints only, depth first
    stack = [root_link]
    while stack:
        link = stack.pop()
        static.append(link)
        stack.extend(child_of[j] for j in reversed(children[link]) if kind_of[j] == "fixed")

    bases = [link for link in static if any(kind_of[j] in MOVABLE_JOINTS for j in children[link])]
    if not bases:
        raise CellError(f"{source}: no arm found (no movable joint hangs from a fixed link)")
    order = {name: k for k, name in enumerate(links)}
    arms = tuple(_arm(root, base, set(bases), joints, parent_of, children, child_of, order) for base in bases)
    names = [a.name for a in arms]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise CellError(f"{source}: several arms are named {dup[0]!r}; give each arm its own prefix")
    taken = {link for a in arms for link in a.links}
    static_set = set(static)
    fixtures = tuple(
        link for link in links
        if link not in taken and link in static_set and links[link].find("collision") is not None
    )
    fixture_set = set(fixtures)
    frames = tuple(link for link in links if link not in taken and link not in fixture_set)
    moving_outside = [link for link in links if link not in taken and link not in static_set]
    if moving_outside:  # pragma: no cover - every movable subtree hangs from a static base
        raise CellError(f"{source}: links {moving_outside} move but belong to no arm")
    return CellSpec(name=root.get("name", "cell"), root_link=root_link, arms=arms, fixtures=fixtures, frames=frames,
                    declared=_declared(root, links, source))


def _declared(root: ET.Element, links: dict[str, ET.Element], source: str) -> tuple[tuple[str, str, str], ...]:
    """The ``<disable_collisions link1 link2 reason>`` elements: ``(link1, link2, reason)`` each.

    Raises:
        CellError: an element without two distinct link names, or naming a link the file does not define.
    """
    return declared_pairs(root, links, source, CellError, "name two links of the cell (arm links with their prefix)")


def _tree(links: dict[str, ET.Element], joints: dict[str, ET.Element],
          source: str) -> tuple[dict[str, tuple[str, str]], dict[str, list[str]], str]:
    """The link tree: each child link's ``(joint, parent link)``, each link's child joints, and the one root link.

    Raises:
        CellError: an unsupported joint type, a joint naming a missing link, a link with
            two parents, or not exactly one root.
    """
    parent_of: dict[str, tuple[str, str]] = {}  # child link -> (joint, parent link)
    children: dict[str, list[str]] = {name: [] for name in links}  # link -> joints
    for jname, joint in joints.items():
        kind = joint.get("type")
        if kind not in _KINDS:
            raise CellError(
                f"{source}: joint {jname!r} is of type {kind!r}; a cell holds fixed, revolute, continuous "
                "and prismatic joints"
            )
        parent = joint.find("parent")
        child = joint.find("child")
        p = None if parent is None else parent.get("link")
        c = None if child is None else child.get("link")
        for role, link in (("parent", p), ("child", c)):
            if link not in links:
                raise CellError(f"{source}: joint {jname!r} names {role} link {link!r}, which is not defined")
        if c in parent_of:
            raise CellError(f"{source}: link {c!r} is the child of two joints ({parent_of[c][0]!r}, {jname!r})")
        parent_of[c] = (jname, p)
        children[p].append(jname)
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        raise CellError(
            f"{source}: a cell has one root link (the world); found {len(roots)}: {', '.join(roots) or 'none (a loop)'}"
        )
    return parent_of, children, roots[0]


def _arm(root: ET.Element, base: str, base_set: set[str], joints: dict[str, ET.Element],
         parent_of: dict[str, tuple[str, str]], children: dict[str, list[str]], child_of: dict[str, str],
         order: dict[str, int]) -> ArmSpec:
    """The arm whose base is ``base``: every link below it (up to another arm's base), its joints, name and prefix."""
    members = [base]
    stack = [child_of[j] for j in children[base]]
    while stack:
        link = stack.pop()
        if link in base_set:
            continue  # another arm bolted to this one's base: its own arm
        members.append(link)
        stack.extend(child_of[j] for j in children[link])
    members_set = set(members)
    arm_joints = [j for j in joints if parent_of[child_of[j]][1] in members_set and child_of[j] in members_set]
    arm_joints = [j for j in arm_joints if child_of[j] != base]
    if base.endswith("base_link"):
        prefix = base[: -len("base_link")]
        name = prefix.rstrip("_") or root.get("name", "arm")
    else:
        prefix, name = "", base
    if not all(n.startswith(prefix) for n in members + arm_joints):
        prefix = ""
    return ArmSpec(
        name=name,
        prefix=prefix,
        base_link=base,
        links=tuple(sorted(members, key=lambda n: (n != base, order[n]))),
        joints=tuple(arm_joints),
    )


def _strip(name: str, prefix: str) -> str:
    return name[len(prefix):] if prefix and name.startswith(prefix) else name


def arm_urdf(root: ET.Element, arm: ArmSpec) -> str:
    """The arm alone as URDF text: its links and joints (prefix removed), base link as root.

    Materials defined at the top level of the cell are kept (the arm's visuals name them).
    """
    out = ET.Element("robot", {"name": arm.name})
    links = {el.get("name"): el for el in root.findall("link")}
    joints = {el.get("name"): el for el in root.findall("joint")}
    for material in root.findall("material"):
        out.append(_copy(material))
    for name in arm.links:
        el = _copy(links[name])
        el.set("name", _strip(name, arm.prefix))
        out.append(el)
    for name in arm.joints:
        el = _copy(joints[name])
        el.set("name", _strip(name, arm.prefix))
        for tag in ("parent", "child"):
            sub = el.find(tag)
            sub.set("link", _strip(sub.get("link"), arm.prefix))
        mimic = el.find("mimic")
        if mimic is not None:
            mimic.set("joint", _strip(mimic.get("joint"), arm.prefix))
        out.append(el)
    ET.indent(out, space="  ")
    return ET.tostring(out, encoding="unicode") + "\n"


def _copy(el: ET.Element) -> ET.Element:
    return ET.fromstring(ET.tostring(el))
