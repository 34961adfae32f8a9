"""URDF export for other tools: one self-contained folder per robot.

``export_urdf(robot_or_name, out_dir)`` writes

    out_dir/
        <name>.urdf          the robot's URDF, mesh paths made relative to this file
        meshes/<package>/... every mesh it references (and the images a COLLADA mesh uses)

so that PyBullet, MuJoCo, yourdfpy, MATLAB ``importrobot`` or ROS load it without pinarms
and without a ROS package path. The URDF text is the one the :class:`pinarms.robots.Robot` was
built from (joints frozen by the registry stay frozen), edited only in its ``<mesh
filename=...>`` attributes: everything else, ``<mimic>`` included, is kept byte for byte.
(yourdfpy's ``write_xml`` is not used: it drops ``<mimic>``.)

The folder is written into a temporary sibling folder first and renamed into place, so a
failed export never leaves a half-written folder behind.
"""

from __future__ import annotations

import os
import shutil
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

from pinarms import robots
from pinarms.files import publish_folder, safe_file_name
from pinarms.errors import InvalidInput, ModelError
from pinarms.robots.robot import Robot

from pinarms.export.cell import export_robot_with_srdf
from pinarms.export.urdf_files import check_export_folder, compile_mjcf, write_urdf_folder
from pinarms.export.urdf_files import SITE_SIZE_M, ExportedURDF, mesh_references  # noqa: F401  (public names of this module)

__all__ = ["ExportedURDF", "ExportedMJCF", "export_urdf", "export_mjcf", "mesh_references"]


def export_urdf(robot_or_name: Robot | str, out_dir: str | os.PathLike, *, overwrite: bool = False,
                srdf: bool = False, states: dict | None = None,
                packages: Mapping[str, str | os.PathLike] | None = None) -> ExportedURDF:
    """Write a self-contained URDF folder for ``robot_or_name`` into ``out_dir``.

    Args:
        robot_or_name: a :class:`pinarms.robots.Robot` or a name :func:`pinarms.robots.load` accepts.
        out_dir: the folder to create. It must not exist or be empty, unless ``overwrite``. A
            symbolic link to a folder is written through (the link stays). The folder gets the
            umask's permissions.
        overwrite: replace an existing non-empty folder (the old one is removed only
            after the new one is complete).
        srdf: also write ``<name>.srdf`` (:mod:`pinarms.export.srdf`: the arm's group,
            end effector, ``home`` and ``states``, disable_collisions from pinarms' pair
            classification). The URDF then gives every collision element its own link
            (:func:`pinarms.export.cell.one_collision_per_link`) instead of being kept byte
            for byte, so that the SRDF can name every pair.
        states: with ``srdf``, extra named states ``{name: q (nq,)}`` [rad or m]; ``home``
            is the arm's home (else the all-zero pose where the limits allow it, else no
            home: ``notes`` says so).
        packages: ``{NAME: folder}`` for ``package://NAME/`` meshes. Meshes are copied only
            from the URDF's folder, ``robot.package_dirs`` and these (:mod:`.mesh_sources`).

    The URDF file is named after the robot, made a plain file name
    (:func:`pinarms.files.safe_file_name`: ``<robot name="../x">`` gives ``_x.urdf``).

    Returns:
        :class:`ExportedURDF` with the folder, the URDF path and the copied mesh files.

    Raises:
        RobotNotFound: unknown robot name.
        InvalidInput: ``out_dir`` exists and is not empty (and ``overwrite`` is false),
            or is a file.
        MeshNotFound: a referenced mesh cannot be found.
        MeshNotAllowed: a mesh or texture outside the allowed folders, or not a mesh file.
    """
    robot = robots.load(robot_or_name) if isinstance(robot_or_name, str) else robot_or_name
    if not isinstance(robot, Robot):
        raise InvalidInput(f"export_urdf takes a robots.Robot or a robot name, got {robot_or_name!r}")
    if srdf:
        done = export_robot_with_srdf(robot, out_dir, overwrite=overwrite, states=states, packages=packages)
        return ExportedURDF(folder=done.folder, urdf=done.urdf, meshes=done.meshes, srdf=done.srdf, notes=done.notes)
    return write_urdf_folder(robot, out_dir, overwrite, packages=packages)


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




def export_mjcf(robot_or_name: Robot | str, out_dir: str | os.PathLike, *, sites: tuple[str, ...] | None = None,
                overwrite: bool = False, packages: Mapping[str, str | os.PathLike] | None = None) -> ExportedMJCF:
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
    (``discardvisual``); COLLADA collision meshes are converted to OBJ files beside them
    (:mod:`pinarms.export.mesh_convert`, trimesh with pycollada), ASCII STL meshes to binary
    STL. Needs the ``mujoco``
    package (``pip install 'pinarms[mujoco]'``: mujoco, trimesh, pycollada). The folder, the file name and the
    meshes follow :func:`export_urdf` (``packages`` likewise).

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
    out = check_export_folder(out_dir, overwrite)
    links = {link.get("name") for link in ET.fromstring(robot.urdf_text).iter("link")}
    if sites is None:
        sites = tuple(dict.fromkeys(f for f in ("flange", robot.tcp_frame) if f in links))
    for frame in sites:
        if frame not in links:
            raise InvalidInput(f"site {frame!r} is not a link of robot '{robot.name}'; links: {', '.join(sorted(links))}")
    name = f"{safe_file_name(robot.name, 'robot')}.xml"
    written: dict[str, tuple[str, ...]] = {}

    def fill(tmp: Path) -> None:
        staged = write_urdf_folder(robot, tmp / "urdf", packages=packages)
        written["meshes"] = compile_mjcf(mujoco, staged.urdf, staged.meshes, tmp / name, sites, f"robot '{robot.name}'")
        shutil.rmtree(staged.folder)

    publish_folder(out, fill)
    return ExportedMJCF(folder=out, mjcf=out / name, sites=tuple(sites), meshes=written["meshes"])
