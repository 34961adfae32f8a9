"""Assembling a cell from its URDF: its arms, its collision geometry and its fixtures.

:class:`~pinarms.robots.cell.Cell` calls these steps once when it is built: each arm as a
:class:`~.components.CellArm` (:func:`build_arm`), the coal collision model with every mesh
path checked (:func:`build_geometry`), the fixtures' shapes (:func:`read_fixtures`), and,
once the pairs are classified, one distance and one contact test of every checked pair
(:func:`probe_pairs`), so that a pair coal cannot measure is a named error at load time.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Mapping

import coal
import numpy as np
import pinocchio as pin

from pinarms.robots.collision_requests import cold_start
from pinarms.errors import CellError, CollisionGeometryError
from pinarms.robots.robot import Robot
from pinarms.robots.xacro_expand import mesh_path
from pinarms.robots.cell.components import CellArm, Fixture, Shape
from pinarms.robots.cell.description import ArmSpec, arm_urdf

__all__ = ["build_arm", "build_geometry", "package_dirs", "plain_pin_index", "probe_pairs", "read_fixtures"]


def package_dirs(base_dir: Path, packages: Mapping[str, str | Path]) -> list[str]:
    """Where the cell's ``package://`` meshes are looked for: its folder, the built-in package, the given packages."""
    from pinarms.robots.xacro_expand import BUILTIN_PACKAGE

    return [str(base_dir.resolve()), str(BUILTIN_PACKAGE[1]), *(str(Path(v)) for v in packages.values())]


def build_arm(model: pin.Model, cell_robot: Robot, root: ET.Element, spec: ArmSpec, *, source: str, cell_name: str,
              dirs: list[str]) -> CellArm:
    """The arm ``spec`` of the cell: its own :class:`Robot`, its base pose in the world and its joint block.

    Raises:
        CellError: the arm's joints are not one block of the cell joint vector.
    """
    from pinarms.robots.registry import from_urdf_text, match_builtin

    text = arm_urdf(root, spec)
    # closed-form IK by geometry (robot.ik_family); the built-in it is by kinematics, not names
    robot = from_urdf_text(text, tcp=None, name=spec.name, source=f"arm {spec.name!r} of {source}",
                           package_dirs=tuple(dirs))
    model_name = match_builtin(robot)
    robot.description = f"{model_name or 'arm'} {spec.name!r} of cell {cell_name}"
    cell_names = cell_robot.joint_names
    idx = [cell_names.index(spec.prefix + j) if spec.prefix + j in cell_names else -1 for j in robot.joint_names]
    if -1 in idx or idx != list(range(idx[0], idx[0] + len(idx))):
        raise CellError(
            f"{source}: the joints of arm {spec.name!r} are not one block of the cell's joint vector "
            f"(cell joints {list(cell_names)}); an arm must be one subtree below its base"
        )
    base_id = model.getFrameId(spec.base_link)
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    base_to_world = data.oMf[base_id].homogeneous.copy()
    return CellArm(
        name=spec.name,
        robot=robot,
        base_to_world=base_to_world,
        q_slice=slice(idx[0], idx[0] + len(idx)),
        prefix=spec.prefix,
        model=model_name,
    )


def plain_pin_index(model: pin.Model, nq: int) -> np.ndarray | None:
    """Where each cell coordinate sits in Pinocchio's q, when every joint stores one value (else ``None``)."""
    index = np.full(nq, -1, dtype=int)
    for i in range(1, model.njoints):
        joint = model.joints[i]
        if "Mimic" in joint.shortname():
            continue
        if joint.nq != 1:
            return None  # a continuous joint (cos, sin): use Robot.q_to_pinocchio
        index[joint.idx_v] = joint.idx_q
    return None if (index < 0).any() else index


def _resolved_urdf(root: ET.Element, base_dir: Path, packages: Mapping[str, str | Path]) -> str:
    """The URDF with every mesh filename replaced by its checked absolute path (for Pinocchio)."""
    resolved = ET.fromstring(ET.tostring(root))
    from pinarms.robots.cell.limits import check_mesh_size

    for mesh in resolved.iter("mesh"):
        path = mesh_path(mesh.get("filename", ""), base_dir, packages)
        check_mesh_size(path)  # by stat: a huge mesh is refused unread
        mesh.set("filename", str(path))
    return ET.tostring(resolved, encoding="unicode")


def build_geometry(model: pin.Model, root: ET.Element, *, source: str, base_dir: Path,
                   packages: Mapping[str, str | Path]) -> pin.GeometryModel:
    """The cell's collision model (coal geometry of every ``<collision>``), meshes checked before they are read.

    Raises:
        CollisionGeometryError: Pinocchio cannot load it, or a link's collision geometry did
            not load (an unsupported or empty ``<geometry>``).
    """
    text = _resolved_urdf(root, base_dir, packages)
    try:
        gm = pin.buildGeomFromUrdfString(model, text, pin.COLLISION, package_dirs=package_dirs(base_dir, packages))
    except Exception as exc:
        raise CollisionGeometryError(f"cannot load the collision geometry of {source}: {exc}") from exc
    expected: dict[str, int] = {}
    for link in root.findall("link"):
        n = len(link.findall("collision"))
        if n:
            expected[link.get("name")] = n
    got: dict[str, int] = {}
    for g in gm.geometryObjects:
        link = model.frames[g.parentFrame].name
        got[link] = got.get(link, 0) + 1
    missing = sorted(link for link, n in expected.items() if got.get(link, 0) < n)
    if missing:
        raise CollisionGeometryError(
            f"{source}: the collision geometry of link(s) {', '.join(missing)} did not load "
            "(an unsupported or empty <geometry>?); every <collision> must give a box, cylinder, sphere, "
            "capsule or mesh"
        )
    return gm


def _shape_of(geometry: Any) -> tuple[str, tuple[float, ...]]:
    """A coal geometry's kind and size as :class:`Shape` gives them (a mesh's size is its scale, set by the caller)."""
    if isinstance(geometry, coal.Box):
        return "box", tuple(float(v) for v in 2.0 * np.asarray(geometry.halfSide))
    if isinstance(geometry, coal.Cylinder):
        return "cylinder", (float(geometry.radius), float(2.0 * geometry.halfLength))
    if isinstance(geometry, coal.Capsule):
        return "capsule", (float(geometry.radius), float(2.0 * geometry.halfLength))
    if isinstance(geometry, coal.Sphere):
        return "sphere", (float(geometry.radius),)
    if isinstance(geometry, (coal.BVHModelBase, coal.ConvexBase)):
        return "mesh", ()
    return type(geometry).__name__, ()


def read_fixtures(model: pin.Model, collision_model: pin.GeometryModel, fixture_links: Any,
                  urdf_text: str) -> tuple[Fixture, ...]:
    """The fixtures (links ``fixture_links``, in that order) with their shapes at the neutral configuration."""
    data = model.createData()
    gd = cold_start(pin.GeometryData(collision_model))
    pin.updateGeometryPlacements(model, data, collision_model, gd, pin.neutral(model))
    by_link: dict[str, list[Shape]] = {name: [] for name in fixture_links}
    for k, g in enumerate(collision_model.geometryObjects):
        link = model.frames[g.parentFrame].name
        if link not in by_link:
            continue
        kind, size = _shape_of(g.geometry)
        mesh = None
        if kind == "mesh":
            size = tuple(float(v) for v in np.asarray(g.meshScale))
            mesh = _mesh_name(urdf_text, link)
        by_link[link].append(Shape(kind, size, gd.oMg[k].homogeneous.copy(), mesh, g.name))
    return tuple(Fixture(name, tuple(shapes)) for name, shapes in by_link.items())


def _mesh_name(urdf_text: str, link: str) -> str | None:
    """The mesh file the URDF names for ``link``'s collision geometry (as written), or ``None``."""
    root = ET.fromstring(urdf_text)
    for el in root.findall("link"):
        if el.get("name") == link:
            mesh = el.find("collision/geometry/mesh")
            return None if mesh is None else mesh.get("filename")
    return None


def probe_pairs(model: pin.Model, views: Any, pairs: tuple, source: str) -> None:
    """One distance and one contact test of every checked pair at the neutral configuration.

    ``views`` is the cell's :class:`~.views.PairViews` (its first ``len(pairs)`` candidates).

    Raises:
        CollisionGeometryError: coal cannot check a pair, or its distance is not finite.
    """
    n = len(pairs)
    gm, gd = views.geometry(n), views.distance_data(n)
    pin.updateGeometryPlacements(model, views.data(), gm, gd, pin.neutral(model))
    for k, p in enumerate(pairs):
        try:
            d = pin.computeDistance(gm, gd, k).min_distance
            pin.computeCollision(gm, gd, k)
        except Exception as exc:
            raise CollisionGeometryError(
                f"{source}: the pair ({p.body_a}, {p.body_b}) cannot be checked by coal: {exc}"
            ) from exc
        if not np.isfinite(d):
            raise CollisionGeometryError(
                f"{source}: the distance between {p.body_a} and {p.body_b} is {d}: check their geometry"
            )
