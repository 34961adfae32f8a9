"""What a loaded reachability map must satisfy: its attributes and arrays checked against each other.

:func:`~pinarms.robots.reach.reach_io.load_reachability` receives the attributes and the raw
arrays of a map file from its reader process (dtypes and shapes already agreed); here they
become a :class:`ReachabilityMap` only if they make one: the format and version, the robot's
joints and limits, proper rotations numbered in groups, strictly increasing voxel indices,
a reachability index that follows from the reached bits, and one stored IK solution per
reached pose, inside the joint limits. Each problem is a :class:`ReachabilityFileError`
naming the member and what is wrong.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from pinarms.errors import PinarmsError
from pinarms.robots.reach.orientations import MAX_ORIENTATIONS, OrientationSet
from pinarms.robots.reach.reach_digest import PosesDigest, map_checksum
from pinarms.robots.reach.reach_map import MAX_GRID_VOXELS, PoseSolutions, ReachabilityMap
from pinarms.robots.reach.reach_write import FORMAT_NAME, FORMAT_VERSION

__all__ = ["ReachabilityFileError", "MapChecker", "check_map", "MAX_JOINTS", "MAX_TEXT", "MIN_RESOLUTION",
           "MAX_RESOLUTION", "MAX_EXTENT"]

#: Longest text attribute a map may hold [characters].
MAX_TEXT = 1_000_000
#: Most joints a map's robot may have.
MAX_JOINTS = 64
#: Voxel edges a map may have [m], and how far its grid may reach from the robot's base [m].
MIN_RESOLUTION = 1e-4
MAX_RESOLUTION = 10.0
MAX_EXTENT = 1000.0


class ReachabilityFileError(PinarmsError):
    """A reachability map file is not one pinarms can trust: what is wrong and where is in the message."""


class MapChecker:
    """The attributes and arrays the reader sent; each problem becomes a :class:`ReachabilityFileError`."""

    def __init__(self, path: Path, attrs: dict, arrays: dict[str, np.ndarray], wall: str = "") -> None:
        self.path, self.attrs, self.arrays, self.wall = path, attrs, arrays, wall

    def fail(self, what: str) -> ReachabilityFileError:
        return ReachabilityFileError(f"{str(self.path)!r} is not a valid pinarms reachability map: {what}")

    def attr(self, group: str, key: str, kind: type) -> Any:
        where = "the file" if group == "/" else group
        values = self.attrs.get(group)
        value = values.get(key) if isinstance(values, dict) else None
        ok = {str: lambda v: isinstance(v, str) and len(v) <= MAX_TEXT, bool: lambda v: isinstance(v, bool),
              int: lambda v: isinstance(v, int) and not isinstance(v, bool),
              float: lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
              list: lambda v: isinstance(v, list) and len(v) <= 16 and all(isinstance(x, int) for x in v)}[kind]
        if not ok(value):
            raise self.fail(f"attribute {key!r} of {where} is missing or not a {kind.__name__}")
        return float(value) if kind is float else value

    def json(self, group: str, key: str, kind: type) -> Any:
        where = "the file" if group == "/" else group
        try:
            value = json.loads(self.attr(group, key, str))
        except (json.JSONDecodeError, RecursionError):
            raise self.fail(f"attribute {key!r} of {where} is not valid JSON") from None
        if not isinstance(value, kind):
            raise self.fail(f"attribute {key!r} of {where} must be a JSON {kind.__name__}")
        return value

    def finite(self, name: str, *, nan_ok: bool = False) -> np.ndarray:
        arr = self.arrays[name]
        bad = np.isinf(arr) if nan_ok else ~np.isfinite(arr)
        if np.any(bad):
            raise self.fail(f"dataset /{name} holds {'infinite' if nan_ok else 'NaN or infinite'} values")
        return arr


def check_map(r: MapChecker, want_solutions: bool) -> ReachabilityMap:
    """The map the reader sent, checked (``want_solutions``: also its stored IK solutions, when present)."""
    fmt, version = r.attr("/", "format", str), r.attr("/", "version", int)
    if fmt != FORMAT_NAME or not 1 <= version <= FORMAT_VERSION:
        raise r.fail(f"format {fmt!r} version {version} is not this pinarms' map format")
    sha = r.attr("/", "urdf_sha256", str)
    if len(sha) != 64 or any(c not in "0123456789abcdef" for c in sha):
        raise r.fail("urdf_sha256 is not a SHA-256 hex digest")
    solver = r.attr("/", "solver", str)
    if solver not in ("analytic", "numerical"):
        raise r.fail(f"solver must be 'analytic' or 'numerical', got {solver!r}")
    manip = r.attr("/", "manipulability", str)
    if manip not in ("full", "position"):
        raise r.fail(f"manipulability must be 'full' or 'position', got {manip!r}")
    resolution = r.attr("/", "resolution", float)
    if not (np.isfinite(resolution) and MIN_RESOLUTION <= resolution <= MAX_RESOLUTION):
        raise r.fail(f"resolution must be a length from {MIN_RESOLUTION:g} to {MAX_RESOLUTION:g} m, got {resolution!r}")
    shape = r.attr("/", "shape", list)
    if len(shape) != 3 or min(shape) < 1 or math.prod(shape) > MAX_GRID_VOXELS:
        raise r.fail(f"shape must be 3 positive integers with at most {MAX_GRID_VOXELS} voxels, got {shape}")
    origin = r.finite("grid/origin")
    if max(shape) * resolution > MAX_EXTENT or np.any(np.abs(origin) > MAX_EXTENT):
        raise r.fail(f"the grid (origin {origin.tolist()} m, {shape} voxels of {resolution:g} m) reaches beyond "
                     f"{MAX_EXTENT:g} m of the robot's base")
    joint_names = r.json("/robot", "joint_names", list)
    nq = len(joint_names)
    if not (1 <= nq <= MAX_JOINTS) or not all(isinstance(j, str) and 0 < len(j) <= 200 for j in joint_names):
        raise r.fail(f"/robot joint_names must list 1 to {MAX_JOINTS} joint names")
    lower, upper = r.finite("robot/joint_lower"), r.finite("robot/joint_upper")
    if lower.size != nq:
        raise r.fail(f"dataset /robot/joint_lower holds {lower.size} limits for the {nq} joint names")
    if np.any(lower > upper):
        raise r.fail("/robot joint limits have lower > upper")
    oset = _check_orientations(r)
    flat, reached, index, best = _check_voxels(r, oset, math.prod(shape))
    sols = _check_poses(r, flat, reached, lower, upper) if want_solutions and "poses/voxel" in r.arrays else None
    m = ReachabilityMap(
        robot=r.attr("/", "robot", str), urdf_sha256=sha, tcp_frame=r.attr("/", "tcp_frame", str),
        joint_names=tuple(joint_names), joint_lower=lower, joint_upper=upper, solver=solver,
        manipulability_kind=manip, origin=origin, resolution=resolution,
        shape=(int(shape[0]), int(shape[1]), int(shape[2])), orientations=oset, voxels=flat, reached=reached,
        index=index, best_manipulability=best, solutions=sols, parameters=r.json("/", "parameters", dict),
        reader_wall=r.wall,
    )
    _check_checksums(r, m, sols)
    return m


def _check_checksums(r: MapChecker, m: ReachabilityMap, sols: PoseSolutions | None) -> None:
    """The values read against the checksums the writer stored (:mod:`~.reach_digest`)."""
    stored = r.attrs["/"].get("checksum")
    if not isinstance(stored, str):
        raise r.fail("it holds no checksum of its values (written by an older pinarms): rebuild it with "
                     "reachability_map(ReachabilityRequest(..., out=...)) or save_reachability")
    if stored != map_checksum(m):
        raise r.fail("its values do not match the checksum stored with them (a byte was changed or damaged): "
                     "rebuild the map")
    if sols is None:
        return
    digest = PosesDigest()
    digest.update(sols.voxel, sols.orientation, sols.q, sols.manipulability)
    if r.attrs["/"].get("poses_checksum") != digest.hexdigest():
        raise r.fail("its stored solutions (/poses) do not match their checksum (a byte was changed or damaged, or "
                     "the checksum is missing): rebuild the map, or load it with solutions=False")


def _check_orientations(r: MapChecker) -> OrientationSet:
    kind = r.attr("/orientations", "kind", str)
    if kind not in ("so3", "tool_axis"):
        raise r.fail(f"/orientations kind must be 'so3' or 'tool_axis', got {kind!r}")
    roll_free = r.attr("/orientations", "roll_free", bool)
    n_groups = r.attr("/orientations", "n_groups", int)
    oparams = r.json("/orientations", "parameters", dict)
    rot = r.finite("orientations/rotations")
    M = rot.shape[0]
    if not (1 <= M <= MAX_ORIENTATIONS) or not (1 <= n_groups <= MAX_ORIENTATIONS):
        raise r.fail(f"/orientations holds {M} rotations in {n_groups} groups; expected 1 to {MAX_ORIENTATIONS}")
    ortho = np.abs(rot @ np.swapaxes(rot, 1, 2) - np.eye(3)).max()
    if ortho > 1e-9 or np.any(np.linalg.det(rot) < 0.0):
        raise r.fail("/orientations/rotations holds a matrix that is not a proper rotation")
    group = r.arrays["orientations/group"].astype(np.int64)  # M ≤ 10⁵ entries
    if np.any(group < 0) or np.any(group >= n_groups) or np.any(np.diff(group) < 0) or np.unique(group).size != n_groups:
        raise r.fail("/orientations/group must number the directions 0..n_groups-1 in order, each used")
    directions, tool_axis = r.finite("orientations/directions"), r.finite("orientations/tool_axis")
    if directions.shape[0] != n_groups:
        raise r.fail(f"dataset /orientations/directions holds {directions.shape[0]} rows for {n_groups} groups")
    if kind == "so3" and (n_groups != M or roll_free):
        raise r.fail("/orientations of kind 'so3' must have one group per rotation and roll_free false")
    return OrientationSet(kind, rot, group, n_groups, roll_free, tool_axis, directions, oparams)


def _check_voxels(r: MapChecker, o: OrientationSet, n_grid: int) -> tuple[np.ndarray, ...]:
    flat = r.arrays["voxels/flat"]
    V = flat.size
    if V and (flat[0] < 0 or flat[-1] >= n_grid or np.any(flat[1:] <= flat[:-1])):
        raise r.fail(f"/voxels/flat must be strictly increasing flat indices in [0, {n_grid})")
    index = r.finite("voxels/index")
    best = r.finite("voxels/best_manipulability", nan_ok=True)
    reached_u1 = r.arrays["voxels/reached"]
    if reached_u1.size and reached_u1.max() > 1:
        raise r.fail("/voxels/reached must hold only 0 and 1")
    reached = reached_u1.view(bool)  # 0/1 bytes are valid booleans: no copy
    M, G = reached.shape[1], o.n_groups
    if o.roll_free:
        per_group = np.zeros((V, G), dtype=bool)
        for k in range(M):
            per_group[:, o.group[k]] |= reached[:, k]
        expect = per_group.sum(axis=1) / G
    else:
        expect = np.count_nonzero(reached, axis=1) / M
    if not np.array_equal(expect, index):
        row = int(np.flatnonzero(expect != index)[0])
        raise r.fail(f"/voxels/index does not follow from /voxels/reached (row {row}: {index[row]!r} vs {expect[row]!r})")
    any_reached = reached.any(axis=1)
    if np.any(np.isnan(best) == any_reached) or np.any(best[any_reached] < 0):
        raise r.fail("/voxels/best_manipulability must be >= 0 where a pose is reached and NaN elsewhere")
    n_reached = r.attrs["/"].get("n_reached")  # optional (files of pinarms 0.1 lack it)
    if n_reached is not None and (not isinstance(n_reached, int) or n_reached != int(np.count_nonzero(reached))):
        raise r.fail(f"the file declares n_reached = {n_reached} but /voxels/reached marks "
                     f"{int(np.count_nonzero(reached))} poses")
    return flat, reached, index, best


def _check_poses(r: MapChecker, flat: np.ndarray, reached: np.ndarray, lower: np.ndarray,
                 upper: np.ndarray) -> PoseSolutions:
    pv, po_i4 = r.arrays["poses/voxel"], r.arrays["poses/orientation"]
    q, w = r.finite("poses/q"), r.finite("poses/manipulability")
    K, (V, M) = pv.size, reached.shape
    rows = np.searchsorted(flat, pv)
    po = po_i4.astype(np.int64)
    ok = (rows < V) & (po >= 0) & (po < M)
    ok[ok] &= flat[rows[ok]] == pv[ok]
    if not ok.all():
        raise r.fail(f"/poses entry {int(np.flatnonzero(~ok)[0])} names a voxel or orientation the map does not have")
    key = rows * M + po
    del rows, po, ok
    hit = reached.reshape(-1)[key]
    if not hit.all():
        raise r.fail(f"/poses entry {int(np.flatnonzero(~hit)[0])} stores a solution of a pose marked unreached")
    seen = np.zeros(V * M, dtype=bool)
    seen[key] = True
    if int(np.count_nonzero(seen)) != K or K != int(np.count_nonzero(reached)):
        raise r.fail("/poses must hold exactly one solution per reached pose")
    del seen, key
    out = (q < lower - 1e-9) | (q > upper + 1e-9)
    if out.any():
        raise r.fail(f"/poses/q entry {int(np.flatnonzero(out.any(axis=1))[0])} lies outside the joint limits")
    if np.any(w < 0):
        raise r.fail("/poses/manipulability holds a negative value")
    return PoseSolutions(pv, po_i4, q, w)
