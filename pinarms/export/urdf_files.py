"""Writing export folders: a robot's URDF with its meshes, folders published atomically, MJCF compiling.

The plumbing under :mod:`pinarms.export.robot` (one arm) and :mod:`pinarms.export.cell`
(a cell): both import it, and it imports neither, so the two exports do not import each
other. Users call :func:`pinarms.export.export_urdf` and friends, not this module.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Mapping

from pinarms.files import copy_new_file, output_folder, path_inside, publish_folder, safe_file_name, write_new_file
from pinarms.errors import InvalidInput, ModelError
from pinarms.robots.robot import Robot

from pinarms.export.errors import ExportError, MeshNotAllowed
from pinarms.export.mesh_convert import mujoco_conversions
from pinarms.export.mesh_sources import MAX_COPY_BYTES, MeshFolders, MeshSource, collada_textures, mesh_source

__all__ = ["ExportedURDF", "check_export_folder", "mesh_references", "write_urdf_folder", "compile_mjcf", "robot_folders", "plan_copies",
           "copy_files", "SITE_SIZE_M"]

#: Radius of the exported sites [m] (they are markers: no mass, no collision).
SITE_SIZE_M = 0.01


@dataclass(frozen=True)
class ExportedURDF:
    """What :func:`export_urdf` wrote.

    Attributes:
        folder: the export folder.
        urdf: the URDF file inside it.
        meshes: the copied files, relative to ``folder`` (POSIX paths), sorted.
        srdf: the SRDF file (``srdf=True``), else ``None``.
        notes: what the export left out and why (an arm without a home state).
    """

    folder: Path
    urdf: Path
    meshes: tuple[str, ...]
    srdf: Path | None = None
    notes: tuple[str, ...] = ()


def mesh_references(urdf_text: str) -> list[str]:
    """Every distinct ``<mesh filename=...>`` of a URDF, in document order."""
    try:
        root = ET.fromstring(urdf_text)
    except ET.ParseError as exc:
        raise ModelError(f"the URDF is not well-formed XML: {exc}") from exc
    seen: dict[str, None] = {}
    for mesh in root.iter("mesh"):
        name = mesh.get("filename")
        if name:
            seen.setdefault(name, None)
    return list(seen)


def robot_folders(robot: Robot, packages: Mapping[str, str | os.PathLike] | None = None) -> MeshFolders:
    """The folders a robot's export may copy meshes from: its URDF's folder, the folders it was loaded with
    (``robot.package_dirs``) and ``packages`` (:mod:`.mesh_sources`)."""
    own = None if robot.urdf_path is None else Path(robot.urdf_path).parent
    return MeshFolders(owner=f"robot {robot.name!r}", own=own,
                       packages={str(k): Path(v) for k, v in (packages or {}).items()},
                       search=tuple(Path(d) for d in robot.package_dirs))


def plan_copies(references: list[str], folders: MeshFolders) -> tuple[dict[str, str], dict[str, Path]]:
    """``({reference: its path in the export}, {path in the export: real source})`` of meshes and their textures.

    Raises:
        MeshNotAllowed, MeshNotFound: see :func:`.mesh_sources.mesh_source`.
    """
    mapping: dict[str, str] = {}
    copies: dict[str, Path] = {}

    def take(source: MeshSource) -> str:
        dest, k = source.dest, 0
        while dest in copies and copies[dest] != source.real:  # two files, one name: number the later one
            k += 1
            stem, dot, suffix = source.dest.rpartition(".")
            dest = f"{stem}_{k}{dot}{suffix}"
        copies[dest] = source.real
        return dest

    for ref in references:
        source = mesh_source(ref, folders)
        mapping[ref] = take(source)
        for texture in collada_textures(MeshSource(source.real, mapping[ref]), folders):
            if copies.get(texture.dest, texture.real) != texture.real:
                raise MeshNotAllowed(f"{folders.owner}: texture {texture.dest!r} of mesh {ref[:200]!r} would replace "
                                     f"another file of the export ({copies[texture.dest]})")
            copies[texture.dest] = texture.real
    return mapping, copies


def copy_files(folder: Path, copies: Mapping[str, Path]) -> None:
    """Copy each real source to its path in ``folder`` (each proven inside it, each a new file)."""
    for dest, source in copies.items():
        copy_new_file(folder, dest, source, MAX_COPY_BYTES)


def _rewrite_filenames(urdf_text: str, mapping: dict[str, str], *, complete: bool = False) -> str:
    """Replace the mesh ``filename`` attribute values (and only those) in the raw text.

    Raises:
        ExportError: with ``complete``, a mesh reference left that is not one of the new values
            (the text spells it otherwise, with XML character references): the URDF would point
            outside its folder.
    """

    def repl(match: re.Match) -> str:
        quote, value = match.group(2), match.group(3)
        if value not in mapping:
            return match.group(0)
        return f"{match.group(1)}{quote}{mapping[value]}{quote}"

    pattern = re.compile(r"(<mesh\b[^>]*?\bfilename\s*=\s*)([\"'])(.*?)\2", re.DOTALL)
    text = pattern.sub(repl, urdf_text)
    left = [ref for ref in mesh_references(text) if ref not in mapping.values()] if complete else []
    if left:
        raise ExportError(f"mesh reference {left[0][:200]!r} could not be rewritten to its copy; "
                          "write it without XML character references")
    return text


def check_export_folder(out_dir: str | os.PathLike, overwrite: bool) -> Path:
    """The real export folder of ``out_dir`` (a link to a folder: that folder), refused when not empty
    unless ``overwrite`` (every export writes its files through :func:`pinarms.files.publish_folder` into it).

    Raises:
        InvalidInput: the folder holds files and ``overwrite`` is False.
    """
    out = output_folder(out_dir)
    if out.is_dir() and any(out.iterdir()) and not overwrite:
        raise InvalidInput(f"export folder {str(out_dir)!r} is not empty; choose another folder or pass "
                           "overwrite=True (on the command line --overwrite)")
    return out


def write_urdf_folder(robot: Robot, out_dir: str | os.PathLike, overwrite: bool = False,
                      packages: Mapping[str, str | os.PathLike] | None = None) -> ExportedURDF:
    """The URDF folder of :func:`pinarms.export.export_urdf` without an SRDF (``robot`` already loaded)."""
    out = check_export_folder(out_dir, overwrite)
    mapping, copies = plan_copies(mesh_references(robot.urdf_text), robot_folders(robot, packages))
    text = _rewrite_filenames(robot.urdf_text, mapping, complete=True)
    urdf_name = f"{safe_file_name(robot.name, 'robot')}.urdf"

    def fill(tmp: Path) -> None:
        write_new_file(tmp, urdf_name, text.encode("utf-8"))
        copy_files(tmp, copies)

    publish_folder(out, fill)
    return ExportedURDF(folder=out, urdf=out / urdf_name, meshes=tuple(sorted(copies)))


def compile_mjcf(mujoco, urdf: Path, meshes: tuple[str, ...], target: Path, sites: tuple[str, ...] | list[str],
                 label: str, geom_names: dict[str, str] | None = None) -> tuple[str, ...]:
    """Compile the self-contained URDF ``urdf`` (meshes at ``meshes`` beside it) into the MJCF file ``target``.

    Every link stays a body (``fusestatic="false"``), a site named like each frame of
    ``sites`` sits at the origin of its body, joint equalities (``<mimic>``) are made as
    stiff as the time step allows, mesh paths are made relative, COLLADA collision meshes
    and ASCII STL meshes are converted beside them (:mod:`.mesh_convert`; COLLADA visuals
    are discarded), and the meshes MuJoCo reads are copied beside ``target``. ``geom_names`` names the one collision geom of a
    body (``{body: name}``). Returns the meshes copied (POSIX paths relative to the folder).
    """
    folder = urdf.parent
    dae = any(m.lower().endswith(".dae") for m in meshes)
    extension = (f'<mujoco><compiler fusestatic="false" discardvisual="{"true" if dae else "false"}" '
                 'strippath="false"/></mujoco>')
    text = urdf.read_text(encoding="utf-8")
    converted = {}
    for mesh, new, convert in mujoco_conversions(text, folder):  # COLLADA, ASCII STL (.mesh_convert)
        converted[mesh] = new
        copy_new_file(folder, new, path_inside(folder, mesh), MAX_COPY_BYTES, transform=convert)
    text = _rewrite_filenames(text, converted) if converted else text
    head, end, tail = text.rpartition("</robot>")
    path_inside(target.parent, target.name)
    compiled = write_new_file(folder, urdf.stem + ".mujoco.urdf", f"{head}{extension}\n{end}{tail}".encode("utf-8"))
    try:
        model = mujoco.MjModel.from_xml_path(str(compiled))
        mujoco.mj_saveLastXML(str(target), model)
    except Exception as exc:  # MuJoCo raises ValueError with its own message
        raise ModelError(f"MuJoCo refuses {label}: {' '.join(str(exc).split())}") from exc
    finally:
        compiled.unlink(missing_ok=True)
    tree = ET.parse(target)
    for frame in sites:
        body = tree.getroot().find(f".//body[@name='{frame}']")
        if body is None:  # pragma: no cover - fusestatic="false" keeps every link
            raise ModelError(f"MuJoCo dropped the body {frame!r} of {label}")
        ET.SubElement(body, "site", {"name": frame, "size": f"{SITE_SIZE_M:g}", "rgba": "0.85 0.15 0.15 1"})
    for body_name, geom_name in (geom_names or {}).items():
        body = tree.getroot().find(f".//body[@name='{body_name}']")
        colliding = [] if body is None else [g for g in body.findall("geom")
                                             if g.get("contype", "1") != "0" or g.get("conaffinity", "1") != "0"]
        if len(colliding) != 1:
            raise ModelError(f"MuJoCo made {len(colliding)} colliding geoms of body {body_name!r} of {label}, "
                             "expected one")
        colliding[0].set("name", geom_name)
    _mesh_paths_relative_to(tree, folder, target.parent)
    step = float(model.opt.timestep)
    for eq in tree.getroot().iter("equality"):
        for joint in eq.iter("joint"):  # a linkage is rigid: the stiffest constraint the time step allows
            joint.set("solref", f"{2.0 * step:g} 1")
            joint.set("solimp", "0.99 0.999 0.001")
    ET.indent(tree)
    tree.write(target, encoding="unicode")
    kept = [m for m in meshes if not (dae and m.lower().endswith(".dae"))] + list(converted.values())
    if Path(os.path.realpath(target.parent)) != Path(os.path.realpath(folder)):
        for mesh in kept:
            copy_new_file(target.parent, mesh, path_inside(folder, mesh), MAX_COPY_BYTES)
    return tuple(sorted(kept))

def _mesh_paths_relative_to(tree: ET.ElementTree, source: Path, target: Path) -> None:
    """Mesh ``file`` attributes of a saved MJCF, relative to ``source``, made relative to ``target``'s layout.

    The staged URDF folder and the final folder hold the meshes at the same relative paths
    (``meshes/...``), so a path is kept relative and stripped of any absolute prefix.
    """
    root = tree.getroot()
    compiler = root.find("compiler")
    if compiler is not None:
        for key in ("meshdir", "assetdir", "texturedir"):
            compiler.attrib.pop(key, None)
    for mesh in root.iter("mesh"):
        file = mesh.get("file")
        if not file:
            continue
        path = Path(file)
        if path.is_absolute():
            try:
                path = path.relative_to(source)
            except ValueError:
                continue
        mesh.set("file", PurePosixPath(*path.parts).as_posix())
