"""A robot in a session: stored by its registry name or with its URDF embedded, rebuilt on load.

A robot that ``robots.load(name)`` rebuilds exactly is stored by name; any other has its
URDF text embedded (with the folders its meshes came from, recorded for messages only) so
that the session reopens anywhere. A payload is stored beside it and reapplied. Rebuilding an
embedded URDF reads meshes only from the folders the caller allowed
(:func:`pinarms.viz.mesh_paths.check_mesh_paths`), pinarms' own model folders among them.
"""

from __future__ import annotations

from pathlib import Path

from numpy.typing import ArrayLike

from pinarms import robots
from pinarms.errors import PinarmsError
from pinarms.robots.robot import Robot

from pinarms.viz.errors import SessionFormatError
from pinarms.viz.mesh_paths import check_mesh_paths
from pinarms.viz.session_inputs import pose_array
from pinarms.viz.session_records import RobotEntry

__all__ = ["robot_entry", "rebuild_robot", "shipped_model_dirs"]


def _registry_name(robot: Robot) -> str | None:
    """``robot.name`` when ``robots.load(robot.name)`` rebuilds exactly this robot, else ``None``."""
    if robot.name not in robots.names():
        return None
    try:
        ref = robots.load(robot.name)
    except PinarmsError:
        return None
    if ref.urdf_text == robot.urdf_text and ref.tcp_frame == robot.tcp_frame:
        return robot.name  # a payload is stored beside the name (RobotEntry.payload)
    return None


def robot_entry(robot: Robot, key: str, base_to_world: ArrayLike) -> RobotEntry:
    """The session's record of ``robot`` under ``key``, placed at ``base_to_world`` (4, 4) in the world."""
    reg = _registry_name(robot)
    return RobotEntry(
        key=key,
        source="registry" if reg else "urdf",
        name=robot.name,
        tcp_frame=robot.tcp_frame,
        joint_names=tuple(robot.joint_names),
        base_to_world=pose_array(base_to_world, f"base_to_world of robot {key!r}"),
        urdf_text=None if reg else robot.urdf_text,
        package_dirs=() if reg else tuple(str(p) for p in robot.package_dirs),
        payload=None if robot.payload is None else robot.payload.as_dict(),
    )


def rebuild_robot(entry: RobotEntry, mesh_dirs: tuple[str, ...]) -> Robot:
    """The :class:`pinarms.robots.Robot` of ``entry``, its meshes read only from ``mesh_dirs``, its payload reapplied.

    Raises:
        SessionFormatError: a mesh outside ``mesh_dirs``, or the robot now loads with other joints.
    """
    if entry.source == "registry":
        rob = robots.load(entry.name)
    else:
        # an embedded URDF comes from a file: its meshes must stay inside the folders the caller
        # allowed; the folders the file names (entry.package_dirs) only appear in the message
        dirs = check_mesh_paths(entry.urdf_text, mesh_dirs, f"session robot {entry.key!r}",
                                recorded=entry.package_dirs)
        rob = robots.from_urdf_text(
            entry.urdf_text, tcp=entry.tcp_frame, name=entry.name, source=f"session robot {entry.key!r}",
            package_dirs=tuple(dirs),
        )
    if entry.payload is not None:
        rob = rob.with_payload(entry.payload)
    if tuple(rob.joint_names) != entry.joint_names:
        raise SessionFormatError(
            f"robot {entry.key!r} ({entry.name}) was saved with joints {list(entry.joint_names)} but now loads "
            f"with {list(rob.joint_names)}; the registry's model changed since the session was saved"
        )
    return rob


def shipped_model_dirs() -> tuple[str, ...]:
    """pinarms' own model folders (built-in URDFs and cells with their meshes, the xacro macros): always allowed."""
    import pinarms.urdf

    return (str(Path(pinarms.urdf.__file__).resolve().parent), str(Path(robots.__file__).resolve().parent / "xacro"))
