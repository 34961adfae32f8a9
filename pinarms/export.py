"""URDF export for other tools: one self-contained folder per robot.

``export_urdf(robot_or_name, out_dir)`` writes

    out_dir/
        <name>.urdf          the robot's URDF, mesh paths made relative to this file
        meshes/<package>/... every mesh it references (and the images a COLLADA mesh uses)

so that PyBullet, MuJoCo, yourdfpy, MATLAB ``importrobot`` or ROS load it without pinarms
and without a ROS package path. The URDF text is the one the :class:`robots.Robot` was
built from (joints frozen by the registry stay frozen), edited only in its ``<mesh
filename=...>`` attributes: everything else, ``<mimic>`` included, is kept byte for byte.
(yourdfpy's ``write_xml`` is not used: it drops ``<mimic>``.)

The folder is written into a temporary sibling folder first and renamed into place, so a
failed export never leaves a half-written folder behind.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from pinarms import robots
from pinarms.robots.errors import InvalidInput, ModelError
from pinarms.robots.robot import Robot

__all__ = ["ExportedURDF", "export_urdf", "mesh_references"]


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


def export_urdf(robot_or_name: Robot | str, out_dir: str | os.PathLike, *, overwrite: bool = False) -> ExportedURDF:
    """Write a self-contained URDF folder for ``robot_or_name`` into ``out_dir``.

    Args:
        robot_or_name: a :class:`robots.Robot` or a name :func:`robots.load` accepts.
        out_dir: the folder to create. It must not exist or be empty, unless ``overwrite``.
        overwrite: replace an existing non-empty folder (the old one is removed only
            after the new one is complete).

    Returns:
        :class:`ExportedURDF` with the folder, the URDF path and the copied mesh files.

    Raises:
        RobotNotFound: unknown robot name.
        InvalidInput: ``out_dir`` exists and is not empty (and ``overwrite`` is false),
            or is a file.
        ModelError: a referenced mesh cannot be found.
    """
    robot = robots.load(robot_or_name) if isinstance(robot_or_name, str) else robot_or_name
    if not isinstance(robot, Robot):
        raise InvalidInput(f"export_urdf takes a robots.Robot or a robot name, got {robot_or_name!r}")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InvalidInput(f"export folder {str(out)!r} is a file; give a folder path")
    if out.is_dir() and any(out.iterdir()) and not overwrite:
        raise InvalidInput(f"export folder {str(out)!r} is not empty; choose another folder or pass overwrite=True")

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

    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".partial", dir=out.parent))
    try:
        urdf_name = f"{robot.name}.urdf"
        (tmp / urdf_name).write_text(text, encoding="utf-8")
        for dest, source in copies.items():
            target = tmp / Path(*dest.parts)
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, target)
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
    return ExportedURDF(folder=out, urdf=out / urdf_name, meshes=tuple(sorted(str(d) for d in copies)))
