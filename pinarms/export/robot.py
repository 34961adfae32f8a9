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
from typing import Callable

from pinarms import robots
from pinarms.robots.errors import InvalidInput, ModelError
from pinarms.robots.robot import Robot

__all__ = ["ExportedURDF", "ExportedMJCF", "export_urdf", "export_mjcf", "mesh_references"]


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


def export_urdf(robot_or_name: Robot | str, out_dir: str | os.PathLike, *, overwrite: bool = False,
                srdf: bool = False, states: dict | None = None) -> ExportedURDF:
    """Write a self-contained URDF folder for ``robot_or_name`` into ``out_dir``.

    Args:
        robot_or_name: a :class:`robots.Robot` or a name :func:`robots.load` accepts.
        out_dir: the folder to create. It must not exist or be empty, unless ``overwrite``.
        overwrite: replace an existing non-empty folder (the old one is removed only
            after the new one is complete).
        srdf: also write ``<name>.srdf`` (:mod:`pinarms.export.srdf`: the arm's group,
            end effector, ``home`` and ``states``, disable_collisions from pinarms' pair
            classification). The URDF then gives every collision element its own link
            (:func:`pinarms.export.cell.one_collision_per_link`) instead of being kept byte
            for byte, so that the SRDF can name every pair.
        states: with ``srdf``, extra named states ``{name: q (nq,)}`` [rad or m].

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
    if srdf:
        from .cell import export_robot_with_srdf

        done = export_robot_with_srdf(robot, out_dir, overwrite=overwrite, states=states)
        return ExportedURDF(folder=done.folder, urdf=done.urdf, meshes=done.meshes, srdf=done.srdf)
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


# --------------------------------------------------------------------------- MuJoCo
@dataclass(frozen=True)
class ExportedMJCF:
    """What :func:`export_mjcf` wrote.

    Attributes:
        folder: the export folder.
        mjcf: the MJCF file inside it (``<name>.xml``).
        sites: the frames that carry a MuJoCo ``site`` of the same name (flange, tcp, ...).
        meshes: the copied mesh files, relative to ``folder`` (POSIX paths), sorted.
    """

    folder: Path
    mjcf: Path
    sites: tuple[str, ...]
    meshes: tuple[str, ...]


#: Radius of the exported sites [m] (they are markers: no mass, no collision).
SITE_SIZE_M = 0.01


def export_mjcf(robot_or_name: Robot | str, out_dir: str | os.PathLike, *, sites: tuple[str, ...] | None = None,
                overwrite: bool = False) -> ExportedMJCF:
    """Write ``robot_or_name`` as a MuJoCo model (MJCF) that keeps the tool point, into ``out_dir``.

    MuJoCo reads URDF itself, and turns ``<mimic>`` into joint equality constraints, but by
    default it fuses every link attached by a fixed joint into its parent: the massless
    ``flange`` and ``tcp`` links, and with them the tool point, are lost. This export
    compiles the URDF with MuJoCo's documented URDF extension
    ``<mujoco><compiler fusestatic="false"/></mujoco>`` (every link stays a body), saves
    the compiled model as MJCF, and puts a ``site`` named like the frame at the origin of
    the bodies in ``sites`` (default: ``flange`` and the robot's tcp frame, where they
    exist), so ``data.site("tcp").xpos`` is the tcp position in MuJoCo. The mimic equality
    constraints are made as stiff as MuJoCo allows (``solref`` time constant twice the time
    step, ``solimp`` 0.99–0.999): a parallelogram is a rigid linkage, and MuJoCo's default
    soft constraint lets the koji arm's linkage sag by 0.8° under its own weight.

    COLLADA (``.dae``) meshes, which MuJoCo cannot read, are left out of the visual geometry
    (``discardvisual``); the collision meshes stay. Needs the ``mujoco`` package
    (``pip install mujoco``, or pinarms' ``mujoco`` extra).

    Raises:
        InvalidInput: ``out_dir`` is a file, or not empty (without ``overwrite``); a frame
            of ``sites`` is not a link of the robot.
        ModelError: ``mujoco`` is not installed, or MuJoCo refuses the model.
    """
    try:
        import mujoco
    except ImportError as exc:
        raise ModelError("export_mjcf needs MuJoCo's Python package: pip install mujoco "
                         "(or pip install 'pinarms[mujoco]')") from exc
    robot = robots.load(robot_or_name) if isinstance(robot_or_name, str) else robot_or_name
    if not isinstance(robot, Robot):
        raise InvalidInput(f"export_mjcf takes a robots.Robot or a robot name, got {robot_or_name!r}")
    out = _check_folder(out_dir, overwrite)
    links = {link.get("name") for link in ET.fromstring(robot.urdf_text).iter("link")}
    if sites is None:
        sites = tuple(dict.fromkeys(f for f in ("flange", robot.tcp_frame) if f in links))
    for frame in sites:
        if frame not in links:
            raise InvalidInput(f"site {frame!r} is not a link of robot '{robot.name}'; links: {', '.join(sorted(links))}")
    name = f"{robot.name}.xml"
    written: dict[str, tuple[str, ...]] = {}

    def fill(tmp: Path) -> None:
        staged = export_urdf(robot, tmp / "urdf")
        written["meshes"] = compile_mjcf(mujoco, staged.urdf, staged.meshes, tmp / name, sites, f"robot '{robot.name}'")
        shutil.rmtree(staged.folder)

    _publish(out, fill)
    return ExportedMJCF(folder=out, mjcf=out / name, sites=tuple(sites), meshes=written["meshes"])



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
