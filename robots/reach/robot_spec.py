"""How a reach task names its robot, so that a worker process can rebuild it: :class:`RobotSpec`.

A spec is small and picklable: the registry name when the robot is the registry's (same URDF
by SHA-256, same tool frame, same closed-form family), else the URDF text itself.
:func:`robot_of` rebuilds the robot once per process and checks its URDF against the SHA-256.
Used by the chunk tasks of :func:`pinarms.robots.reach.reachability.reachability_map` and by the
exact check of :func:`pinarms.robots.reach.inverse_reach.base_placements`.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from pinarms.errors import ModelError

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.robot import Robot

__all__ = ["RobotSpec", "spec_of", "robot_of", "spec_key", "urdf_sha256"]


@dataclass(frozen=True)
class RobotSpec:
    """What a worker needs to rebuild the robot: a registry name, or the URDF text (picklable, small)."""

    name: str
    sha256: str
    tcp_frame: str
    registry: bool
    urdf_text: str | None
    package_dirs: tuple[str, ...]
    family: str | None


_ROBOT_CACHE: dict[tuple, Any] = {}


def urdf_sha256(robot: "Robot") -> str:
    """SHA-256 (hex) of the robot's URDF text."""
    return hashlib.sha256(robot.urdf_text.encode("utf-8")).hexdigest()


def _family(robot: "Robot") -> str | None:
    solver = getattr(robot, "analytic_ik", None)
    if solver is None:
        return None
    from pinarms.robots.ik import FAMILIES

    for key, cls in FAMILIES.items():
        if type(solver) is cls:
            return key
    raise ModelError(f"robot '{robot.name}' has a closed-form solver of an unknown family ({type(solver).__name__})")


def spec_of(robot: "Robot") -> RobotSpec:
    """The spec of ``robot`` (the robot itself is cached for this process under the spec's key)."""
    from pinarms.robots import registry

    sha = urdf_sha256(robot)
    family = _family(robot)
    is_registry = False
    if robot.name in registry.names():
        try:
            ref = registry.load(robot.name)
            is_registry = urdf_sha256(ref) == sha and ref.tcp_frame == robot.tcp_frame and _family(ref) == family
        except Exception:  # a registry robot that cannot load here: ship the URDF text instead
            is_registry = False
    spec = RobotSpec(
        name=robot.name,
        sha256=sha,
        tcp_frame=robot.tcp_frame,
        registry=is_registry,
        urdf_text=None if is_registry else robot.urdf_text,
        package_dirs=tuple(str(p) for p in robot.package_dirs),
        family=family,
    )
    _ROBOT_CACHE.setdefault(spec_key(spec), robot)
    return spec


def spec_key(spec: RobotSpec) -> tuple:
    """The key of a spec's robot in per-process caches: ``(sha256, tcp_frame, family)``."""
    return (spec.sha256, spec.tcp_frame, spec.family)


def robot_of(spec: RobotSpec) -> "Robot":
    """The robot of ``spec``, built once per process."""
    key = spec_key(spec)
    robot = _ROBOT_CACHE.get(key)
    if robot is None:
        from pinarms.robots import registry
        from pinarms.robots.ik import attach_analytic_ik

        if spec.registry:
            robot = registry.load(spec.name)
        else:
            robot = registry.from_urdf_text(spec.urdf_text, tcp=spec.tcp_frame, name=spec.name,
                                            package_dirs=spec.package_dirs)
            attach_analytic_ik(robot, spec.family) if spec.family else None
        if urdf_sha256(robot) != spec.sha256:
            raise ModelError(
                f"robot '{spec.name}' loads here with another URDF (SHA-256 {urdf_sha256(robot)[:12]}… instead of "
                f"{spec.sha256[:12]}…): the worker runs another pinarms version"
            )
        _ROBOT_CACHE[key] = robot
    return robot
