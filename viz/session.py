"""Saved sessions: what a user keeps from a study, in one open, versioned file.

A session holds robots (a registry name, or the URDF text embedded) with their base
placements, static boxes (a conveyor, a crate), named trajectories (their definition plus
sampled joint positions), workspace clouds with manipulability, via points and targets,
optimisation histories, and free metadata.

File format (``FORMAT_NAME`` version ``FORMAT_VERSION``; full spec in docs/viz.md): a zip
archive holding ``session.json`` (format, version, metadata, index of everything) and one
``.npy`` file per array (``numpy.save``; loaded with ``allow_pickle=False``), plus
``robots/<key>.urdf`` for embedded URDFs. Never pickle. Written atomically; validated on
load (:class:`SessionFormatError` says what is wrong). A save/load round trip is exact:
arrays are bit-equal and the JSON is equal.

Frames and units: positions in metres, angles in radians, times in seconds. Every robot
has a pose ``base_to_world`` (4×4). Workspace points, point sets with a ``robot`` and
trajectory joint values are given in (or for) that robot's base frame; point sets without a
robot are in the world frame.
"""

from __future__ import annotations

import importlib.metadata
import io
import json
import math
import re
import zipfile
import zlib
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from pinarms import robots
from pinarms.robots.errors import InvalidInput, PinarmsError
from pinarms.robots.robot import Robot

from ._atomic import atomic_write
from .errors import SessionFormatError

__all__ = [
    "FORMAT_NAME",
    "FORMAT_VERSION",
    "Session",
    "RobotEntry",
    "BoxObject",
    "TrajectoryRecord",
    "WorkspaceRecord",
    "PointSet",
    "HistoryRecord",
    "load_session",
    "MAX_TRAJECTORY_SAMPLES",
]

FORMAT_NAME = "pinarms-session"
FORMAT_VERSION = 1
JSON_MEMBER = "session.json"

#: names of robots, trajectories, ...: 1-100 printable characters, no "/" (scene path separator)
_NAME_RE = re.compile(r"^(?=.*\S)[^/\x00-\x1f\x7f]{1,100}$")
_POINT_KINDS = ("via", "target")
_F8 = np.dtype("<f8")
MAX_TRAJECTORY_SAMPLES = 2_000_000
"""Most samples :meth:`Session.add_trajectory` takes from a Trajectory (duration × hz)."""


# ---------------------------------------------------------------------------- records
@dataclass(frozen=True, eq=False)
class RobotEntry:
    """A robot of the session.

    Attributes:
        key: name of the robot in this session (scene path ``pinarms/<key>``).
        source: ``"registry"`` (reloaded with ``robots.load(name)``) or ``"urdf"``
            (rebuilt from the embedded ``urdf_text``).
        name: the robot's name (registry name for ``"registry"``).
        tcp_frame: frame used as the tool centre point.
        joint_names: independent joints, in ``q`` order.
        base_to_world: pose of the robot's base in the world frame, (4, 4), m.
        urdf_text: embedded URDF (``None`` for registry robots).
        package_dirs: folders that resolved ``package://`` meshes when saved (a hint only).
    """

    key: str
    source: str
    name: str
    tcp_frame: str
    joint_names: tuple[str, ...]
    base_to_world: np.ndarray
    urdf_text: str | None = None
    package_dirs: tuple[str, ...] = ()

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
        """The :class:`planning.Trajectory` rebuilt from :attr:`definition`."""
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


# ---------------------------------------------------------------------------- helpers
def _check_name(name: Any, what: str) -> str:
    if not isinstance(name, str) or not _NAME_RE.match(name):
        raise InvalidInput(
            f"{what} name {name!r} is not allowed: use 1-100 printable characters without '/'"
        )
    return name


def _json_normalised(obj: Any, what: str) -> Any:
    """``obj`` as it will come back from JSON (tuples → lists); rejects NaN and non-JSON values."""
    try:
        return json.loads(json.dumps(obj, allow_nan=False))
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be JSON-able (dicts, lists, str, finite numbers, bool, None): {exc}") from exc


def _float_array(values: Any, what: str, ndim: int, width: int | None = None, *, allow_inf: bool = False) -> np.ndarray:
    """A fresh, read-only, finite float64 array of ``ndim`` dims (last dim ``width``); ±inf allowed on request."""
    try:
        arr = np.array(values, dtype=_F8)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be numbers, got {type(values).__name__}") from exc
    if arr.ndim != ndim or (width is not None and arr.shape[-1] != width):
        shape = "(N,)" if ndim == 1 else f"(N, {width})"
        raise InvalidInput(f"{what} must have shape {shape}, got {arr.shape}")
    if np.any(np.isnan(arr)) if allow_inf else not np.all(np.isfinite(arr)):
        raise InvalidInput(f"{what} holds NaN{'' if allow_inf else ' or infinite'} values")
    arr.flags.writeable = False
    return arr


def _pose(values: Any, what: str) -> np.ndarray:
    T = np.array(np.eye(4) if values is None else values, dtype=_F8)
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
        return robot.name
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
        self._loaded: dict[str, Robot] = {}
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
        URDF text embedded so that the session reopens anywhere.
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
        )
        self._loaded[key] = robot
        return key

    def robot(self, key: str | None = None) -> Robot:
        """The :class:`robots.Robot` of ``key`` (default: the only robot), loaded on first use."""
        entry = self._entry(key)
        if entry.key not in self._loaded:
            if entry.source == "registry":
                rob = robots.load(entry.name)
            else:
                dirs = self.package_dirs_override if self.package_dirs_override is not None else entry.package_dirs
                rob = robots.from_urdf_text(
                    entry.urdf_text, tcp=entry.tcp_frame, name=entry.name, source=f"session robot {entry.key!r}",
                    package_dirs=tuple(dirs),
                )
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

    # ---------------------------------------------------------------- content
    def add_box(self, name: str, size: Any, pose: Any = None, color: Any = (0.6, 0.6, 0.6, 1.0)) -> BoxObject:
        """Add a static box: ``size`` (3,) edge lengths in m, ``pose`` box centre → world (4, 4), ``color`` RGBA."""
        name = self._free(self.objects, name, "object")
        size_arr = _float_array(size, f"size of box {name!r}", 1, 3)
        if np.any(size_arr <= 0):
            raise InvalidInput(f"size of box {name!r} must be positive edge lengths in m, got {size_arr.tolist()}")
        try:
            rgba = tuple(float(c) for c in np.asarray(color, dtype=float).ravel())
        except (TypeError, ValueError):
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
        q_arr = np.asarray(q, dtype=float)
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
        try:
            arr = np.atleast_2d(np.asarray(points, dtype=float))
        except (TypeError, ValueError) as exc:
            raise InvalidInput(f"points of point set {name!r} must be numbers (n, 3) in m, got {points!r}") from exc
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

    # ---------------------------------------------------------------- (de)serialisation
    def to_document(self) -> tuple[dict, dict[str, np.ndarray], dict[str, str]]:
        """The ``session.json`` document, the arrays by member name, and the text members."""
        arrays: dict[str, np.ndarray] = {}
        texts: dict[str, str] = {}

        def ref(member: str, arr: np.ndarray) -> dict:
            arrays[member] = arr
            return {"member": member, "dtype": arr.dtype.str, "shape": list(arr.shape)}

        doc: dict[str, Any] = {"format": FORMAT_NAME, "version": FORMAT_VERSION, "metadata": self.metadata}
        doc["robots"] = []
        for i, e in enumerate(self.robots.values()):
            urdf_member = None
            if e.urdf_text is not None:
                urdf_member = f"robots/{i}.urdf"
                texts[urdf_member] = e.urdf_text
            doc["robots"].append({
                "key": e.key, "source": e.source, "name": e.name, "tcp_frame": e.tcp_frame,
                "joint_names": list(e.joint_names), "urdf_member": urdf_member, "package_dirs": list(e.package_dirs),
                "base_to_world": ref(f"arrays/robots/{i}/base_to_world.npy", e.base_to_world),
            })
        doc["objects"] = [
            {"name": b.name, "shape": "box", "color": list(b.color),
             "size": ref(f"arrays/objects/{i}/size.npy", b.size),
             "pose": ref(f"arrays/objects/{i}/pose.npy", b.pose)}
            for i, b in enumerate(self.objects.values())
        ]
        doc["trajectories"] = [
            {"name": r.name, "robot": r.robot, "definition": r.definition,
             "t": ref(f"arrays/trajectories/{i}/t.npy", r.t),
             "q": ref(f"arrays/trajectories/{i}/q.npy", r.q),
             "knot_times": ref(f"arrays/trajectories/{i}/knot_times.npy", r.knot_times)}
            for i, r in enumerate(self.trajectories.values())
        ]
        doc["workspaces"] = [
            {"name": r.name, "robot": r.robot,
             "points": ref(f"arrays/workspaces/{i}/points.npy", r.points),
             "manipulability": ref(f"arrays/workspaces/{i}/manipulability.npy", r.manipulability)}
            for i, r in enumerate(self.workspaces.values())
        ]
        doc["points"] = [
            {"name": p.name, "kind": p.kind, "robot": p.robot, "points": ref(f"arrays/points/{i}/points.npy", p.points)}
            for i, p in enumerate(self.point_sets.values())
        ]
        doc["histories"] = [
            {"name": h.name,
             "columns": {k: ref(f"arrays/histories/{i}/{c}.npy", v) for c, (k, v) in enumerate(h.columns.items())}}
            for i, h in enumerate(self.histories.values())
        ]
        if self.reachability:  # optional: sessions without maps keep their documents unchanged
            from .reach_record import record_document

            doc["reachability"] = record_document(self.reachability, ref)
        return doc, arrays, texts

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

    def save(self, path: str | Path) -> Path:
        """Write the session to ``path`` (one zip file, atomically); return the path."""
        doc, arrays, texts = self.to_document()
        payload = json.dumps(doc, indent=1, allow_nan=False, ensure_ascii=False)

        def write(f: Any) -> None:
            with zipfile.ZipFile(f, "w", compression=zipfile.ZIP_DEFLATED) as zf:
                zf.writestr(JSON_MEMBER, payload.encode("utf-8"))
                for member, text in texts.items():
                    zf.writestr(member, text.encode("utf-8"))
                for member, arr in arrays.items():
                    buf = io.BytesIO()
                    np.save(buf, np.ascontiguousarray(arr), allow_pickle=False)
                    zf.writestr(member, buf.getvalue())

        return atomic_write(path, write)


# ---------------------------------------------------------------------------- loading
class _Reader:
    """Validating reader of one session archive; every problem becomes a SessionFormatError."""

    def __init__(self, path: Path, zf: zipfile.ZipFile) -> None:
        self.path = path
        self.zf = zf

    def fail(self, what: str) -> SessionFormatError:
        return SessionFormatError(f"{str(self.path)!r} is not a valid pinarms session: {what}")

    def read(self, member: str) -> bytes:
        try:
            return self.zf.read(member)
        except KeyError:
            raise self.fail(f"member {member!r} is missing (the file is incomplete)") from None
        except (zipfile.BadZipFile, zlib.error, EOFError, OSError) as exc:
            raise self.fail(f"member {member!r} is corrupt ({exc})") from None

    def field(self, obj: Any, key: str, types: type | tuple, where: str) -> Any:
        if not isinstance(obj, dict):
            raise self.fail(f"{where} must be a JSON object")
        if key not in obj:
            raise self.fail(f"{where} lacks the field {key!r}")
        value = obj[key]
        allowed = types if isinstance(types, tuple) else (types,)
        if not isinstance(value, allowed) or (isinstance(value, bool) and bool not in allowed):
            raise self.fail(f"{where}.{key} has the wrong type ({type(value).__name__})")
        return value

    def name(self, obj: Any, where: str) -> str:
        name = self.field(obj, "name", str, where)
        if not _NAME_RE.match(name):
            raise self.fail(f"{where}.name {name!r} is not a valid name")
        return name

    def array(self, obj: Any, key: str, where: str, shape: tuple[int | None, ...], allow_inf: bool = False) -> np.ndarray:
        ref = self.field(obj, key, dict, where)
        member = self.field(ref, "member", str, f"{where}.{key}")
        dtype = self.field(ref, "dtype", str, f"{where}.{key}")
        idx_shape = self.field(ref, "shape", list, f"{where}.{key}")
        if dtype != _F8.str:
            raise self.fail(f"{where}.{key} declares dtype {dtype!r}; this version stores float64 ({_F8.str!r}) only")
        data = self.read(member)
        try:
            arr = np.load(io.BytesIO(data), allow_pickle=False)
        except Exception as exc:  # numpy raises ValueError/EOFError/... on a damaged .npy
            raise self.fail(f"member {member!r} is not a readable .npy array ({exc})") from None
        if not isinstance(arr, np.ndarray) or arr.dtype != _F8:
            raise self.fail(f"member {member!r} has dtype {getattr(arr, 'dtype', '?')}, expected float64")
        if list(arr.shape) != idx_shape:
            raise self.fail(f"member {member!r} has shape {arr.shape}, but session.json says {tuple(idx_shape)}")
        if len(shape) != arr.ndim or any(s is not None and s != a for s, a in zip(shape, arr.shape)):
            want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
            raise self.fail(f"member {member!r} has shape {arr.shape}, expected {want}")
        if np.any(np.isnan(arr)) if allow_inf else not np.all(np.isfinite(arr)):
            raise self.fail(f"member {member!r} holds NaN{'' if allow_inf else ' or infinite'} values")
        arr.flags.writeable = False
        return arr

    def unique(self, seen: set, name: str, where: str) -> None:
        if name in seen:
            raise self.fail(f"{where} name {name!r} appears twice")
        seen.add(name)


def load_session(path: str | Path, *, package_dirs: tuple[str, ...] | list[str] | None = None) -> Session:
    """Read and validate a session file written by :meth:`Session.save`.

    Args:
        path: the session file.
        package_dirs: folders resolving ``package://`` meshes of embedded URDFs (default:
            the folders recorded when the session was saved).

    Raises:
        SessionFormatError: the file is not a zip, is truncated or corrupt, lacks a member,
            has a malformed ``session.json``, arrays of the wrong dtype or shape, or was
            written by a newer format version.
        InvalidInput: ``path`` does not exist or is a folder.
    """
    p = Path(path)
    if not p.is_file():
        raise InvalidInput(f"session file {str(p)!r} does not exist (or is not a file)")
    try:
        zf = zipfile.ZipFile(p, "r")
    except zipfile.BadZipFile:
        raise SessionFormatError(
            f"{str(p)!r} is not a valid pinarms session: not a zip archive, or truncated (its directory is missing)"
        ) from None
    except OSError as exc:
        raise SessionFormatError(f"cannot read session {str(p)!r}: {exc}") from None
    with zf:
        return _read(_Reader(p, zf), package_dirs)


def _read(r: _Reader, package_dirs: Any) -> Session:
    raw = r.read(JSON_MEMBER)
    try:
        doc = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise r.fail(f"{JSON_MEMBER} is not valid UTF-8 JSON ({exc})") from None
    if not isinstance(doc, dict):
        raise r.fail(f"{JSON_MEMBER} must hold a JSON object")
    if doc.get("format") != FORMAT_NAME:
        raise r.fail(f"{JSON_MEMBER} has format {doc.get('format')!r}, expected {FORMAT_NAME!r}")
    version = doc.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise r.fail(f"format version {version!r} is not a positive integer")
    if version > FORMAT_VERSION:
        raise SessionFormatError(
            f"{str(r.path)!r} was written in session format version {version}, newer than this pinarms reads "
            f"(up to {FORMAT_VERSION}); upgrade pinarms to open it"
        )

    s = Session()
    meta = r.field(doc, "metadata", dict, "session")
    for k, typ in (("title", str), ("created", str), ("pinarms_version", str), ("user", dict)):
        r.field(meta, k, typ, "metadata")
    s.metadata = meta
    if package_dirs is not None:
        s.package_dirs_override = tuple(str(d) for d in package_dirs)

    seen: set = set()
    for i, e in enumerate(r.field(doc, "robots", list, "session")):
        where = f"robots[{i}]"
        key = r.field(e, "key", str, where)
        if not _NAME_RE.match(key):
            raise r.fail(f"{where}.key {key!r} is not a valid name")
        r.unique(seen, key, "robot")
        source = r.field(e, "source", str, where)
        if source not in ("registry", "urdf"):
            raise r.fail(f"{where}.source must be 'registry' or 'urdf', got {source!r}")
        joints = r.field(e, "joint_names", list, where)
        if not joints or not all(isinstance(j, str) for j in joints):
            raise r.fail(f"{where}.joint_names must be a non-empty list of strings")
        urdf_member = e.get("urdf_member")
        urdf_text = None
        if source == "urdf":
            if not isinstance(urdf_member, str):
                raise r.fail(f"{where} embeds its URDF but has no urdf_member")
            try:
                urdf_text = r.read(urdf_member).decode("utf-8")
            except UnicodeDecodeError:
                raise r.fail(f"member {urdf_member!r} is not UTF-8 text") from None
        dirs = r.field(e, "package_dirs", list, where)
        s.robots[key] = RobotEntry(
            key=key, source=source, name=r.field(e, "name", str, where), tcp_frame=r.field(e, "tcp_frame", str, where),
            joint_names=tuple(joints), base_to_world=r.array(e, "base_to_world", where, (4, 4)), urdf_text=urdf_text,
            package_dirs=tuple(str(d) for d in dirs),
        )

    def robot_key(obj: dict, where: str, optional: bool = False) -> str | None:
        key = obj.get("robot") if optional else r.field(obj, "robot", str, where)
        if key is None and optional:
            return None
        if key not in s.robots:
            raise r.fail(f"{where}.robot {key!r} is not one of the session's robots ({', '.join(s.robots) or 'none'})")
        return key

    seen = set()
    for i, o in enumerate(r.field(doc, "objects", list, "session")):
        where = f"objects[{i}]"
        name = r.name(o, where)
        r.unique(seen, name, "object")
        if r.field(o, "shape", str, where) != "box":
            raise r.fail(f"{where}.shape {o['shape']!r} is not known (this version knows 'box')")
        color = r.field(o, "color", list, where)
        if len(color) != 4 or not all(isinstance(c, (int, float)) and 0 <= c <= 1 for c in color):
            raise r.fail(f"{where}.color must be 4 RGBA numbers in [0, 1]")
        s.objects[name] = BoxObject(name, r.array(o, "size", where, (3,)), r.array(o, "pose", where, (4, 4)),
                                    tuple(float(c) for c in color))

    seen = set()
    for i, o in enumerate(r.field(doc, "trajectories", list, "session")):
        where = f"trajectories[{i}]"
        name = r.name(o, where)
        r.unique(seen, name, "trajectory")
        key = robot_key(o, where)
        if "definition" not in o or not (o["definition"] is None or isinstance(o["definition"], dict)):
            raise r.fail(f"{where}.definition must be a JSON object or null")
        t = r.array(o, "t", where, (None,))
        q = r.array(o, "q", where, (t.shape[0], s.robots[key].nq))
        if t.shape[0] < 2 or np.any(np.diff(t) <= 0):
            raise r.fail(f"{where}.t must hold at least 2 strictly increasing instants")
        knots = r.array(o, "knot_times", where, (None,))
        s.trajectories[name] = TrajectoryRecord(name, key, t, q, knots, o["definition"])

    seen = set()
    for i, o in enumerate(r.field(doc, "workspaces", list, "session")):
        where = f"workspaces[{i}]"
        name = r.name(o, where)
        r.unique(seen, name, "workspace")
        key = robot_key(o, where)
        pts = r.array(o, "points", where, (None, 3))
        w = r.array(o, "manipulability", where, (pts.shape[0],))
        s.workspaces[name] = WorkspaceRecord(name, key, pts, w)

    seen = set()
    for i, o in enumerate(r.field(doc, "points", list, "session")):
        where = f"points[{i}]"
        name = r.name(o, where)
        r.unique(seen, name, "point set")
        kind = r.field(o, "kind", str, where)
        if kind not in _POINT_KINDS:
            raise r.fail(f"{where}.kind must be one of {_POINT_KINDS}, got {kind!r}")
        s.point_sets[name] = PointSet(name, kind, robot_key(o, where, optional=True), r.array(o, "points", where, (None, 3)))

    seen = set()
    for i, o in enumerate(r.field(doc, "histories", list, "session")):
        where = f"histories[{i}]"
        name = r.name(o, where)
        r.unique(seen, name, "history")
        cols_doc = r.field(o, "columns", dict, where)
        if "best" not in cols_doc:
            raise r.fail(f"{where}.columns lacks 'best'")
        cols = {k: r.array(cols_doc, k, f"{where}.columns", (None,), allow_inf=True) for k in cols_doc}
        if len({c.shape[0] for c in cols.values()}) != 1:
            raise r.fail(f"{where}.columns have different lengths")
        s.histories[name] = HistoryRecord(name, cols)

    from .reach_record import read_records

    s.reachability = read_records(r, doc, robot_key)
    return s
