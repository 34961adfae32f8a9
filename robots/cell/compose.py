"""Any URDF arm in a cell under a prefix: a cell description file, or :func:`compose_cell`.

A **cell description** (``*.toml``, docs/cells.md "Any URDF arm in a cell") lists arms by
their URDF file, name and base pose, and fixtures as primitives::

    name = "two_scaras"

    [[arm]]
    name = "left"                   # the arm's name; every link, joint and material gets "left_"
    urdf = "user_scara.urdf"        # beside this file, or "package://vendor/urdf/arm.urdf"
    xyz = [0.0, 0.45, 0.0]          # base_to_world [m] and roll-pitch-yaw [rad]
    rpy = [0.0, 0.0, -1.5707963267948966]

    [[fixture]]
    name = "belt"
    box = [2.0, 0.30, 0.05]         # or cylinder = [radius, length], sphere = radius [m]
    xyz = [0.0, 0.0, 0.30]

It is expanded into a cell URDF (:func:`compose_cell_urdf`): each arm's links, joints,
``<mimic>`` references and materials prefixed, its base link named ``<prefix>base_link``
(so the cell names the arm after the prefix), relative mesh paths rewritten to resolve
from the cell's folder, the arm's root fixed to the world at its pose. Elements other
than links, joints and materials (transmissions, gazebo tags) are left out.

A received file is not trusted: URDF paths are relative, without ``..``, and resolve
(symbolic links followed) inside the description's folder or a package folder the caller
names; the description is read only up to :data:`MAX_DESCRIPTION_BYTES`, each arm file up
to :data:`MAX_ARM_BYTES`; at most :data:`MAX_ARMS` arms and :data:`MAX_FIXTURES`
fixtures; every number finite; unknown keys are errors. Failures are :class:`CellError`
(content), :class:`CellNotFound` (a missing file) or :class:`XacroForbidden` (a path
outside the allowed folders), each naming the file.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Mapping, Sequence

from pinarms.errors import CellError, ModelError, XacroForbidden
from pinarms.robots.urdf_checks import check_tree, refuse_dtd
from pinarms.robots.cell.cell import Cell
from pinarms.robots.cell.compose_file import (
    FIXTURE_SIZES,
    MAX_ARM_BYTES,
    MAX_ARMS,
    MAX_FIXTURES,
    ArmPlacement,
    CellDescription,
    FixturePrimitive,
    ToolPoint,
    check_name,
    check_crate,
    read_cell_file,
    read_cell_description,
)
from pinarms.robots.cell.arm_keys import rewrite_arm
from pinarms.robots.cell.description import MOVABLE_JOINTS

__all__ = [
    "ArmPlacement",
    "ToolPoint",
    "FixturePrimitive",
    "CellDescription",
    "read_cell_description",
    "compose_cell_urdf",
    "compose_cell",
    "load_cell_description",
]


def _inside(real: Path, roots: Sequence[Path]) -> bool:
    return any(real == r or r in real.parents for r in roots)


def _arm_file(ref: str | os.PathLike, base_dir: Path, packages: Mapping[str, Path], strict: bool, where: str) -> Path:
    """The arm URDF ``ref`` names, checked to lie in ``base_dir`` or a package folder.

    ``strict`` (a description file): ``ref`` must be relative, without ``..``.
    """
    text = str(ref).strip()
    if text.startswith("package://"):
        pkg, _, rel = text[len("package://"):].partition("/")
        if pkg not in packages:
            raise XacroForbidden(f"{where}: urdf {text!r} names package {pkg!r}, which is not among the packages "
                                 f"given ({', '.join(sorted(packages)) or 'none'}); pass packages={{{pkg!r}: folder}} "
                                 f"(on the command line --package {pkg}=FOLDER)")
        root, rel_path = packages[pkg], rel
    else:
        root, rel_path = base_dir, text
    parts = re.split(r"[/\\]", rel_path)
    if strict and (os.path.isabs(rel_path) or rel_path.startswith(("/", "\\", "file:")) or ".." in parts):
        raise XacroForbidden(f"{where}: urdf {text!r} must be a relative path without '..' (inside the "
                             "description's folder) or package://PKG/path")
    target = Path(rel_path) if os.path.isabs(rel_path) else root / rel_path
    real = Path(os.path.realpath(target))
    roots = [Path(os.path.realpath(base_dir)), *(Path(os.path.realpath(p)) for p in packages.values())]
    if not _inside(real, roots):
        raise XacroForbidden(f"{where}: urdf {text!r} lies outside the folders the cell may read "
                             f"({', '.join(str(r) for r in roots)})")
    return real


# ------------------------------------------------------------- the cell URDF
def _fmt(values: Sequence[float]) -> str:
    return " ".join(repr(float(v)) for v in values)


def _mesh_ref(filename: str, arm_dir: Path, base_dir: Path, packages: Mapping[str, Path]) -> str:
    """A relative mesh path of an arm file, rewritten to resolve from the cell's folder (or a package)."""
    text = filename.strip()
    if text.startswith(("package://", "file://")) or os.path.isabs(text):
        return text
    real = Path(os.path.realpath(arm_dir / text))
    base = Path(os.path.realpath(base_dir))
    if _inside(real, [base]):
        return real.relative_to(base).as_posix()
    for pkg, folder in packages.items():
        root = Path(os.path.realpath(folder))
        if _inside(real, [root]):
            return f"package://{pkg}/{real.relative_to(root).as_posix()}"
    return str(real)  # outside every allowed folder: the cell's mesh check refuses it, naming the file


def _parse_arm(path: Path, source: str) -> ET.Element:
    text = read_cell_file(path, MAX_ARM_BYTES, source)
    try:
        refuse_dtd(text, source)
        root = ET.fromstring(text)
        if root.tag != "robot":
            raise ModelError(f"{source} is not a URDF: its root element is <{root.tag}>, expected <robot>")
        check_tree(root, source)
    except ET.ParseError as exc:
        raise CellError(f"{source} is not well-formed XML: {exc}") from exc
    except ModelError as exc:
        raise CellError(str(exc)) from exc
    return root


def _base_of(root: ET.Element, source: str) -> tuple[str, str]:
    """The arm's root link and its base (the one static link its movable joints hang from)."""
    below: dict[str, list[tuple[str, str]]] = {}  # parent link -> [(joint type, child link)]
    child_links = set()
    for j in root.findall("joint"):
        child = j.find("child").get("link")
        child_links.add(child)
        below.setdefault(j.find("parent").get("link"), []).append((j.get("type"), child))
    root_link = next(ln.get("name") for ln in root.findall("link") if ln.get("name") not in child_links)
    static, stack = [], [root_link]
    while stack:  # links reached from the root through fixed joints only
        link = stack.pop()
        static.append(link)
        stack.extend(child for kind, child in below.get(link, ()) if kind == "fixed")
    bases = [ln for ln in static if any(kind in MOVABLE_JOINTS for kind, _ in below.get(ln, ()))]
    if len(bases) != 1:
        raise CellError(f"{source}: an arm has one base (a link reached through fixed joints from the root, with "
                        f"movable joints below it); found {len(bases)}: {bases[:5]}")
    return root_link, bases[0]


def _arm_elements(arm: ArmPlacement, path: Path, base_dir: Path, packages: Mapping[str, Path]) -> list[ET.Element]:
    """The arm's materials, links, joints and ``<disable_collisions>``, prefixed, and the fixed joint that mounts it."""
    source = f"URDF {str(path)!r} of arm {arm.name!r}"
    if path.name.endswith(".xacro"):
        raise CellError(f"{source} is a xacro file: expand it first (`pinarms urdf build {path.name} -o arm.urdf`) "
                        "or place it from a xacro cell")
    root = _parse_arm(path, source)
    rewrite_arm(root, arm, source)  # frozen joints fixed at their values, the tool point as a link "tcp"
    root_link, base = _base_of(root, source)
    link_names = {ln.get("name") for ln in root.findall("link")}
    rename = {}
    if base != "base_link":
        if "base_link" in link_names:
            raise CellError(f"{source}: its base is {base!r} but another link is called 'base_link'; the cell names "
                            "an arm's base <prefix>base_link: rename one of them")
        rename[base] = "base_link"
    prefix = arm.name + "_"

    def link(name: str) -> str:
        return prefix + rename.get(name, name)

    out = []
    for el in root:
        if el.tag == "disable_collisions":  # the arm's own contacts by design, under the cell's link names
            out.append(ET.Element("disable_collisions", {"link1": link(el.get("link1", "")),
                                                         "link2": link(el.get("link2", "")), "reason": el.get("reason", "")}))
            continue
        if el.tag not in ("material", "link", "joint"):
            continue  # transmissions, gazebo and control tags: not part of the cell's model
        el = ET.fromstring(ET.tostring(el))
        el.set("name", link(el.get("name")) if el.tag == "link" else prefix + el.get("name", ""))
        for tag in ("parent", "child"):
            sub = el.find(tag) if el.tag == "joint" else None
            if sub is not None:
                sub.set("link", link(sub.get("link")))
        for mimic in el.iter("mimic"):
            mimic.set("joint", prefix + mimic.get("joint", ""))
        for material in el.iter("material"):
            if material is not el and material.get("name"):
                material.set("name", prefix + material.get("name"))
        for mesh in el.iter("mesh"):
            mesh.set("filename", _mesh_ref(mesh.get("filename", ""), path.parent, base_dir, packages))
        out.append(el)
    mount = ET.Element("joint", {"name": f"{prefix}mount_joint", "type": "fixed"})
    ET.SubElement(mount, "origin", {"xyz": _fmt(arm.xyz), "rpy": _fmt(arm.rpy)})
    ET.SubElement(mount, "parent", {"link": "world"})
    ET.SubElement(mount, "child", {"link": link(root_link)})
    return out + [mount]


def _crate_elements(fixture: FixturePrimitive) -> list[ET.Element]:
    """A crate as the ``fixture_crate`` macro makes it: the floor slab (its frame) and four walls on it."""
    sx, sy, h = fixture.size
    wall, floor = fixture.wall, fixture.floor
    parts = [(fixture.name, (sx, sy, floor), fixture.xyz, fixture.rpy, "world")]
    for side, size, xyz in (("xpos", (wall, sy), ((sx - wall) / 2.0, 0.0)), ("xneg", (wall, sy), (-(sx - wall) / 2.0, 0.0)),
                            ("ypos", (sx - 2.0 * wall, wall), (0.0, (sy - wall) / 2.0)),
                            ("yneg", (sx - 2.0 * wall, wall), (0.0, -(sy - wall) / 2.0))):
        parts.append((f"{fixture.name}_wall_{side}", (*size, h - floor), (*xyz, h / 2.0), (0.0, 0.0, 0.0), fixture.name))
    out = []
    for name, size, xyz, rpy, parent in parts:
        box = FixturePrimitive(name, "box", tuple(float(v) for v in size), xyz, rpy)
        link, joint = _fixture_elements(box)
        joint.find("parent").set("link", parent)
        out += [link, joint]
    return out


def _fixture_elements(fixture: FixturePrimitive) -> list[ET.Element]:
    if fixture.kind == "crate":
        return _crate_elements(fixture)
    link = ET.Element("link", {"name": fixture.name})
    for tag in ("visual", "collision"):
        part = ET.SubElement(link, tag)
        geometry = ET.SubElement(part, "geometry")
        size = fixture.size
        attrs = {"box": {"size": _fmt(size)}, "cylinder": {"radius": repr(size[0]), "length": repr(size[-1])},
                 "sphere": {"radius": repr(size[0])}}[fixture.kind]
        ET.SubElement(geometry, fixture.kind, attrs)
        if tag == "visual":
            material = ET.SubElement(part, "material", {"name": f"{fixture.name}_colour"})
            ET.SubElement(material, "color", {"rgba": "0.72 0.72 0.70 1.0"})
    joint = ET.Element("joint", {"name": f"{fixture.name}_joint", "type": "fixed"})
    ET.SubElement(joint, "origin", {"xyz": _fmt(fixture.xyz), "rpy": _fmt(fixture.rpy)})
    ET.SubElement(joint, "parent", {"link": "world"})
    ET.SubElement(joint, "child", {"link": fixture.name})
    return [link, joint]


def _check_entries(arms: Sequence[ArmPlacement], fixtures: Sequence[FixturePrimitive]) -> None:
    if not arms or len(arms) > MAX_ARMS or len(fixtures) > MAX_FIXTURES:
        raise CellError(f"a composed cell holds 1 to {MAX_ARMS} arms and at most {MAX_FIXTURES} fixtures; got "
                        f"{len(arms)} and {len(fixtures)}")
    for a in arms:
        if not isinstance(a, ArmPlacement):
            raise CellError(f"arms must be ArmPlacement entries, got {type(a).__name__}")
        check_name(a.name, f"arm {a.name!r}")
    for f in fixtures:
        if not isinstance(f, FixturePrimitive):
            raise CellError(f"fixtures must be FixturePrimitive entries, got {type(f).__name__}")
        check_name(f.name, f"fixture {f.name!r}")
        if f.kind not in FIXTURE_SIZES or len(f.size) != FIXTURE_SIZES[f.kind] or min(f.size) <= 0.0:
            raise CellError(f"fixture {f.name!r}: a {f.kind!r} needs {FIXTURE_SIZES.get(f.kind, '?')} positive size(s); "
                            f"kinds: {', '.join(FIXTURE_SIZES)}")
        check_crate(f, f"fixture {f.name!r}")
        for a in arms:
            if f.name == a.name or f.name.startswith(a.name + "_"):
                raise CellError(f"fixture {f.name!r} clashes with the names of arm {a.name!r} (prefix {a.name + '_'!r})")
    names = [a.name for a in arms] + [f.name for f in fixtures] + ["world"]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise CellError(f"the name {dup[0]!r} is used twice (arms, fixtures and 'world' need distinct names)")
    for a in arms:
        clash = [b.name for b in arms if b is not a and b.name.startswith(a.name + "_")]
        if clash:
            raise CellError(f"arm {clash[0]!r} starts with the prefix of arm {a.name!r}; their names would mix")


def compose_cell_urdf(
    arms: Sequence[ArmPlacement],
    fixtures: Sequence[FixturePrimitive] = (),
    *,
    name: str = "cell",
    base_dir: str | os.PathLike = ".",
    packages: Mapping[str, str | os.PathLike] | None = None,
    strict: bool = False,
    declared: Sequence[tuple[str, str, str]] = (),
) -> str:
    """The cell URDF of ``arms`` (each prefixed ``<name>_``, mounted at its pose) and primitive ``fixtures``.

    Arm files resolve against ``base_dir`` (or ``package://PKG/``) and must lie inside it or
    a package folder; ``strict`` (used for description files) also refuses absolute paths
    and ``..``. Relative mesh paths are rewritten to resolve from ``base_dir``. ``declared``:
    ``(link1, link2, reason)`` pairs of the cell's links in contact by design, written as
    ``<disable_collisions>`` elements (checked against the links when the cell is loaded).

    Raises:
        CellError: bad names or sizes, an arm file that is too large, malformed, not one
            tree or without exactly one base.
        CellNotFound: an arm file does not exist.
        XacroForbidden: an arm file outside the allowed folders.
    """
    _check_entries(arms, fixtures)
    check_name(name, "cell")
    base = Path(base_dir).resolve()
    pkgs = {str(k): Path(v) for k, v in (packages or {}).items()}
    robot = ET.Element("robot", {"name": name})
    ET.SubElement(robot, "link", {"name": "world"})
    for arm in arms:
        if arm.delta is not None:  # a delta: its actuated joints only, its bodies from the closed form
            from pinarms.robots.cell.delta_urdf import delta_elements

            robot.extend(delta_elements(arm))
            continue
        path = _arm_file(arm.urdf, base, pkgs, strict, f"arm {arm.name!r}")
        robot.extend(_arm_elements(arm, path, base, pkgs))
    for fixture in fixtures:
        robot.extend(_fixture_elements(fixture))
    for a, b, note in declared:
        ET.SubElement(robot, "disable_collisions", {"link1": str(a), "link2": str(b), "reason": str(note)})
    ET.indent(robot, space="  ")
    return ET.tostring(robot, encoding="unicode") + "\n"


def compose_cell(
    arms: Sequence[ArmPlacement],
    fixtures: Sequence[FixturePrimitive] = (),
    *,
    name: str = "cell",
    base_dir: str | os.PathLike = ".",
    packages: Mapping[str, str | os.PathLike] | None = None,
    seed: int = 0,
) -> Cell:
    """A :class:`~.cell.Cell` of any URDF arms under their prefixes (see :func:`compose_cell_urdf`)."""
    text = compose_cell_urdf(arms, fixtures, name=name, base_dir=base_dir, packages=packages)
    return Cell(text, source=f"composed cell {name!r}", base_dir=Path(base_dir).resolve(), packages=packages, seed=seed,
                placements=arms)


def load_cell_description(
    path: str | os.PathLike, *, packages: Mapping[str, str | os.PathLike] | None = None, seed: int = 0
) -> Cell:
    """Load a cell description file (``*.toml``): read, checked, composed into a cell URDF, loaded.

    ``packages``: ``{name: folder}`` for ``package://name/`` arm files and meshes.
    ``robots.load_cell(path)`` calls this for a ``.toml`` file.
    """
    desc = read_cell_description(path)
    text = compose_cell_urdf(desc.arms, desc.fixtures, name=desc.name, base_dir=desc.base_dir, packages=packages,
                             strict=True, declared=desc.declared)
    return Cell(text, source=str(path), base_dir=desc.base_dir, packages=packages, seed=seed, placements=desc.arms)
