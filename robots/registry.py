"""Robots by name: the built-in arms of the four papers and example-robot-data's arms.

``load(name)`` is the one entry point, like ``robot_descriptions``; ``names()`` lists
what it accepts; ``from_urdf(path)`` loads any other URDF.
"""

from __future__ import annotations

import difflib
import importlib.metadata
import importlib.resources
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import pinocchio as pin

from pinarms.files import read_bounded_text

from pinarms.errors import InvalidInput, ModelError, RobotNotFound
from pinarms.robots.robot import Robot
# the URDF checks, under the names robots/cell/compose.py imports from here
from pinarms.robots._checks import check_path_name
from pinarms.robots.urdf_checks import check_inertials as _check_inertials
from pinarms.robots.urdf_checks import check_limits as _check_limits
from pinarms.robots.urdf_checks import check_tree as _check_tree
from pinarms.robots.urdf_checks import refuse_dtd as _refuse_dtd

__all__ = ["load", "names", "from_urdf", "from_urdf_text", "from_xacro", "builtin_names", "RobotInfo", "info", "suggest",
           "match_builtin", "MAX_URDF_BYTES", "example_robot_data_share"]

#: Largest URDF file :func:`from_urdf` reads [bytes] (as much as a xacro expansion may produce).
MAX_URDF_BYTES = 64 * 2**20


@dataclass(frozen=True)
class RobotInfo:
    """What the registry knows about a robot name."""

    name: str
    source: str  # "pinarms" (built-in, generated from robots/xacro) or "example-robot-data"
    description: str
    urdf_relpath: str  # inside urdf/ (built-in) or example-robot-data's robots/ folder
    tcp: str = "tcp"
    frozen_joints: tuple[str, ...] = ()  # joints fixed at zero (grippers of example robots)
    #: contacts by design of a URDF that is not ours, ``(link1, link2, reason)``: added to it as
    #: ``<disable_collisions>`` elements (a built-in arm declares its own in its xacro)
    declared: tuple[tuple[str, str, str], ...] = ()


_BUILTIN = {
    info.name: info
    for info in (
        RobotInfo("scara_mushroom", "pinarms", "4-axis SCARA of an enoki-mushroom packing line (seed 000)", "scara_mushroom.urdf"),
        RobotInfo("aubo_i3", "pinarms", "AUBO-i3 6-axis collaborative arm handling food (seed 001)", "aubo_i3.urdf"),
        RobotInfo("gantry_flower", "pinarms", "3-axis Cartesian gantry packing flowers (seed 002)", "gantry_flower.urdf"),
        RobotInfo("koji_turner", "pinarms", "suspended koji-block turning arm with a parallelogram (seed 004)", "koji_turner.urdf"),
        RobotInfo("koji_turner_rail", "pinarms", "koji turning arm on its two overhead-rail slides (seed 004)", "koji_turner_rail.urdf"),
    )
}

#: Why the Panda's wrist meshes are declared in contact (example-robot-data's URDF, not ours): seeded samples put
#: link 5's mesh into link 7's in 90 % of the configurations with joint 6 within 0.12 rad of its lower limit
#: (the neutral configuration among them), 20-30 % up to 0.4 rad, 1-2 % beyond; Drake's Panda model filters
#: the link5-link7 pair too (RobotLocomotion/drake, manipulation/models/franka_description/README.md).
_PANDA_WRIST = ("the convex collision meshes of link 5 and the wrist overlap near joint 6's lower limit "
                "(Drake's Panda model filters link5-link7 too)")

_EXAMPLE = {
    info.name: info
    for info in (
        RobotInfo("ur3", "example-robot-data", "Universal Robots UR3", "ur_description/urdf/ur3_robot.urdf", tcp="tool0"),
        RobotInfo("ur5", "example-robot-data", "Universal Robots UR5", "ur_description/urdf/ur5_robot.urdf", tcp="tool0"),
        RobotInfo("ur10", "example-robot-data", "Universal Robots UR10", "ur_description/urdf/ur10_robot.urdf", tcp="tool0"),
        RobotInfo(
            "panda",
            "example-robot-data",
            "Franka Emika Panda, 7 DoF (fingers fixed)",
            "panda_description/urdf/panda.urdf",
            tcp="panda_hand_tcp",
            frozen_joints=("panda_finger_joint1", "panda_finger_joint2"),
            declared=tuple((link, "panda_link5", _PANDA_WRIST) for link in ("panda_link7", "panda_hand")),
        ),
    )
}


def builtin_names() -> list[str]:
    """Names of the arms defined by pinarms itself."""
    return list(_BUILTIN)


def names() -> list[str]:
    """Every name :func:`load` accepts."""
    return list(_BUILTIN) + list(_EXAMPLE)


def info(name: str) -> RobotInfo:
    """Registry entry of ``name``; raises :class:`RobotNotFound` listing the known names."""
    if name in _BUILTIN:
        return _BUILTIN[name]
    if name in _EXAMPLE:
        return _EXAMPLE[name]
    close = suggest(name)
    hint = f"did you mean {' or '.join(close)}? " if close else ""
    raise RobotNotFound(f"unknown robot {name!r}; {hint}known robots: {', '.join(names())} "
                        "(or use robots.from_urdf(path))")


def suggest(name: str, limit: int = 3) -> list[str]:
    """Known robot names close to ``name`` (a typo, another case, ``-`` for ``_``), closest first.

    Names are compared lowered, with ``-`` and spaces read as ``_``: an exact match after
    that comes alone; then the names that contain ``name`` (3 characters or more, e.g.
    ``koji``), in registry order; then :func:`difflib.get_close_matches` (similarity ratio
    ≥ 0.6), at most ``limit`` in all.
    """
    def norm(text: str) -> str:
        return text.lower().replace("-", "_").replace(" ", "_")

    known = names()
    by_norm = {norm(k): k for k in known}
    key = norm(name)
    if key in by_norm:
        return [by_norm[key]]
    found = [k for k in by_norm if len(key) >= 3 and key in k]
    found += [k for k in difflib.get_close_matches(key, list(by_norm), n=limit, cutoff=0.6) if k not in found]
    return [by_norm[k] for k in found[:limit]]


@lru_cache(maxsize=1)
def example_robot_data_share() -> Path:
    """The installed ``share/example-robot-data`` folder (example-robot-data ships no Python loader)."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError as exc:  # pragma: no cover - a dependency
        raise RobotNotFound("example-robot-data is not installed: pip install example-robot-data") from exc
    for f in dist.files or ():
        parts = Path(str(f)).parts
        if "example-robot-data" in parts and "robots" in parts:
            full = Path(dist.locate_file(f))
            idx = full.parts.index("example-robot-data")
            return Path(*full.parts[: idx + 1])
    raise RobotNotFound("example-robot-data is installed but ships no robots/ folder")


def builtin_urdf_path(name: str) -> Path:
    """Path of the committed URDF of built-in arm ``name``."""
    entry = info(name)
    if entry.source != "pinarms":
        raise RobotNotFound(f"{name!r} is not a built-in pinarms arm; built-ins: {', '.join(_BUILTIN)}")
    return Path(str(importlib.resources.files("pinarms.urdf") / entry.urdf_relpath))


def load(name: str) -> Robot:
    """Load a robot by name (see :func:`names`).

    Raises:
        RobotNotFound: the name is unknown (the message lists the known names).
    """
    if not isinstance(name, str):
        raise InvalidInput(f"robot name must be a string, got {name!r}")
    entry = info(name)
    if entry.source == "pinarms":
        path = builtin_urdf_path(name)
        if not path.exists():
            raise ModelError(f"the URDF of {name!r} is missing ({path.name}); regenerate it with `pinarms urdf build`")
        robot = from_urdf(path, tcp=entry.tcp, name=name, description=entry.description)
    else:
        share = example_robot_data_share()
        path = share / "robots" / entry.urdf_relpath
        robot = from_urdf(
            path,
            tcp=entry.tcp,
            name=name,
            package_dirs=(str(share.parent),),
            freeze=entry.frozen_joints,
            description=entry.description,
            declare=entry.declared,
        )
    return robot  # its closed-form IK (if any) was recognised by from_urdf_text


def _kinematics(robot: Robot) -> tuple[tuple[int, ...], np.ndarray]:
    """What makes an arm the arm it is, without its names: the tree, joint kinds, axes,
    placements, mimic couplings, position limits and the tcp's placement.

    Returns ``(integers, floats)``: parents, kinds and coordinate indices; then every
    joint's placement and axis, mimic multiplier and offset, the limits and the tcp.
    """
    tree, model = robot.kinematic_tree, robot.model
    n = model.njoints
    ints = (n, *tree.parent.tolist(), *tree.kind.tolist(), *tree.q_index.tolist())
    place = [np.asarray(model.jointPlacements[i].homogeneous[:3]).ravel() for i in range(1, n)]
    tcp = model.frames[robot.frame_id("tcp")]
    floats = np.concatenate([
        *place, np.asarray(tree.axis_rot)[1:, :, 2].ravel(), tree.scale, tree.offset, robot.lower, robot.upper,
        np.asarray(tcp.placement.homogeneous[:3]).ravel(),
    ])
    return (*ints, int(tcp.parentJoint)), floats


@lru_cache(maxsize=1)
def _builtin_kinematics() -> tuple[tuple[str, tuple[int, ...], np.ndarray], ...]:
    return tuple((name, *_kinematics(load(name))) for name in builtin_names())


def match_builtin(robot: Robot, tol: float = 1e-9) -> str | None:
    """The built-in arm that ``robot`` is, told from its kinematics, or ``None``.

    Names play no part: two arms are the same when their trees, joint kinds, joint
    placements and axes, mimic couplings, position limits and tcp placement agree within
    ``tol`` [m, rad, 1]. A cell arm placed by a built-in macro (``<xacro:scara_mushroom
    prefix="left_" .../>``) is that built-in; a user's arm with other lengths or limits
    (whatever its joints are called) is not.
    """
    ints, floats = _kinematics(robot)
    for name, ref_ints, ref_floats in _builtin_kinematics():
        if ref_ints == ints and ref_floats.shape == floats.shape and np.allclose(ref_floats, floats, rtol=0.0, atol=tol):
            return name
    return None


def _freeze_joints(root: ET.Element, freeze: tuple[str, ...], source: str) -> None:
    """Turn the named joints into fixed joints at their zero position (mimics of them too)."""
    joints = {j.get("name"): j for j in root.iter("joint")}
    for jname in freeze:
        if jname not in joints:
            raise ModelError(f"{source}: cannot freeze joint {jname!r}: no such joint")
    for j in root.iter("joint"):
        mimic = j.find("mimic")
        if j.get("name") in freeze or (mimic is not None and mimic.get("joint") in freeze):
            if mimic is not None and float(mimic.get("offset", 0.0)) != 0.0:
                raise ModelError(f"{source}: cannot freeze mimic joint {j.get('name')!r} with a non-zero offset")
            j.set("type", "fixed")
            for child in list(j):
                if child.tag in ("mimic", "limit", "axis", "dynamics", "safety_controller"):
                    j.remove(child)


def from_urdf_text(
    urdf_text: str,
    *,
    tcp: str | None = None,
    name: str | None = None,
    source: str = "<string>",
    urdf_path: Path | None = None,
    package_dirs: tuple[str, ...] = (),
    freeze: tuple[str, ...] = (),
    description: str = "",
    declare: tuple[tuple[str, str, str], ...] = (),
) -> Robot:
    """Build a :class:`Robot` from URDF text (see :func:`from_urdf`).

    Its closed-form IK, when its kinematic structure matches a family, is attached
    (:func:`pinarms.robots.ik.recognise`; ``robot.ik_family``).

    Raises:
        InvalidInput: ``urdf_text`` is not a string.
        ModelError: not well-formed XML, not a URDF, a DOCTYPE or entity declaration
            (URDF has none; Pinocchio's parser would not expand them), joint limits with
            lower > upper or negative speed/effort, or Pinocchio rejects the model.
    """
    if not isinstance(urdf_text, str):
        raise InvalidInput(f"urdf_text must be the URDF as a string, got {type(urdf_text).__name__}")
    _refuse_dtd(urdf_text, source)
    try:
        root = ET.fromstring(urdf_text)
    except ET.ParseError as exc:
        raise ModelError(f"{source} is not well-formed XML: {exc}") from exc
    if root.tag != "robot":
        raise ModelError(f"{source} is not a URDF: its root element is <{root.tag}>, expected <robot>")
    if not root.findall("link"):
        raise ModelError(f"{source} defines no <link>")
    _check_tree(root, source)
    _check_inertials(root, source)
    if freeze:
        _freeze_joints(root, tuple(freeze), source)
    for link1, link2, reason in declare:  # read back by robots.SelfCollision
        ET.SubElement(root, "disable_collisions", {"link1": link1, "link2": link2, "reason": reason})
    if freeze or declare:
        urdf_text = ET.tostring(root, encoding="unicode")
    try:
        model = pin.buildModelFromXML(urdf_text, mimic=True)
    except Exception as exc:  # pinocchio raises RuntimeError/ValueError with its own message
        raise ModelError(f"Pinocchio cannot build a model from {source}: {exc}") from exc
    if model.nv == 0:
        raise ModelError(f"{source} has no movable joint")
    _check_limits(model, source)
    if tcp is None:
        tcp = "tcp" if model.existFrame("tcp") else _last_body_frame(model)
    robot = Robot(
        model,
        name=name or root.get("name", "robot"),
        urdf_text=urdf_text,
        urdf_path=urdf_path,
        package_dirs=package_dirs,
        tcp_frame=tcp,
        description=description,
    )
    from pinarms.robots.ik import attach_analytic_ik  # late import: ik solvers need the Robot class

    attach_analytic_ik(robot)  # by geometry, proven by FK round trips (robot.ik_family)
    return robot


def from_urdf(
    path: str | Path,
    tcp: str | None = None,
    *,
    name: str | None = None,
    package_dirs: tuple[str, ...] = (),
    freeze: tuple[str, ...] = (),
    description: str = "",
    declare: tuple[tuple[str, str, str], ...] = (),
) -> Robot:
    """Load any URDF file (closed-form IK attached when its geometry matches a family: ``robot.ik_family``).

    Args:
        path: the URDF file.
        tcp: frame used as ``"tcp"``; default: a frame named ``tcp`` if there is one, else
            the last link of the kinematic tree.
        name: robot name (default: the URDF's ``<robot name>``).
        package_dirs: folders that resolve ``package://`` mesh paths (for the viewer).
        freeze: joints to fix at zero (e.g. gripper fingers).
        declare: pairs of links in contact by design, ``(link1, link2, reason)``, added as
            ``<disable_collisions>`` elements (:class:`~pinarms.robots.SelfCollision` skips them).

    Raises:
        ModelError: the file is missing, not a regular file, larger than :data:`MAX_URDF_BYTES`,
            not XML, not a URDF, or Pinocchio rejects it.
    """
    check_path_name(path, "URDF file")
    text = read_bounded_text(path, MAX_URDF_BYTES, "URDF file", error=ModelError)
    path = Path(path)
    if not package_dirs:
        package_dirs = (str(path.parent),)
    return from_urdf_text(
        text,
        tcp=tcp,
        name=name,
        source=str(path),
        urdf_path=path,
        package_dirs=tuple(package_dirs),
        freeze=tuple(freeze),
        description=description,
        declare=tuple(declare),
    )


def from_xacro(
    path: str | Path,
    tcp: str | None = None,
    *,
    name: str | None = None,
    packages: dict[str, str | Path] | None = None,
    limits=None,
    xacro_args: dict | None = None,
    **args,
) -> Robot:
    """Load a user's xacro file as a :class:`Robot`, expanded behind a wall.

    The file is expanded by :func:`~pinarms.robots.xacro_expand.expand_xacro`: in a child
    process bounded in time and memory, reading only its own folder and the ``packages``
    it is given (``$(find pinarms)`` is the built-in arms' macros). Mesh files must lie
    in those folders too.

    Args:
        path: the ``.xacro`` file (its ``<robot>`` must describe one arm).
        tcp: frame used as ``"tcp"`` (default: ``tcp`` if present, else the deepest link).
        name: robot name (default: the URDF's ``<robot name>``).
        packages: ``{name: folder}`` for ``$(find name)`` and ``package://name/...``.
        limits: a :class:`~pinarms.robots.xacro_expand.XacroLimits`.
        xacro_args: the file's ``xacro:arg`` values, for names that clash with the
            keywords above; otherwise pass them as keywords (``height=0.8``).

    Raises:
        XacroForbidden, XacroLimitExceeded, XacroArgError, XacroError: see
            :func:`~pinarms.robots.xacro_expand.expand_xacro`.
        MissingMesh: a mesh file named by the URDF does not exist.
        ModelError: Pinocchio cannot build a model of the result.
    """
    from pinarms.robots.xacro_expand import check_mesh_files, expand_xacro

    check_path_name(path, "xacro file")
    path = Path(path)
    all_args = {**(xacro_args or {}), **args}
    result = expand_xacro(path, all_args, packages=packages, limits=limits)
    pkgs = check_mesh_files(result.urdf_text, path, packages)
    return from_urdf_text(
        result.urdf_text,
        tcp=tcp,
        name=name,
        source=str(path),
        package_dirs=tuple(dict.fromkeys([str(path.resolve().parent), *pkgs])),
    )


def _last_body_frame(model: pin.Model) -> str:
    """The body frame deepest in the tree (most ancestors), last defined on ties."""
    best, best_depth = None, -1
    for f in model.frames:
        if f.type != pin.FrameType.BODY:
            continue
        depth, j = 0, f.parentJoint
        while j > 0:
            depth += 1
            j = model.parents[j]
        if depth >= best_depth:
            best, best_depth = f.name, depth
    return best
