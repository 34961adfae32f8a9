"""Writing export folders: a robot's URDF with its meshes, folders published atomically, MJCF compiling.

The plumbing under :mod:`pinarms.export.robot` (one arm) and :mod:`pinarms.export.cell`
(a cell): both import it, and it imports neither, so the two exports do not import each
other. Users call :func:`pinarms.export.export_urdf` and friends, not this module.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Callable

from pinarms.robots.errors import InvalidInput, ModelError
from pinarms.robots.robot import Robot

__all__ = ["ExportedURDF", "mesh_references", "write_urdf_folder", "compile_mjcf", "SITE_SIZE_M"]

#: Radius of the exported sites [m] (they are markers: no mass, no collision).
SITE_SIZE_M = 0.01


@dataclass(frozen=True)
class ExportedURDF:
    """What :func:`export_urdf` wrote.

    Attributes:
        folder: the export folder.
        urdf: the URDF file inside it.
        meshes: the copied files, relative to ``folder`` (POSIX paths), sorted.
    """

    folder: Path
    urdf: Path
    meshes: tuple[str, ...]
    srdf: Path | None = None


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


def _resolve(reference: str, robot: Robot) -> tuple[Path, PurePosixPath]:
    """Source file of a mesh reference and its destination under ``meshes/``."""
    if reference.startswith("package://"):
        rest = PurePosixPath(reference[len("package://") :])
        for base in robot.package_dirs:
            candidate = Path(base) / rest
            if candidate.is_file():
                return candidate, PurePosixPath("meshes") / rest
        raise ModelError(
            f"robot '{robot.name}': mesh {reference!r} not found in its package folders "
            f"{list(robot.package_dirs)}; load it with robots.from_urdf(path, package_dirs=...)"
        )
    path_text = reference[len("file://") :] if reference.startswith("file://") else reference
    path = Path(path_text)
    if not path.is_absolute():
        if robot.urdf_path is None:
            raise ModelError(
                f"robot '{robot.name}': relative mesh {reference!r} but the URDF has no file to resolve it from"
            )
        path = Path(robot.urdf_path).parent / path
    if not path.is_file():
        raise ModelError(f"robot '{robot.name}': mesh file {reference!r} does not exist ({path})")
    # keep the last folders of the original path so that equal file names stay distinct
    tail = PurePosixPath(*path.resolve().parts[-3:])
    return path, PurePosixPath("meshes") / "files" / tail


_IMAGE_RE = re.compile(r"<init_from>\s*([^<\s]+)\s*</init_from>")


def _collada_images(mesh_file: Path) -> list[str]:
    """Relative image files a COLLADA (.dae) mesh refers to."""
    if mesh_file.suffix.lower() != ".dae":
        return []
    text = mesh_file.read_text(encoding="utf-8", errors="replace")
    out = []
    for ref in _IMAGE_RE.findall(text):
        if "://" in ref or ref.startswith("/") or ref.startswith("#"):
            continue
        if Path(ref).suffix.lower() in (".png", ".jpg", ".jpeg", ".tga", ".bmp", ".tif", ".tiff"):
            out.append(ref)
    return out


def _rewrite_filenames(urdf_text: str, mapping: dict[str, str]) -> str:
    """Replace the mesh ``filename`` attribute values (and only those) in the raw text."""

    def repl(match: re.Match) -> str:
        quote, value = match.group(2), match.group(3)
        if value not in mapping:
            return match.group(0)
        return f"{match.group(1)}{quote}{mapping[value]}{quote}"

    pattern = re.compile(r"(<mesh\b[^>]*?\bfilename\s*=\s*)([\"'])(.*?)\2", re.DOTALL)
    return pattern.sub(repl, urdf_text)


def _check_folder(out_dir: str | os.PathLike, overwrite: bool) -> Path:
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InvalidInput(f"export folder {str(out)!r} is a file; give a folder path")
    if out.is_dir() and any(out.iterdir()) and not overwrite:
        raise InvalidInput(f"export folder {str(out)!r} is not empty; choose another folder or pass overwrite=True")
    return out


def _publish(out: Path, fill: Callable[[Path], None]) -> None:
    """Fill a temporary sibling folder with ``fill(tmp)``, then rename it to ``out``.

    A failure leaves no half-written folder; an existing ``out`` is removed only after the
    new one is in place (and put back if the rename fails).
    """
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".partial", dir=out.parent))
    try:
        fill(tmp)
        old = None
        if out.exists():
            if any(out.iterdir()):
                old = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".old", dir=out.parent))
                old.rmdir()
                os.rename(out, old)
            else:
                out.rmdir()
        try:
            os.rename(tmp, out)
        except OSError:
            if old is not None:
                os.rename(old, out)  # put the previous export back
            raise
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def write_urdf_folder(robot: Robot, out_dir: str | os.PathLike, overwrite: bool = False) -> ExportedURDF:
    """The URDF folder of :func:`pinarms.export.export_urdf` without an SRDF (``robot`` already loaded)."""
    out = _check_folder(out_dir, overwrite)
    mapping: dict[str, str] = {}
    copies: dict[PurePosixPath, Path] = {}
    for ref in mesh_references(robot.urdf_text):
        source, dest = _resolve(ref, robot)
        mapping[ref] = str(dest)
        copies[dest] = source
        for image in _collada_images(source):
            image_source = source.parent / image
            if image_source.is_file():
                copies[dest.parent / PurePosixPath(image)] = image_source
    text = _rewrite_filenames(robot.urdf_text, mapping)

    urdf_name = f"{robot.name}.urdf"

    def fill(tmp: Path) -> None:
        (tmp / urdf_name).write_text(text, encoding="utf-8")
        for dest, source in copies.items():
            target = tmp / Path(*dest.parts)
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, target)

    _publish(out, fill)
    return ExportedURDF(folder=out, urdf=out / urdf_name, meshes=tuple(sorted(str(d) for d in copies)))


def compile_mjcf(mujoco, urdf: Path, meshes: tuple[str, ...], target: Path, sites: tuple[str, ...] | list[str],
                 label: str, geom_names: dict[str, str] | None = None) -> tuple[str, ...]:
    """Compile the self-contained URDF ``urdf`` (meshes at ``meshes`` beside it) into the MJCF file ``target``.

    Every link stays a body (``fusestatic="false"``), a site named like each frame of
    ``sites`` sits at the origin of its body, joint equalities (``<mimic>``) are made as
    stiff as the time step allows, mesh paths are made relative, and the meshes MuJoCo
    reads are copied beside ``target``. ``geom_names`` names the one collision geom of a
    body (``{body: name}``). Returns the meshes copied (POSIX paths relative to the folder).
    """
    folder = urdf.parent
    dae = any(m.lower().endswith(".dae") for m in meshes)
    extension = (f'<mujoco><compiler fusestatic="false" discardvisual="{"true" if dae else "false"}" '
                 'strippath="false"/></mujoco>')
    text = urdf.read_text(encoding="utf-8")
    head, end, tail = text.rpartition("</robot>")
    compiled = folder / (urdf.stem + ".mujoco.urdf")
    compiled.write_text(f"{head}{extension}\n{end}{tail}", encoding="utf-8")
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
    kept = [m for m in meshes if not (dae and m.lower().endswith(".dae"))]
    for mesh in kept:
        dest = target.parent / Path(*PurePosixPath(mesh).parts)
        if dest.resolve() == (folder / Path(*PurePosixPath(mesh).parts)).resolve():
            continue
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(folder / Path(*PurePosixPath(mesh).parts), dest)
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
