"""Reading controller trajectory files back: JointTrajectory YAML and pinarms' trajectory CSV.

A file may come from anyone, so it is read behind bounds (docs/files.md, "Controller
trajectory"): a regular file of at most :data:`MAX_FILE_BYTES`, checked by ``stat`` before a
byte is read; YAML parsed by PyYAML's safe loader restricted further to what a
``JointTrajectory`` needs (mappings, sequences, strings, integers, floats, booleans and null:
no ``!!binary``, ``!!timestamp``, ``!!set``, ``!!omap``, ``!!python/...`` tags and no aliases); at most :data:`~.trajectory.MAX_POINTS` points; every number finite. Anything else is
:class:`~.errors.TrajectoryFileError` naming the file and what is wrong.
"""

from __future__ import annotations

import csv
import os
from typing import Any, Sequence

import numpy as np

from pinarms.files import read_bounded_text

from pinarms.export.errors import JointMismatch, TrajectoryFileError
from pinarms.export.trajectory import MAX_POINTS, ControllerTrajectory

__all__ = ["read_trajectory_yaml", "read_trajectory_csv", "MAX_FILE_BYTES", "MAX_JOINTS"]

#: Largest trajectory file read [bytes] (a 500 Hz, 6-joint motion of 10 min is about 40 MB).
MAX_FILE_BYTES = 256 * 1024 * 1024
#: Most joints one file may name.
MAX_JOINTS = 1000


def _read_text(path: Any) -> str:
    """The UTF-8 text of regular file ``path`` (a FIFO or a device refused unopened), at most
    :data:`MAX_FILE_BYTES` bytes (:func:`pinarms.files.read_bounded_text`)."""
    return read_bounded_text(path, MAX_FILE_BYTES, "trajectory file", error=TrajectoryFileError)


def _loader_class() -> type:
    """PyYAML's safe loader with only the plain types (libyaml's parser when present)."""
    import yaml

    base = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

    class Loader(base):  # type: ignore[valid-type, misc]
        yaml_constructors = {tag: base.yaml_constructors[tag] for tag in (
            "tag:yaml.org,2002:null", "tag:yaml.org,2002:bool", "tag:yaml.org,2002:int", "tag:yaml.org,2002:float",
            "tag:yaml.org,2002:str", "tag:yaml.org,2002:seq", "tag:yaml.org,2002:map")}
        yaml_multi_constructors: dict = {}

    def refuse(loader, node):
        raise yaml.YAMLError(f"the tag {node.tag} is not allowed in a trajectory file (line {node.start_mark.line + 1})")

    Loader.add_constructor(None, refuse)
    return Loader


def _refuse_aliases(node: Any) -> None:
    """An alias (``*name``) composes to a node met twice: refused before anything is constructed."""
    import yaml

    seen: set[int] = set()
    stack = [node]
    while stack:
        item = stack.pop()
        if id(item) in seen:
            raise yaml.YAMLError(f"an alias (*name) is not allowed in a trajectory file (line {item.start_mark.line + 1})")
        seen.add(id(item))
        if isinstance(item, yaml.SequenceNode):
            stack.extend(item.value)
        elif isinstance(item, yaml.MappingNode):
            stack.extend(v for pair in item.value for v in pair)


def _yaml_document(path: Any) -> Any:
    import yaml

    text = _read_text(path)
    loader = _loader_class()(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _refuse_aliases(node)
        return loader.construct_document(node)
    except yaml.YAMLError as exc:
        raise TrajectoryFileError(f"trajectory file {os.fspath(path)!r} is not valid YAML for a trajectory: "
                                  f"{' '.join(str(exc).split())}") from exc
    finally:
        loader.dispose()


def _numbers(values: Any, n: int, what: str) -> list[float]:
    if not isinstance(values, list) or len(values) != n:
        raise ValueError(f"{what} must be a list of {n} numbers")
    out = []
    for v in values:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(float(v)):
            raise ValueError(f"{what} holds {v!r}: every value must be a finite number")
        out.append(float(v))
    return out


def _time_ns(stamp: Any, k: int) -> int:
    sec, nanosec = (stamp.get("sec"), stamp.get("nanosec")) if isinstance(stamp, dict) else (None, None)
    if not all(isinstance(v, int) and not isinstance(v, bool) for v in (sec, nanosec)) \
            or not 0 <= sec < 2**31 or not 0 <= nanosec < 1_000_000_000:
        raise ValueError(f"point {k}: time_from_start must be {{sec: 0 to 2**31 - 1, nanosec: 0 to 999999999}}")
    return sec * 1_000_000_000 + nanosec


def _trajectory(doc: Any) -> ControllerTrajectory:
    if not isinstance(doc, dict) or not isinstance(doc.get("joint_names"), list) or \
            not isinstance(doc.get("points"), list):
        raise ValueError("not a JointTrajectory document: joint_names and points (lists) are needed")
    names = doc["joint_names"]
    if not all(isinstance(n, str) for n in names) or not 0 < len(names) <= MAX_JOINTS:
        raise ValueError(f"joint_names must be 1 to {MAX_JOINTS} strings")
    points = doc["points"]
    if len(points) > MAX_POINTS:
        raise ValueError(f"{len(points)} points, more than the {MAX_POINTS} allowed")
    n = len(names)
    rows: dict[str, list] = {"positions": [], "velocities": [], "accelerations": []}
    ns = []
    for k, p in enumerate(points):
        if not isinstance(p, dict):
            raise ValueError(f"point {k} is not a mapping")
        for key, row in rows.items():
            row.append(_numbers(p.get(key), n, f"point {k}: {key}"))
        ns.append(_time_ns(p.get("time_from_start"), k))
    arrays = [np.array(rows[key], dtype=float).reshape(len(points), n) for key in rows]
    return ControllerTrajectory(tuple(names), np.array(ns, dtype=np.int64), *arrays)


def _expect(names: tuple[str, ...], joint_names: Any, path: Any) -> None:
    if joint_names is not None and tuple(joint_names) != names:
        raise JointMismatch(f"{path}: the file's joints {list(names)} are not the expected {list(joint_names)}")


def read_trajectory_yaml(path: str | os.PathLike, *, joint_names: Sequence[str] | None = None) -> ControllerTrajectory:
    """Read a file of :func:`~.trajectory.write_trajectory_yaml` (any JointTrajectory YAML with those fields).

    Raises:
        TrajectoryFileError: not a regular file, too large, not UTF-8, not valid YAML, a tag,
            alias or field the format does not have, a number that is not finite (module doc).
        JointMismatch: ``joint_names`` given and the file's differ.
    """
    doc = _yaml_document(path)
    try:
        traj = _trajectory(doc)
    except ValueError as exc:
        raise TrajectoryFileError(f"trajectory file {os.fspath(path)!r}: {exc}") from exc
    _expect(traj.joint_names, joint_names, path)
    return traj


def read_trajectory_csv(path: str | os.PathLike, *, joint_names: Sequence[str] | None = None) -> ControllerTrajectory:
    """Read a file of :func:`~.trajectory.write_trajectory_csv`.

    Raises:
        TrajectoryFileError: as :func:`read_trajectory_yaml`, or a header, row or field that is
            not the format's (a field over the ``csv`` module's 128 KiB limit included).
        JointMismatch: ``joint_names`` given and the file's differ.
    """
    text = _read_text(path)
    try:
        rows = list(csv.reader(text.splitlines()))
    except csv.Error as exc:
        raise TrajectoryFileError(f"trajectory file {os.fspath(path)!r} is not CSV: {exc}") from exc
    header = rows[0] if rows else []
    n = (len(header) - 1) // 3
    names = tuple(h[len("pos:"):] for h in header[1 : 1 + n])
    if not header or header[0] != "time_s" or len(header) != 1 + 3 * n or n < 1 or \
            header[1 : 1 + n] != [f"pos:{x}" for x in names] or \
            header[1 + n :] != [f"vel:{x}" for x in names] + [f"acc:{x}" for x in names]:
        raise TrajectoryFileError(f"{os.fspath(path)!r} is not a pinarms trajectory CSV (header {header[:4]}...)")
    if len(rows) - 1 > MAX_POINTS:
        raise TrajectoryFileError(f"{os.fspath(path)!r} has {len(rows) - 1} rows, more than the {MAX_POINTS} allowed")
    values = np.empty((len(rows) - 1, 1 + 3 * n))
    for k, row in enumerate(rows[1:]):
        try:
            values[k] = [float(v) for v in row] if len(row) == 1 + 3 * n else []
        except ValueError as exc:
            raise TrajectoryFileError(f"{os.fspath(path)!r} row {k + 1}: {1 + 3 * n} numbers expected "
                                      f"({' '.join(str(exc).split())[:120]})") from exc
    if not np.all(np.isfinite(values)):
        raise TrajectoryFileError(f"{os.fspath(path)!r}: every value must be a finite number")
    _expect(names, joint_names, path)
    ns = np.round(values[:, 0] * 1e9).astype(np.int64)
    return ControllerTrajectory(names, ns, values[:, 1 : 1 + n], values[:, 1 + n : 1 + 2 * n], values[:, 1 + 2 * n :])
