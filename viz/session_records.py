"""The records a session holds, one frozen dataclass per kind (robots, boxes, trajectories,
workspaces, point sets, GA histories), and the rule for their names.

Their file format (JSON fields, arrays, texts per kind; reading and writing) is
:mod:`pinarms.viz.session_format`, which re-exports every name here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pinarms.errors import InvalidInput

from pinarms.viz.names import NAME_RE

__all__ = ["RobotEntry", "BoxObject", "TrajectoryRecord", "WorkspaceRecord", "PointSet", "HistoryRecord", "check_name"]


@dataclass(frozen=True, eq=False)
class RobotEntry:
    """A robot of the session.

    Attributes:
        key: name of the robot in this session (scene path ``pinarms/robots/<key>``).
        source: ``"registry"`` (reloaded with ``robots.load(name)``) or ``"urdf"``
            (rebuilt from the embedded ``urdf_text``).
        name: the robot's name (registry name for ``"registry"``).
        tcp_frame: frame used as the tool centre point.
        joint_names: independent joints, in ``q`` order.
        base_to_world: pose of the robot's base in the world frame, (4, 4), m.
        urdf_text: embedded URDF (``None`` for registry robots).
        package_dirs: folders that resolved ``package://`` meshes when saved: a hint shown in
            error messages only; loading never reads meshes from them unless the caller
            passes them (``load_session(..., package_dirs=...)``).
        payload: the payload the robot carries (:meth:`pinarms.robots.payload.Payload.as_dict`:
            ``mass_kg``, ``com_m``, ``inertia_kg_m2``, ``frame``), or ``None``; reapplied
            with ``robot.with_payload`` when the session reopens.
    """

    key: str
    source: str
    name: str
    tcp_frame: str
    joint_names: tuple[str, ...]
    base_to_world: np.ndarray
    urdf_text: str | None = None
    package_dirs: tuple[str, ...] = ()
    payload: dict | None = None

    @property
    def nq(self) -> int:
        """Number of independent joints."""
        return len(self.joint_names)


@dataclass(frozen=True, eq=False)
class BoxObject:
    """A static box in the scene (conveyor, crate): ``size`` (3,) m, ``pose`` box→world (4, 4), ``color`` RGBA in [0, 1]."""

    name: str
    size: np.ndarray
    pose: np.ndarray
    color: tuple[float, float, float, float]


@dataclass(frozen=True, eq=False)
class TrajectoryRecord:
    """A trajectory of one robot: definition (JSON recipe or ``None``) plus samples.

    Attributes:
        t: sample instants (N,), s, strictly increasing.
        q: joint positions (N, nq) at ``t`` (rad or m, the robot's ``q`` order).
        knot_times: knot (via point) instants (m+1,), s.
        definition: ``Trajectory.definition`` (rebuild with :meth:`rebuild`), or ``None``.
    """

    name: str
    robot: str
    t: np.ndarray
    q: np.ndarray
    knot_times: np.ndarray
    definition: dict | None

    def rebuild(self) -> Any:
        """The :class:`pinarms.planning.Trajectory` rebuilt from :attr:`definition`."""
        if self.definition is None:
            raise InvalidInput(f"trajectory {self.name!r} was saved from samples only; it has no definition to rebuild")
        from pinarms import planning  # late import: only this method needs it

        return planning.from_definition(self.definition)


@dataclass(frozen=True, eq=False)
class WorkspaceRecord:
    """A workspace cloud: ``points`` (n, 3) m in the robot's base frame, ``manipulability`` (n,)."""

    name: str
    robot: str
    points: np.ndarray
    manipulability: np.ndarray


@dataclass(frozen=True, eq=False)
class PointSet:
    """Via points or targets: ``points`` (n, 3) m, in ``robot``'s base frame or the world frame (``robot`` None)."""

    name: str
    kind: str
    robot: str | None
    points: np.ndarray


@dataclass(frozen=True, eq=False)
class HistoryRecord:
    """An optimisation history: equal-length 1-D float columns (``best`` and usually ``mean``), one row per generation.

    ``inf`` marks a generation without any finite objective (NaN is never stored).
    """

    name: str
    columns: dict[str, np.ndarray]

    @property
    def best(self) -> np.ndarray:
        """Best objective per generation."""
        return self.columns["best"]

    @property
    def mean(self) -> np.ndarray | None:
        """Mean objective per generation, when recorded."""
        return self.columns.get("mean")


def check_name(name: object, what: str) -> str:
    """``name`` when it is a valid session name, else :class:`InvalidInput`."""
    if not isinstance(name, str) or not NAME_RE.match(name):
        raise InvalidInput(
            f"{what} name {name!r} is not allowed: use 1-100 printable characters without '/'"
        )
    return name
