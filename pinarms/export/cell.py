"""Whole cells out: one folder with the cell's URDF, SRDF and MJCF and the meshes they use.

``export_cell(cell_or_name, out_dir)`` writes

    out_dir/
        <cell>.urdf     arms and fixtures; mesh paths relative to this file; one collision
                        element per link (see below); loads in Pinocchio, MoveIt, yourdfpy
        <cell>.srdf     planning groups, end effectors, named states, disable_collisions
                        (:mod:`pinarms.export.srdf`)
        <cell>.xml      MuJoCo: every link a body, fixtures as geoms of static bodies, a site
                        at every arm's flange and tcp, ``<mimic>`` as joint equalities, each
                        collision geom named like pinarms' geometry (``left_forearm_link_0``)
        meshes/...      every mesh file referenced

**One collision element per link.** SRDF disables collisions between links; pinarms
classifies geometries. A link ``L`` with several ``<collision>`` elements keeps the first,
and the k-th moves (same origin, same geometry) to a new link ``L_collision_k`` held to ``L``
by a fixed joint ``L_collision_k_joint`` at the identity: the bodies and their geometry do
not change, and the SRDF can name every geometry pair.

Everything is written into a temporary sibling folder and renamed into place.
"""

from __future__ import annotations

import os
import shutil
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, TYPE_CHECKING

from pinarms.files import copy_new_file, path_inside, publish_folder, safe_file_name, write_new_file
from pinarms.errors import InvalidInput

from pinarms.export.mesh_convert import binary_stl
from pinarms.export.mesh_sources import MAX_COPY_BYTES, MeshFolders, mesh_source
from pinarms.export.urdf_files import check_export_folder, compile_mjcf, write_urdf_folder
from pinarms.export.srdf import geometry_links, home_notes, srdf_text

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from pinarms.robots.cell.cell import Cell
    from pinarms.robots.robot import Robot

__all__ = ["ExportedCell", "export_cell", "one_collision_per_link", "cell_of_urdf_folder"]


@dataclass(frozen=True)
class ExportedCell:
    """What :func:`export_cell` wrote.

    Attributes:
        folder: the export folder; ``urdf``, ``srdf``, ``mjcf``: the files in it (``mjcf``
            ``None`` when not asked).
        meshes: the copied mesh files, relative to ``folder`` (POSIX paths), sorted.
        sites: the MuJoCo sites (each arm's flange and tcp).
        geometry_links: ``{pinarms geometry name: exported link name}``.
        notes: what the export left out and why (an arm without a home state:
            :func:`pinarms.export.srdf.home_notes`).
    """

    folder: Path
    urdf: Path
    srdf: Path | None
    mjcf: Path | None
    meshes: tuple[str, ...]
    sites: tuple[str, ...]
    geometry_links: dict[str, str]
    notes: tuple[str, ...] = ()


def _parse(text: str) -> ET.Element:
    return ET.fromstring(text, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True)))


def one_collision_per_link(root: ET.Element) -> dict[str, str]:
    """Move every ``<collision>`` after a link's first to its own link on a fixed joint (module doc), in place.

    Returns ``{new link: its parent link}``.
    """
    added: dict[str, str] = {}
    children = list(root)
    taken = {el.get("name") for el in root if el.tag in ("link", "joint")}
    for link in [el for el in children if el.tag == "link"]:
        collisions = link.findall("collision")
        position = list(root).index(link)
        for k, collision in enumerate(collisions[1:], start=1):
            name = f"{link.get('name')}_collision_{k}"
            if name in taken or f"{name}_joint" in taken:
                raise InvalidInput(f"cannot split the collisions of link {link.get('name')!r}: the name {name!r} is taken")
            link.remove(collision)
            new_link = ET.Element("link", {"name": name})
            new_link.append(collision)
            joint = ET.Element("joint", {"name": f"{name}_joint", "type": "fixed"})
            ET.SubElement(joint, "parent", {"link": link.get("name")})
            ET.SubElement(joint, "child", {"link": name})
            ET.SubElement(joint, "origin", {"xyz": "0 0 0", "rpy": "0 0 0"})
            root.insert(position + 2 * k - 1, new_link)
            root.insert(position + 2 * k, joint)
            added[name] = link.get("name")
    return added


def cell_folders(cell: Cell, packages: Mapping[str, str | os.PathLike] | None = None) -> MeshFolders:
    """The folders a cell's export may copy meshes from: its folder, pinarms' package, its packages and ``packages``."""
    from pinarms.robots.xacro_expand import BUILTIN_PACKAGE

    named = {BUILTIN_PACKAGE[0]: Path(BUILTIN_PACKAGE[1]), **cell.packages,
             **{str(k): Path(v) for k, v in (packages or {}).items()}}
    return MeshFolders(owner=f"cell {cell.name!r}", own=cell.base_dir, packages=named)


def _copy_meshes(root: ET.Element, folders: MeshFolders, folder: Path) -> tuple[str, ...]:
    """Copy every mesh ``root`` references (checked: :mod:`.mesh_sources`) into ``folder/meshes`` as
    ``meshes/<stem>.<suffix>`` (numbered when two share a name) and point the URDF at the copies.
    COLLADA textures are not copied (MuJoCo discards COLLADA visuals)."""
    dest_of: dict[Path, str] = {}
    used: set[str] = set()
    for mesh in root.iter("mesh"):
        source = mesh_source(mesh.get("filename", ""), folders).real
        if source not in dest_of:
            stem, suffix, k = safe_file_name(source.stem, "mesh"), source.suffix.lower(), 0
            name = f"meshes/{stem}{suffix}"
            while name in used:
                k += 1
                name = f"meshes/{stem}_{k}{suffix}"
            used.add(name)
            dest_of[source] = name
            stl = (lambda data, n=source.name: binary_stl(data, n)) if suffix == ".stl" else None
            copy_new_file(folder, name, source, MAX_COPY_BYTES, transform=stl)
        mesh.set("filename", dest_of[source])
    return tuple(sorted(dest_of.values()))


def _sites(cell: Any, root: ET.Element) -> tuple[str, ...]:
    links = {el.get("name") for el in root.iter("link")}
    return tuple(f for arm in cell.arms for f in dict.fromkeys((arm.prefix + "flange", arm.prefix + arm.robot.tcp_frame))
                 if f in links)


def _write_cell(cell: Any, folder: Path, *, srdf: bool, mjcf: bool,
                states: Mapping[str, Mapping[str, Any]] | None, folders: MeshFolders) -> ExportedCell:
    """Write the cell's files into the (new, empty) ``folder``; they are named after the cell, made a plain
    file name (:func:`pinarms.files.safe_file_name`)."""
    folder.mkdir(parents=True, exist_ok=True)
    name = safe_file_name(cell.name, "cell")
    root = _parse(cell.urdf_text)
    meshes = _copy_meshes(root, folders, folder)
    one_collision_per_link(root)
    links = geometry_links(cell)
    ET.indent(root)
    text = '<?xml version="1.0" ?>\n' + ET.tostring(root, encoding="unicode") + "\n"
    urdf = write_new_file(folder, f"{name}.urdf", text.encode("utf-8"))
    srdf_path = None
    if srdf:
        srdf_path = write_new_file(folder, f"{name}.srdf", srdf_text(cell, states=states).encode("utf-8"))
    sites = _sites(cell, root)
    mjcf_path = None
    if mjcf:
        mujoco = _mujoco()
        mjcf_path = path_inside(folder, f"{name}.xml")
        compile_mjcf(mujoco, urdf, meshes, mjcf_path, sites, f"cell {cell.name!r}",
                     geom_names={link: geometry for geometry, link in links.items()})
    notes = home_notes(cell, states=states) if srdf else ()
    return ExportedCell(folder, urdf, srdf_path, mjcf_path, meshes, sites if mjcf else (), links, notes)


def _mujoco():
    try:
        import mujoco
    except ImportError as exc:
        from pinarms.errors import ModelError

        raise ModelError("the MJCF export needs MuJoCo's Python package: pip install mujoco "
                         "(or pip install 'pinarms[mujoco]')") from exc
    return mujoco


def _load(cell_or_name: Any, packages: Mapping[str, str | os.PathLike] | None = None):
    from pinarms.robots.cell import Cell, load_cell

    cell = (load_cell(cell_or_name, packages=packages) if isinstance(cell_or_name, (str, os.PathLike))
            else cell_or_name)
    if not isinstance(cell, Cell):
        raise InvalidInput(f"export_cell takes a robots.cell.Cell, a built-in cell name or a cell file, got {cell_or_name!r}")
    return cell


def export_cell(cell_or_name: Cell | str | os.PathLike, out_dir: str | os.PathLike, *, srdf: bool = True, mjcf: bool = True,
                states: Mapping[str, Mapping[str, ArrayLike]] | None = None, overwrite: bool = False,
                packages: Mapping[str, str | os.PathLike] | None = None) -> ExportedCell:
    """Write a whole cell (URDF + SRDF + MJCF + meshes) into ``out_dir`` (module doc).

    Args:
        cell_or_name: a :class:`pinarms.robots.cell.Cell`, a built-in cell name or a cell file.
        srdf, mjcf: write the SRDF, the MJCF (the latter needs ``mujoco``).
        states: extra named SRDF states ``{name: {arm: q_arm}}`` (:func:`srdf.cycle_states`).
        overwrite: replace a non-empty ``out_dir`` (only once the new one is complete). A
            symbolic link to a folder is written through (the link stays); the folder gets the
            umask's permissions.
        packages: ``{NAME: folder}`` for ``package://NAME/`` files (a cell name or file is
            loaded with them). Meshes are copied only from the cell's folder, pinarms' package,
            the cell's packages and these (:mod:`.mesh_sources`).

    Raises:
        CellNotFound: unknown cell name. InvalidInput: a cell holding a delta; ``out_dir`` is a file or not empty
        (without ``overwrite``); a bad state. MeshNotFound: a mesh cannot be found.
        MeshNotAllowed: a mesh outside the allowed folders or not a mesh file.
        ModelError: MuJoCo is missing or refuses the model.
    """
    cell = _load(cell_or_name, packages)
    if getattr(cell, "deltas", ()):
        raise InvalidInput(f"cell {cell.name!r} holds a delta ({', '.join(d.name for d in cell.deltas)}): its URDF "
                           "carries the delta's motors only (its bodies come from the closed form); export the delta "
                           "with pinarms.export.delta and the rest of the cell without it")
    out = check_export_folder(out_dir, overwrite)
    result: dict[str, ExportedCell] = {}
    folders = cell_folders(cell, packages)

    def fill(tmp: Path) -> None:
        result["cell"] = _write_cell(cell, tmp, srdf=srdf, mjcf=mjcf, states=states, folders=folders)

    publish_folder(out, fill)
    r = result["cell"]
    move = lambda p: None if p is None else out / p.name  # noqa: E731
    return ExportedCell(out, out / r.urdf.name, move(r.srdf), move(r.mjcf), r.meshes, r.sites, r.geometry_links,
                        r.notes)


def cell_of_urdf_folder(robot: Robot, folder: Path):
    """A one-arm :class:`Cell` of ``robot`` built from its exported (self-contained) URDF folder."""
    from pinarms.robots.cell import Cell

    text = (folder / f"{safe_file_name(robot.name, 'robot')}.urdf").read_text(encoding="utf-8")
    return Cell(text, source=f"robot {robot.name!r}", base_dir=folder)


def export_robot_with_srdf(robot: Robot, out_dir: str | os.PathLike, *, overwrite: bool = False,
                           states: Mapping[str, ArrayLike] | None = None,
                           packages: Mapping[str, str | os.PathLike] | None = None) -> ExportedCell:
    """One arm as a folder with its URDF (one collision per link) and SRDF (one-arm cell rules)."""
    out = check_export_folder(out_dir, overwrite)
    result: dict[str, ExportedCell] = {}

    def fill(tmp: Path) -> None:
        staged = write_urdf_folder(robot, tmp / "staged", packages=packages)
        cell = cell_of_urdf_folder(robot, staged.folder)
        arm_states = None if states is None else {k: {cell.arms[0].name: v} for k, v in states.items()}
        result["cell"] = _write_cell(cell, tmp / "out", srdf=True, mjcf=False, states=arm_states,
                                     folders=cell_folders(cell))
        for entry in (tmp / "out").iterdir():
            os.rename(entry, tmp / entry.name)
        (tmp / "out").rmdir()
        shutil.rmtree(staged.folder)

    publish_folder(out, fill)
    r = result["cell"]
    return ExportedCell(out, out / r.urdf.name, out / r.srdf.name, None, r.meshes, (), r.geometry_links, r.notes)
