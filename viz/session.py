"""Saved sessions: the :class:`Session` builder, what a user keeps from a study.

A session holds robots (a registry name, or the URDF text embedded) with their base
placements, static boxes (a conveyor, a crate), named trajectories (their definition plus
sampled joint positions), workspace clouds with manipulability, via points and targets,
optimisation histories, and free metadata.

This module builds sessions from the user's objects (every argument checked by
:mod:`pinarms.viz.session_inputs`; a cell by :mod:`pinarms.viz.cell_session`; a robot stored
and rebuilt by :mod:`pinarms.viz.session_robots`) and saves and
loads them; the file format itself (records, the table of member kinds, bounded and
validated reading, writing) is :mod:`pinarms.viz.session_format`. Never pickle; written
atomically; a save/load round trip is exact (arrays bit-equal, JSON equal).

Frames and units: positions in metres, angles in radians, times in seconds. Every robot
has a pose ``base_to_world`` (4×4). Workspace points, point sets with a ``robot`` and
trajectory joint values are given in (or for) that robot's base frame; point sets without a
robot are in the world frame.
"""

from __future__ import annotations

import importlib.metadata
import os
import threading
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Collection, Mapping, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms import robots
from pinarms.errors import InvalidInput
from pinarms.robots.robot import Robot

from pinarms.viz.session_archive import SessionLimits
from pinarms.viz.session_format import read_session, to_document, write_session
from pinarms.viz.session_inputs import (
    MAX_TRAJECTORY_SAMPLES,
    box_record,
    float_array,
    history_record,
    json_normalised,
    real_array,
    trajectory_record,
    workspace_record,
)
from pinarms.viz.session_records import (
    BoxObject,
    HistoryRecord,
    PointSet,
    RobotEntry,
    TrajectoryRecord,
    WorkspaceRecord,
    check_name as _check_name,
)
from pinarms.viz.session_robots import rebuild_robot, robot_entry, shipped_model_dirs
from pinarms.viz.session_schema import FORMAT_NAME, FORMAT_VERSION, KINDS, POINT_KINDS as _POINT_KINDS

if TYPE_CHECKING:
    from pinarms.robots.delta import DeltaRobot
    from pinarms.viz.delta_record import DeltaRecord
    from pinarms.optim.ga.engine import GAHistory, GAResult
    from pinarms.robots.reach.workspace import Workspace
    from pinarms.robots.cell.motion_report import MotionCheck
    from pinarms.optim.line.api import LineResult, LineSpec
    from pinarms.robots.cell.cell import Cell
    from pinarms.planning.trajectory import Trajectory
    from pinarms.robots.reach.reach_map import ReachabilityMap

__all__ = [
    "FORMAT_NAME",
    "FORMAT_VERSION",
    "Session",
    "SessionLimits",
    "RobotEntry",
    "BoxObject",
    "TrajectoryRecord",
    "WorkspaceRecord",
    "PointSet",
    "HistoryRecord",
    "load_session",
    "MAX_TRAJECTORY_SAMPLES",
]

# ---------------------------------------------------------------------------- helpers
def _pinarms_version() -> str:
    try:
        return importlib.metadata.version("pinarms")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover - running from a bare checkout
        return "unknown"


# ---------------------------------------------------------------------------- session
class Session:
    """A study to keep: robots, static objects, trajectories, workspaces, points, histories, metadata.

    >>> s = Session(robots.load("ur5"), title="pick and place")
    >>> s.add_trajectory("pick", traj)          # planning.Trajectory (or (t, q) arrays)
    >>> s.save("study.pinarms")
    >>> s2 = load_session("study.pinarms")

    Args:
        robot: first robot (a :class:`pinarms.robots.Robot` or a registry name), or ``None``.
        title: human title, stored in the metadata.
        metadata: free JSON-able metadata (stored under ``metadata["user"]``).
        base_to_world: pose of the first robot's base in the world frame (4, 4); default identity.
        key: the first robot's key in the session (default: its name).
    """

    def __init__(
        self,
        robot: Robot | str | None = None,
        *,
        title: str = "",
        metadata: Mapping[str, object] | None = None,
        base_to_world: ArrayLike | None = None,
        key: str | None = None,
    ) -> None:
        if not isinstance(title, str):
            raise InvalidInput(f"title must be a string, got {title!r}")
        if metadata is not None and not isinstance(metadata, Mapping):
            raise InvalidInput(f"metadata must be a mapping (dict) of JSON-able values, got {type(metadata).__name__}")
        user = json_normalised(dict(metadata or {}), "metadata")
        self.metadata: dict[str, Any] = {
            "title": title,
            "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "pinarms_version": _pinarms_version(),
            "user": user,
        }
        self.robots: dict[str, RobotEntry] = {}
        self.objects: dict[str, BoxObject] = {}
        self.trajectories: dict[str, TrajectoryRecord] = {}
        self.workspaces: dict[str, WorkspaceRecord] = {}
        self.point_sets: dict[str, PointSet] = {}
        self.histories: dict[str, HistoryRecord] = {}
        self.reachability: dict[str, Any] = {}  # name → viz.reach_record.ReachabilityRecord
        self.lines: dict[str, Any] = {}  # name → viz.line_record.LineRecord (belt, items; viz.line_session)
        self.deltas: dict[str, Any] = {}  # name → viz.delta_record.DeltaRecord (a shipped delta and its motion)
        self._deltas: dict[str, Any] = {}  # delta registry name → DeltaRobot, loaded once
        self._loaded: dict[str, Robot] = {}
        self._loading = threading.Lock()  # one Robot per key, whichever thread asks first
        #: folders meshes of robots stored in a file may be read from (set by :func:`load_session`:
        #: the session file's own folder and the caller's ``package_dirs``; never folders named in the file)
        self.mesh_dirs: tuple[str, ...] = ()
        #: kept for callers that read it; :func:`load_session` leaves it ``None`` (each robot carries its folders)
        self.package_dirs_override: tuple[str, ...] | None = None
        if robot is not None:
            self.add_robot(robot, key=key, base_to_world=base_to_world)

    @property
    def title(self) -> str:
        """The session's title."""
        return self.metadata["title"]

    def __repr__(self) -> str:
        return (
            f"Session(title={self.title!r}, robots={list(self.robots)}, trajectories={list(self.trajectories)}, "
            f"workspaces={list(self.workspaces)}, points={list(self.point_sets)}, histories={list(self.histories)}"
            + (f", deltas={list(self.deltas)})" if self.deltas else ")")
        )

    # ---------------------------------------------------------------- robots
    def add_robot(self, robot: Robot | str, *, key: str | None = None, base_to_world: ArrayLike | None = None) -> str:
        """Add a robot placed at ``base_to_world`` (4, 4) in the world; return its key.

        A robot that ``robots.load`` rebuilds exactly is stored by name; any other has its
        URDF text embedded so that the session reopens anywhere. A robot carrying a payload
        (``robot.with_payload``) keeps it: the session stores the payload and reapplies it.
        """
        if isinstance(robot, str):
            robot = robots.load(robot)
        if not isinstance(robot, Robot):
            raise InvalidInput(f"robot must be a robots.Robot or a registry name, got {type(robot).__name__}")
        key = _check_name(robot.name if key is None else key, "robot key")
        if key in self.robots:
            raise InvalidInput(f"robot key {key!r} is already used in this session; pass key=... to add another one")
        self.robots[key] = robot_entry(robot, key, base_to_world)
        self._loaded[key] = robot
        return key

    def robot(self, key: str | None = None) -> Robot:
        """The :class:`pinarms.robots.Robot` of ``key`` (default: the only robot), loaded on first use."""
        entry = self._entry(key)
        rob = self._loaded.get(entry.key)
        if rob is not None:
            return rob
        with self._loading:
            return self._load_robot(entry)

    def _load_robot(self, entry: RobotEntry) -> Robot:
        if entry.key not in self._loaded:
            self._loaded[entry.key] = rebuild_robot(entry, self.mesh_dirs)
        return self._loaded[entry.key]

    def _entry(self, key: str | None) -> RobotEntry:
        if key is None:
            if len(self.robots) != 1:
                raise InvalidInput(
                    f"this session has {len(self.robots)} robots ({', '.join(self.robots) or 'none'}); name one with robot=..."
                )
            return next(iter(self.robots.values()))
        if key not in self.robots:
            raise InvalidInput(f"no robot {key!r} in this session; robots: {', '.join(self.robots) or 'none (add_robot first)'}")
        return self.robots[key]

    def free_name(self, table: Collection[str], name: str, what: str) -> str:
        """``name`` checked as a name of a ``what`` (a record kind) not yet in ``table`` (the names taken).

        Raises:
            InvalidInput: not a valid name, or taken.
        """
        name = _check_name(name, what)
        if name in table:
            raise InvalidInput(f"{what} {name!r} already exists in this session; choose another name")
        return name

    def add_cell(self, cell: Cell, *, key: str | None = None, motions: Any = None, check: MotionCheck | None = None,
                 name: str = "cell motion", hz: float = 100.0, hold: ArrayLike | None = None) -> str:
        """Add a :class:`pinarms.robots.cell.Cell`: its arms and fixtures as one robot (the cell's URDF embedded).

        Args:
            cell: the cell; its joint vector is the robot's, poses are in the world frame
                (``base_to_world`` is the identity).
            key: its key (default: the cell's name).
            motions: the arms' motions (:class:`pinarms.robots.cell.ArmMotion` objects or
                ``{arm: trajectory}``), stored as one trajectory ``name`` of the whole cell,
                sampled at ``hz`` over their window: the viewer animates all arms together.
            check: a :class:`pinarms.robots.cell.MotionCheck` of those motions: its samples in
                contact become the point set ``"<name> contacts"`` (kind ``"contact"``, drawn
                red), at the middle of the contact pair's nearest points.
            hold: cell configuration ``(nq,)`` of the arms without a motion (default
                :attr:`Cell.hold`: each arm's hold pose from the cell description, else
                neutral); the check must have been made with the same hold.

        The arms' tcp frames and the hold are recorded in ``metadata["cells"][key]`` so that
        the viewer draws each arm's tcp path.
        """
        from pinarms.viz.cell_session import add_cell

        return add_cell(self, cell, key=key, motions=motions, check=check, name=name, hz=hz, hold=hold)

    def cell_tcp_frames(self, key: str) -> dict[str, str]:
        """``{arm: tcp frame}`` of the cell stored under ``key`` (``{}`` for a plain robot)."""
        entry = self.metadata.get("cells", {})
        info = entry.get(key) if isinstance(entry, dict) else None
        arms = info.get("arms") if isinstance(info, dict) else None
        if not isinstance(arms, dict):
            return {}
        out = {}
        for arm, data in arms.items():
            frame = data.get("tcp_frame") if isinstance(data, dict) else None
            if isinstance(arm, str) and isinstance(frame, str):
                out[arm] = frame
        return out

    def cell_hold(self, key: str) -> np.ndarray | None:
        """The hold pose ``(nq,)`` of the cell stored under ``key``: where its arms rest when nothing
        animates them (``None`` for a plain robot, or a stored value that is not ``nq`` finite numbers)."""
        entry = self.metadata.get("cells", {})
        info = entry.get(key) if isinstance(entry, dict) else None
        hold = info.get("hold") if isinstance(info, dict) else None
        if not isinstance(hold, list) or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in hold):
            return None
        q = np.asarray(hold, dtype=float)
        nq = self.robot(key).nq
        return q if q.shape == (nq,) and np.all(np.isfinite(q)) else None

    # ---------------------------------------------------------------- content
    def add_box(self, name: str, size: ArrayLike, pose: ArrayLike | None = None, color: ArrayLike = (0.6, 0.6, 0.6, 1.0)) -> BoxObject:
        """Add a static box: ``size`` (3,) edge lengths in m, ``pose`` box centre → world (4, 4), ``color`` RGBA."""
        box = box_record(self.free_name(self.objects, name, "object"), size, pose, color)
        self.objects[box.name] = box
        return box

    def add_trajectory(self, name: str, trajectory: Trajectory, *, robot: str | None = None, hz: float = 100.0) -> TrajectoryRecord:
        """Add a trajectory of robot ``robot`` (default: the only robot).

        Args:
            trajectory: a :class:`pinarms.planning.Trajectory` (its ``definition`` is kept and it is
                sampled at ``hz``, knots included), or a pair ``(t, q)`` of samples
                (t (N,) s, q (N, nq)).
            hz: sampling rate (1/s) for a Trajectory.
        """
        rec = trajectory_record(self.free_name(self.trajectories, name, "trajectory"), self._entry(robot), trajectory, hz)
        self.trajectories[rec.name] = rec
        return rec

    def add_workspace(self, name: str, workspace: Workspace | None = None, *, points: ArrayLike | None = None, manipulability: ArrayLike | None = None,
                      robot: str | None = None) -> WorkspaceRecord:
        """Add a workspace cloud of robot ``robot``: a ``Workspace`` (``points``, ``manipulability``) or the two arrays.

        ``points`` (n, 3) m in the robot's base frame; ``manipulability`` (n,) ≥ 0.
        """
        rec = workspace_record(self.free_name(self.workspaces, name, "workspace"), self._entry(robot), workspace, points,
                               manipulability)
        self.workspaces[rec.name] = rec
        return rec

    def add_points(self, name: str, points: ArrayLike, *, kind: str = "via", robot: str | None = None) -> PointSet:
        """Add via points or targets (``kind`` ``"via"`` or ``"target"``), (n, 3) m.

        With ``robot`` the points are in that robot's base frame, without it in the world frame.
        """
        name = self.free_name(self.point_sets, name, "point set")
        if kind not in _POINT_KINDS:
            raise InvalidInput(f"kind of point set {name!r} must be one of {_POINT_KINDS}, got {kind!r}")
        key = None if robot is None else self._entry(robot).key
        arr = np.atleast_2d(real_array(points, f"points of point set {name!r} (n, 3) in m"))
        pts = float_array(arr, f"points of point set {name!r}", 2, 3)
        if pts.shape[0] == 0:
            raise InvalidInput(f"point set {name!r} has no points; give at least one (n, 3) row in m")
        ps = PointSet(name, kind, key, pts)
        self.point_sets[name] = ps
        return ps

    def add_history(self, name: str, history: GAHistory | GAResult | HistoryRecord | Mapping[str, ArrayLike]) -> HistoryRecord:
        """Add an optimisation history: a GA history (``best``, ``mean``, ...), a result with ``.history``, or a mapping of columns."""
        rec = history_record(self.free_name(self.histories, name, "history"), history)
        self.histories[rec.name] = rec
        return rec

    def add_reachability(self, name: str, reach_map: ReachabilityMap, *, robot: str | None = None, min_index: float = 0.0) -> Any:
        """Add the voxels of a :class:`pinarms.robots.ReachabilityMap` with index > ``min_index`` (robot ``robot``'s base frame).

        The viewer and the standalone page draw them as coloured voxels (see :mod:`pinarms.viz.reach_record`).
        """
        from pinarms.viz.reach_record import make_record

        name = self.free_name(self.reachability, name, "reachability")
        rec = make_record(name, self._entry(robot).key, reach_map, min_index, float_array)
        self.reachability[name] = rec
        return rec

    def add_line(self, spec: LineSpec, result: LineResult, **options: Any) -> Any:
        """Add an animated window of a simulated belt line (:func:`pinarms.viz.line_session.add_line`)."""
        from pinarms.viz.line_session import add_line

        return add_line(self, spec, result, **options)

    def add_delta(self, delta: DeltaRobot | str, *, key: str | None = None, base_to_world: ArrayLike | None = None,
                  motion: tuple[ArrayLike, ArrayLike] | None = None) -> DeltaRecord:
        """Add a shipped delta robot (:func:`pinarms.robots.delta.load_delta`, or its registry name) hung at
        ``base_to_world`` (4, 4), with its ``motion``: ``(t (N,) s, actuated (N, 3|4) rad)``, the motor angles
        (and the tool angle of the fourth axis) over time, or ``None`` (at rest). Only the actuated
        coordinates are stored; the passive joints are solved from the closed form wherever the session is
        read (:mod:`pinarms.viz.delta_record`). Returns the :class:`~pinarms.viz.delta_record.DeltaRecord`."""
        from pinarms.robots.delta import load_delta
        from pinarms.viz.delta_record import delta_record

        if isinstance(delta, str):
            delta = load_delta(delta)
        name = self.free_name(self.deltas, getattr(delta, "name", "delta") if key is None else key, "delta")
        rec = delta_record(name, delta, base_to_world, motion)
        self.deltas[name] = rec
        return rec

    def delta(self, key: str) -> DeltaRobot:
        """The :class:`pinarms.robots.delta.DeltaRobot` of the session's delta ``key`` (loaded once by name)."""
        from pinarms.robots.delta import load_delta

        if key not in self.deltas:
            raise InvalidInput(f"no delta {key!r} in this session; deltas: {', '.join(self.deltas) or 'none (add_delta first)'}")
        name = self.deltas[key].delta
        with self._loading:
            if name not in self._deltas:
                self._deltas[name] = load_delta(name)
        return self._deltas[name]

    # ---------------------------------------------------------------- (de)serialisation
    def _tables(self) -> dict[str, dict[str, Any]]:
        return {kind.attr: getattr(self, kind.attr) for kind in KINDS}

    def to_document(self) -> tuple[dict, dict[str, np.ndarray], dict[str, str]]:
        """The ``session.json`` document, the arrays by member name, and the text members."""
        return to_document(self.metadata, self._tables())

    def __eq__(self, other: object) -> bool:
        """Same JSON document and bit-equal arrays (dtype, shape and bytes)."""
        if not isinstance(other, Session):
            return NotImplemented
        da, aa, ta = self.to_document()
        db, ab, tb = other.to_document()
        if da != db or ta != tb or aa.keys() != ab.keys():
            return False
        return all(aa[k].dtype == ab[k].dtype and aa[k].shape == ab[k].shape and aa[k].tobytes() == ab[k].tobytes()
                   for k in aa)

    __hash__ = None  # type: ignore[assignment]

    def save(self, path: str | os.PathLike) -> Path:
        """Write the session to ``path`` (one zip file, atomically); return the path."""
        return write_session(path, self.metadata, self._tables())


def load_session(path: str | os.PathLike, *, package_dirs: tuple[str, ...] | list[str] | None = None,
                 limits: SessionLimits | None = None) -> Session:
    """Read and validate a session file written by :meth:`Session.save`.

    Files users exchange are hostile until checked: the reader compares every member's
    declared size with ``session.json``'s index and with ``limits`` before reading it, reads
    arrays streaming, and refuses what does not fit (see :class:`SessionLimits` and
    docs/viz.md).

    Args:
        path: the session file.
        package_dirs: folders besides the session file's own folder (and pinarms' own model
            folders) that meshes of embedded URDFs may come from (``package://`` paths are
            resolved against each). Folders named inside the file are never used by
            themselves: a mesh outside these is refused with :class:`SessionFormatError`
            naming it and saying what to pass.
        limits: the most the reader accepts (default ``SessionLimits()``: 1 GiB in all,
            512 MiB per array, 16 MiB per URDF, 64 MiB of JSON).

    Raises:
        SessionFormatError: the file is not a zip, is truncated or corrupt, lacks a member,
            has a malformed ``session.json``, arrays of the wrong dtype or shape, members
            larger than their index or the limits, or was written by a newer format version.
        InvalidInput: ``path`` does not exist or is a folder.
    """
    if package_dirs is not None and (isinstance(package_dirs, (str, bytes)) or
                                     not all(isinstance(d, (str, os.PathLike)) for d in package_dirs)):
        raise InvalidInput(f"package_dirs must be a list of folders, got {package_dirs!r}")
    contents = read_session(path, limits)
    s = Session()
    s.metadata = contents.metadata
    for kind in KINDS:
        setattr(s, kind.attr, contents.tables[kind.attr])
    own = str(Path(path).resolve().parent)
    s.mesh_dirs = tuple(dict.fromkeys([own, *(os.fspath(d) for d in (package_dirs or ())), *shipped_model_dirs()]))
    return s
