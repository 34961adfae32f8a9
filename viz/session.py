"""Saved sessions: the :class:`Session` builder, what a user keeps from a study.

A session holds robots (a registry name, or the URDF text embedded) with their base
placements, static boxes (a conveyor, a crate), named trajectories (their definition plus
sampled joint positions), workspace clouds with manipulability, via points and targets,
optimisation histories, and free metadata.

This module builds sessions from the user's objects (checking every argument) and saves
and loads them; the file format itself (records, the table of member kinds, bounded and
validated reading, writing) is :mod:`pinarms.viz.session_format`. Never pickle; written
atomically; a save/load round trip is exact (arrays bit-equal, JSON equal).

Frames and units: positions in metres, angles in radians, times in seconds. Every robot
has a pose ``base_to_world`` (4×4). Workspace points, point sets with a ``robot`` and
trajectory joint values are given in (or for) that robot's base frame; point sets without a
robot are in the world frame.
"""

from __future__ import annotations

import importlib.metadata
import json
import math
import os
import threading
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from pinarms import robots
from pinarms.robots.errors import InvalidInput, PinarmsError
from pinarms.robots.robot import Robot

from .errors import SessionFormatError
from .session_format import (
    F8 as _F8,
    FORMAT_NAME,
    FORMAT_VERSION,
    KINDS,
    POINT_KINDS as _POINT_KINDS,
    BoxObject,
    HistoryRecord,
    PointSet,
    RobotEntry,
    SessionLimits,
    TrajectoryRecord,
    WorkspaceRecord,
    check_mesh_paths,
    check_name as _check_name,
    read_session,
    to_document,
    write_session,
)

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

MAX_TRAJECTORY_SAMPLES = 2_000_000
"""Most samples :meth:`Session.add_trajectory` takes from a Trajectory (duration × hz)."""


# ---------------------------------------------------------------------------- helpers
def _json_normalised(obj: Any, what: str) -> Any:
    """``obj`` as it will come back from JSON (tuples → lists); rejects NaN and non-JSON values."""
    try:
        return json.loads(json.dumps(obj, allow_nan=False, ensure_ascii=False).encode("utf-8"))
    except (TypeError, ValueError, RecursionError) as exc:  # UnicodeEncodeError (lone surrogates) is a ValueError
        raise InvalidInput(f"{what} must be JSON-able (dicts, lists, str, finite numbers, bool, None): {exc}") from exc


def _real(values: Any, what: str) -> np.ndarray:
    """``values`` as a fresh float64 array; complex numbers and non-numbers raise InvalidInput."""
    try:
        if np.iscomplexobj(values):
            raise TypeError("complex numbers")
        return np.array(values, dtype=_F8)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidInput(f"{what} must be numbers (real), got {type(values).__name__}") from exc


def _float_array(values: Any, what: str, ndim: int, width: int | None = None, *, allow_inf: bool = False) -> np.ndarray:
    """A fresh, read-only, finite float64 array of ``ndim`` dims (last dim ``width``); ±inf allowed on request."""
    arr = _real(values, what)
    if arr.ndim != ndim or (width is not None and arr.shape[-1] != width):
        shape = "(N,)" if ndim == 1 else f"(N, {width})"
        raise InvalidInput(f"{what} must have shape {shape}, got {arr.shape}")
    if np.any(np.isnan(arr)) if allow_inf else not np.all(np.isfinite(arr)):
        raise InvalidInput(f"{what} holds NaN{'' if allow_inf else ' or infinite'} values")
    arr.flags.writeable = False
    return arr


def _pose(values: Any, what: str) -> np.ndarray:
    T = _real(np.eye(4) if values is None else values, what)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise InvalidInput(f"{what} must be a finite (4, 4) homogeneous transform, got shape {T.shape}")
    R = T[:3, :3]
    if not np.allclose(T[3], [0, 0, 0, 1]) or not np.allclose(R.T @ R, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0:
        raise InvalidInput(f"{what} must be a rigid transform (orthonormal rotation, last row 0 0 0 1)")
    T.flags.writeable = False
    return T


def _pinarms_version() -> str:
    try:
        return importlib.metadata.version("pinarms")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover - running from a bare checkout
        return "unknown"


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


# ---------------------------------------------------------------------------- session
class Session:
    """A study to keep: robots, static objects, trajectories, workspaces, points, histories, metadata.

    >>> s = Session(robots.load("ur5"), title="pick and place")
    >>> s.add_trajectory("pick", traj)          # planning.Trajectory (or (t, q) arrays)
    >>> s.save("study.pinarms")
    >>> s2 = load_session("study.pinarms")

    Args:
        robot: first robot (a :class:`robots.Robot` or a registry name), or ``None``.
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
        metadata: Mapping[str, Any] | None = None,
        base_to_world: Any = None,
        key: str | None = None,
    ) -> None:
        if not isinstance(title, str):
            raise InvalidInput(f"title must be a string, got {title!r}")
        if metadata is not None and not isinstance(metadata, Mapping):
            raise InvalidInput(f"metadata must be a mapping (dict) of JSON-able values, got {type(metadata).__name__}")
        user = _json_normalised(dict(metadata or {}), "metadata")
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
            f"workspaces={list(self.workspaces)}, points={list(self.point_sets)}, histories={list(self.histories)})"
        )

    # ---------------------------------------------------------------- robots
    def add_robot(self, robot: Robot | str, *, key: str | None = None, base_to_world: Any = None) -> str:
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
        reg = _registry_name(robot)
        self.robots[key] = RobotEntry(
            key=key,
            source="registry" if reg else "urdf",
            name=robot.name,
            tcp_frame=robot.tcp_frame,
            joint_names=tuple(robot.joint_names),
            base_to_world=_pose(base_to_world, f"base_to_world of robot {key!r}"),
            urdf_text=None if reg else robot.urdf_text,
            package_dirs=() if reg else tuple(str(p) for p in robot.package_dirs),
            payload=None if robot.payload is None else robot.payload.as_dict(),
        )
        self._loaded[key] = robot
        return key

    def robot(self, key: str | None = None) -> Robot:
        """The :class:`robots.Robot` of ``key`` (default: the only robot), loaded on first use."""
        entry = self._entry(key)
        rob = self._loaded.get(entry.key)
        if rob is not None:
            return rob
        with self._loading:
            return self._load_robot(entry)

    def _load_robot(self, entry: RobotEntry) -> Robot:
        if entry.key not in self._loaded:
            if entry.source == "registry":
                rob = robots.load(entry.name)
            else:
                # an embedded URDF comes from a file: its meshes must stay inside the folders the caller
                # allowed; the folders the file names (entry.package_dirs) only appear in the message
                dirs = check_mesh_paths(entry.urdf_text, self.mesh_dirs, f"session robot {entry.key!r}",
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
            self._loaded[entry.key] = rob
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

    def _free(self, table: Mapping[str, Any], name: Any, what: str) -> str:
        name = _check_name(name, what)
        if name in table:
            raise InvalidInput(f"{what} {name!r} already exists in this session; choose another name")
        return name

    def add_cell(self, cell: Any, *, key: str | None = None, motions: Any = None, check: Any = None,
                 name: str = "cell motion", hz: float = 100.0) -> str:
        """Add a :class:`robots.cell.Cell`: its arms and fixtures as one robot (the cell's URDF embedded).

        Args:
            cell: the cell; its joint vector is the robot's, poses are in the world frame
                (``base_to_world`` is the identity).
            key: its key (default: the cell's name).
            motions: the arms' motions (:class:`robots.cell.ArmMotion` objects or
                ``{arm: trajectory}``), stored as one trajectory ``name`` of the whole cell,
                sampled at ``hz`` over their window: the viewer animates all arms together.
            check: a :class:`robots.cell.MotionCheck` of those motions: its samples in
                contact become the point set ``"<name> contacts"`` (kind ``"contact"``, drawn
                red), at the middle of the contact pair's nearest points.

        The arms' tcp frames are recorded in ``metadata["cells"][key]`` so that the viewer
        draws each arm's tcp path.
        """
        from pinarms.robots.cell import Cell
        from pinarms.robots.cell.motion import sample_motions

        if not isinstance(cell, Cell):
            raise InvalidInput(f"cell must be a robots.cell.Cell, got {type(cell).__name__}")
        key = self.add_robot(cell.robot, key=cell.name if key is None else key)
        self.metadata.setdefault("cells", {})[key] = {
            "name": cell.name,
            "args": dict(cell.args),
            "arms": {a.name: {"tcp_frame": a.prefix + a.robot.tcp_frame, "q_start": a.q_slice.start,
                              "q_stop": a.q_slice.stop} for a in cell.arms},
            "fixtures": [f.name for f in cell.fixtures],
        }
        if motions is not None:
            t, q = sample_motions(cell, motions, hz=hz, window=None if check is None else check.window)
            self.add_trajectory(name, (t, q), robot=key)
        if check is not None:
            if motions is None:
                raise InvalidInput("a check needs the motions it was made of (motions=...)")
            inside = np.flatnonzero(np.asarray(check.clearance) <= 0.0)
            if inside.size:  # at most 400 contact samples, evenly spread
                inside = inside[np.linspace(0, inside.size - 1, min(inside.size, 400)).round().astype(int)]
                from pinarms.robots.cell.motion import _motions, configurations

                qs = configurations(cell, _motions(cell, motions), np.asarray(check.times)[inside], cell.neutral)
                cl = cell.clearance(qs)
                self.add_points(f"{name} contacts", 0.5 * (cl.point_a + cl.point_b), kind="contact")
        return key

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

    # ---------------------------------------------------------------- content
    def add_box(self, name: str, size: Any, pose: Any = None, color: Any = (0.6, 0.6, 0.6, 1.0)) -> BoxObject:
        """Add a static box: ``size`` (3,) edge lengths in m, ``pose`` box centre → world (4, 4), ``color`` RGBA."""
        name = self._free(self.objects, name, "object")
        size_arr = _float_array(size, f"size of box {name!r}", 1, 3)
        if np.any(size_arr <= 0):
            raise InvalidInput(f"size of box {name!r} must be positive edge lengths in m, got {size_arr.tolist()}")
        try:
            rgba = tuple(float(c) for c in _real(color, "color").ravel())
        except InvalidInput:
            rgba = ()
        if len(rgba) != 4 or not all(0.0 <= c <= 1.0 for c in rgba):
            raise InvalidInput(f"color of box {name!r} must be 4 RGBA values in [0, 1], got {color!r}")
        box = BoxObject(name, size_arr, _pose(pose, f"pose of box {name!r}"), rgba)
        self.objects[name] = box
        return box

    def add_trajectory(self, name: str, trajectory: Any, *, robot: str | None = None, hz: float = 100.0) -> TrajectoryRecord:
        """Add a trajectory of robot ``robot`` (default: the only robot).

        Args:
            trajectory: a :class:`planning.Trajectory` (its ``definition`` is kept and it is
                sampled at ``hz``, knots included), or a pair ``(t, q)`` of samples
                (t (N,) s, q (N, nq)).
            hz: sampling rate (1/s) for a Trajectory.
        """
        name = self._free(self.trajectories, name, "trajectory")
        entry = self._entry(robot)
        if isinstance(trajectory, tuple) and len(trajectory) == 2:
            t, q = trajectory
            definition, knots = None, None
        elif hasattr(trajectory, "sample") and hasattr(trajectory, "knot_times"):
            if not (isinstance(hz, (int, float)) and math.isfinite(hz) and hz > 0):
                raise InvalidInput(f"hz must be a positive sampling rate in 1/s, got {hz!r}")
            knots = np.asarray(trajectory.knot_times, dtype=float)
            n_wanted = (knots[-1] - knots[0]) * hz
            if not n_wanted < MAX_TRAJECTORY_SAMPLES:
                raise InvalidInput(
                    f"trajectory {name!r}: {knots[-1] - knots[0]:g} s at hz={hz:g} gives {n_wanted:.3g} samples, more "
                    f"than {MAX_TRAJECTORY_SAMPLES:,}; lower hz"
                )
            n = max(2, int(math.ceil(n_wanted)) + 1)
            t = np.union1d(np.linspace(knots[0], knots[-1], n), knots)
            q = trajectory.sample(t)[0]
            definition = _json_normalised(trajectory.definition, f"definition of trajectory {name!r}")
        else:
            raise InvalidInput(
                f"trajectory {name!r} must be a planning.Trajectory or a (t, q) pair of arrays, got {type(trajectory).__name__}"
            )
        t = _float_array(t, f"t of trajectory {name!r}", 1)
        q_arr = _real(q, f"q of trajectory {name!r}")
        if q_arr.ndim == 1 and entry.nq == 1:
            q_arr = q_arr[:, None]
        q = _float_array(q_arr, f"q of trajectory {name!r} (robot {entry.key!r} has {entry.nq} joints)", 2, entry.nq)
        if t.size < 2 or np.any(np.diff(t) <= 0) or q.shape[0] != t.size:
            raise InvalidInput(
                f"trajectory {name!r} needs t strictly increasing with at least 2 instants and one q row per instant; "
                f"got t {t.shape}, q {q.shape}"
            )
        knots = _float_array(t[[0, -1]] if knots is None else knots, f"knot_times of trajectory {name!r}", 1)
        rec = TrajectoryRecord(name, entry.key, t, q, knots, definition)
        self.trajectories[name] = rec
        return rec

    def add_workspace(self, name: str, workspace: Any = None, *, points: Any = None, manipulability: Any = None,
                      robot: str | None = None) -> WorkspaceRecord:
        """Add a workspace cloud of robot ``robot``: a ``Workspace`` (``points``, ``manipulability``) or the two arrays.

        ``points`` (n, 3) m in the robot's base frame; ``manipulability`` (n,) ≥ 0.
        """
        name = self._free(self.workspaces, name, "workspace")
        entry = self._entry(robot)
        if workspace is not None:
            if not (hasattr(workspace, "points") and hasattr(workspace, "manipulability")):
                raise InvalidInput(
                    f"workspace {name!r} must be a robots.Workspace (points, manipulability), got {type(workspace).__name__}"
                )
            points, manipulability = workspace.points, workspace.manipulability
        if points is None or manipulability is None:
            raise InvalidInput(f"workspace {name!r}: give a Workspace, or both points= and manipulability=")
        pts = _float_array(points, f"points of workspace {name!r}", 2, 3)
        w = _float_array(manipulability, f"manipulability of workspace {name!r}", 1)
        if pts.shape[0] == 0:
            raise InvalidInput(f"workspace {name!r} has no points; sample at least one")
        if w.shape[0] != pts.shape[0] or np.any(w < 0):
            raise InvalidInput(
                f"workspace {name!r} needs one manipulability value >= 0 per point; got {w.shape[0]} for {pts.shape[0]} points"
            )
        rec = WorkspaceRecord(name, entry.key, pts, w)
        self.workspaces[name] = rec
        return rec

    def add_points(self, name: str, points: Any, *, kind: str = "via", robot: str | None = None) -> PointSet:
        """Add via points or targets (``kind`` ``"via"`` or ``"target"``), (n, 3) m.

        With ``robot`` the points are in that robot's base frame, without it in the world frame.
        """
        name = self._free(self.point_sets, name, "point set")
        if kind not in _POINT_KINDS:
            raise InvalidInput(f"kind of point set {name!r} must be one of {_POINT_KINDS}, got {kind!r}")
        key = None if robot is None else self._entry(robot).key
        arr = np.atleast_2d(_real(points, f"points of point set {name!r} (n, 3) in m"))
        pts = _float_array(arr, f"points of point set {name!r}", 2, 3)
        if pts.shape[0] == 0:
            raise InvalidInput(f"point set {name!r} has no points; give at least one (n, 3) row in m")
        ps = PointSet(name, kind, key, pts)
        self.point_sets[name] = ps
        return ps

    def add_history(self, name: str, history: Any) -> HistoryRecord:
        """Add an optimisation history: a GA history (``best``, ``mean``, ...), a result with ``.history``, or a mapping of columns."""
        name = self._free(self.histories, name, "history")
        if hasattr(history, "history") and not isinstance(history, Mapping):
            history = history.history
        if history is None:
            raise InvalidInput(f"history {name!r} is None (an exact optimiser records no generations)")
        if isinstance(history, Mapping):
            cols = dict(history)
        elif hasattr(history, "as_dict"):
            cols = {k: getattr(history, k) for k in history.as_dict()}
        else:
            raise InvalidInput(f"history {name!r} must be a GA history, a result with .history, or a mapping of columns")
        if "best" not in cols:
            raise InvalidInput(f"history {name!r} needs a 'best' column; got {sorted(cols)}")
        out: dict[str, np.ndarray] = {}
        for k, v in cols.items():
            _check_name(k, f"column of history {name!r}")
            # a generation without any finite objective records inf (optim's GA does so)
            out[k] = _float_array(v, f"column {k!r} of history {name!r}", 1, allow_inf=True)
        lengths = {v.shape[0] for v in out.values()}
        if 0 in lengths:
            raise InvalidInput(f"history {name!r} has no generations; record at least one row")
        if len(lengths) != 1:
            raise InvalidInput(f"columns of history {name!r} must have equal lengths, got {sorted(lengths)}")
        rec = HistoryRecord(name, out)
        self.histories[name] = rec
        return rec

    def add_reachability(self, name: str, reach_map: Any, *, robot: str | None = None, min_index: float = 0.0) -> Any:
        """Add the voxels of a :class:`robots.ReachabilityMap` with index > ``min_index`` (robot ``robot``'s base frame).

        The viewer and the standalone page draw them as coloured voxels (see :mod:`viz.reach_record`).
        """
        from .reach_record import make_record

        name = self._free(self.reachability, name, "reachability")
        rec = make_record(name, self._entry(robot).key, reach_map, min_index, _float_array)
        self.reachability[name] = rec
        return rec

    def add_line(self, spec: Any, result: Any, **options: Any) -> Any:
        """Add an animated window of a simulated belt line (:func:`viz.line_session.add_line`)."""
        from .line_session import add_line

        return add_line(self, spec, result, **options)

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
    s.mesh_dirs = tuple(dict.fromkeys([own, *(os.fspath(d) for d in (package_dirs or ())), *_shipped_model_dirs()]))
    return s


def _shipped_model_dirs() -> tuple[str, ...]:
    """pinarms' own model folders (built-in URDFs and cells with their meshes, the xacro macros): always allowed."""
    import pinarms.urdf

    return (str(Path(pinarms.urdf.__file__).resolve().parent), str(Path(robots.__file__).resolve().parent / "xacro"))
