"""Distance tables for pairs of geometries close in the kinematic chain: a proven lower bound of
their distance, looked up from the joint angles, for :mod:`.cover`'s screens.

**Which pairs** (:func:`table_paths`, :func:`loose_pairs`; :func:`.cover.link_cover` passes an
arm's own pairs). Two geometries whose relative placement depends on at most two revolute
joints (the joints on the tree path between their parent joints: the UR5's forearm and wrist_2
on ``q4, q5``, wrist_1 and wrist_3 on ``q5, q6``, its base and upper arm on ``q1, q2``), at
least one of them a triangle mesh (spheres round a slice of a housing overshoot its flat end by
nearly its radius; the covers of primitives are already tight), and that the sphere cover
leaves loose: open on at least :data:`NEED_SHARE` of :data:`NEED_STATES` seeded random
configurations where coal finds the pair 2 mm beyond a threshold of :data:`NEED_THRESHOLDS`.
A pair of an arm and a fixture is left to the cover: its table would be built again at every
placement of the arm's base (a layout search). No Panda or AUBO-i3 scene has such a pair
(primitives, a mesh base alone): their covers are unchanged.

**What is tabulated.** Each side is cut into convex **parts**: a mesh's triangles into pieces
(:func:`.mesh_cover.split_triangles`) grouped in slabs of at most :data:`PART_LENGTH` along its
longest side, each slab's convex hull (a piece is a combination of its vertices, so the hulls
hold the mesh); a primitive is itself. A side that turns about a path joint's axis (its own
joint, or the first joint below it) is replaced by the cylinder about that axis holding it when
that keeps, at :data:`TURN_SAMPLES` seeded angles, at least :data:`TURNING` of the parts'
distance less 0.5 mm (the UR5's wrist_3 flange about ``q6``): the cylinder is the same at every
angle of that joint, and the table loses that axis. The distance between two convex parts (GJK,
µs) is a lower bound of the geometries'; where the parts prove at most 1 mm at a cell fine enough
(:data:`EXACT_LOSS`), the meshes' exact distance (coal, as the exact check) is taken when larger.

**The bound over a cell of angles.** Turning joint ``j`` by ``Δ`` moves every point of the
part it carries (relative to the other side) by at most ``λ_j |Δ|``, ``λ_j`` the largest
distance of the part's points from the axis of ``j`` over every angle of the joint below ``j``
(for a point ``y`` in that joint's frame: the distance of its axial component's image from
``j``'s axis plus its radial length). The distance changes by at most ``Σ λ_j |Δ_j|`` along any
path in angle space, so a cell ``c ± w/2`` keeps at least ``min over part pairs of d_pq(c) −
Σ λ_j(pq) w_j / 2`` — each part with its own levers: a housing near a joint moves little when
that joint turns, the far end of a long link much. The cells form a k-d tree over ``[−π, π)²``
(revolute joints periodic in 2π; the joint limits are not used): a cell is split in half along
the axis with the larger ``λ_j w_j`` of its binding part pair while that loss exceeds
:data:`TOL` + :data:`REL` · ``d`` (fine near contact, coarse far away), a cell in contact only
down to :data:`CONTACT_TOL`, none once its bound exceeds :data:`CAP`, and no table beyond
:data:`MAX_NODES` nodes (its cells stay coarser, their bounds proven). A child keeps, per part
pair, the larger of its own and its parent's bound; pairs whose parent bound is above the
node's least so far are not recomputed. Each leaf stores its bound less :data:`SLACK` (GJK's
tolerance, the angles' rounding).

**In the kernels** (:mod:`.cover_kernel`: ``cov[14]`` the tables, ``grp[11]`` each pair's table
or −1): a pair with a table takes the larger of the table's bound and its cover's, the table
first (a pair it keeps above the threshold, or above the running excess, costs no cover test);
the angles come from the joint frames already placed (``atan2`` of two dot products; no joint
values are passed, the kernels' signatures are unchanged). Any lower bound at a state keeps the
edge proofs (the Lipschitz ladder, the per-group levers) valid: they need only ``d ≥ bound``
at their samples.

**Measured** (2 cores shared, load 1.5–2.7): the share of 600 seeded clear states the cover
proves whole goes from 21 % to 77 % on ``ur5_table_box`` and from 19 % to 81 % on
``ur5_shelf`` (MotionChecker margin 10 mm, self margin 0; none called clear that coal finds
closer). Four tables per UR5, 84 000 nodes (2 MB); built cold in 4 s, from the disk cache in
0.03 s. Tables are kept per content in memory and on disk, in the user's cache folder
(:mod:`.disk_cache`: ``$PINARMS_CACHE_DIR``, ``$XDG_CACHE_HOME/pinarms`` or ``~/.cache/pinarms``,
then ``pair_tables/<sha256>.npz``), never in the package folder. The name digests the content
**and** the source files that build a table (this module, :mod:`._table_build`,
:mod:`.mesh_cover`) and coal's version: a table built by other code is never found. A file is
read with ``allow_pickle=False`` and checked before use: names, types, shapes, the tree's links,
then its **values** — at :data:`CHECK_STATES` seeded random configurations of the cell its bound
must not exceed coal's exact distance of the pair (+ :data:`CHECK_TOL`). A file that fails (a
stale, damaged or planted table) is built again and overwritten, never used; a bad or
unwritable file only costs the build (4 s for the UR5's four). The content is taken relative to the chain's root joint and the axes as positions on
the pair's path, so a table serves every placement of the arm and every arm of the same model
(the UR5 on the shelf's pedestal reuses the table scene's). Angles in rad, lengths in m.
"""

from __future__ import annotations

import hashlib
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pinarms.robots.cell.cell_model import CellModel

from pinarms.robots.cell._table_build import (
    CAP,
    CONTACT_TOL,
    EXACT_LOSS,
    MAX_NODES,
    MAX_PARTS,
    PART_LENGTH,
    REL,
    SLACK,
    TOL,
    TURN_NEAR,
    TURN_SAMPLES,
    TURNING,
    build_table,
    geometry_points,
    turning_sides,
    axis_arrays,
)
from pinarms.robots.cell import _table_build, mesh_cover
from pinarms.robots.cell.disk_cache import cache_folder, code_digest, read_arrays, write_arrays
from pinarms.robots.cell.mesh_cover import mesh_arrays

__all__ = [
    "CAP",
    "CONTACT_TOL",
    "EXACT_LOSS",
    "MAX_NODES",
    "MAX_PARTS",
    "PART_LENGTH",
    "REL",
    "SLACK",
    "TOL",
    "TURNING",
    "TURN_NEAR",
    "TURN_SAMPLES",
    "PairTables",
    "no_tables",
    "pair_tables",
    "table_paths",
]

#: :func:`loose_pairs`: seeded random configurations, the share of them a pair's cover must leave open
#: where it is clear, and the thresholds [m] tried.
NEED_STATES = 256
NEED_SHARE = 0.01
NEED_THRESHOLDS = (0.0, 0.01)
#: A table read from the disk is used only if, at this many seeded random configurations of the cell, its bound
#: is at most coal's exact distance of the pair plus :data:`CHECK_TOL` [m].
CHECK_STATES = 48
CHECK_TOL = 1e-7
_VERSION = 3
_MEMORY: dict = {}
_LOOSE: dict = {}
#: The source files whose code builds a table: their digest is part of every table's name on disk.
_CODE = (Path(__file__), Path(_table_build.__file__), Path(mesh_cover.__file__))


@dataclass(frozen=True, eq=False)
class PairTables:
    """The tables of a cell (module docstring), for the kernels' :meth:`arrays`.

    Attributes:
        pair_a, pair_b: ``(T,)`` geometry indices of each table's pair.
        joint, parent: ``(T, 2)`` the joint of each axis and its parent (−1: no such axis).
        e, ea, eb: ``(T, 2, 3)`` a unit vector across the joint's axis in its frame, and ``M_R e``,
            ``M_R (u × e)`` in its parent's frame: the angle is ``atan2(R_par eb · R e, R_par ea · R e)``.
        root: ``(T,)`` each table's root node; ``child``: ``(N,)`` first of two children (−1: a leaf);
            ``split``: ``(N,)`` the axis halved; ``low``: ``(N,)`` the bound [m] over the node's cell.
        seconds: build time of the tables not found in a cache.
    """

    pair_a: np.ndarray
    pair_b: np.ndarray
    joint: np.ndarray
    parent: np.ndarray
    e: np.ndarray
    ea: np.ndarray
    eb: np.ndarray
    root: np.ndarray
    child: np.ndarray
    split: np.ndarray
    low: np.ndarray
    seconds: float = 0.0

    def arrays(self) -> tuple:
        """The arrays in the kernels' order (:func:`.cover_kernel.table_low`)."""
        return (self.joint, self.parent, self.ea, self.eb, self.e, self.root, self.child, self.split, self.low)

    def of_pairs(self, pair_a: np.ndarray, pair_b: np.ndarray) -> np.ndarray:
        """``(P,)`` the table of each pair ``(pair_a[k], pair_b[k])`` (either order), −1 where none."""
        index = {(int(a), int(b)): t for t, (a, b) in enumerate(zip(self.pair_a, self.pair_b))}
        index.update({(b, a): t for (a, b), t in list(index.items())})
        return np.array([index.get((int(a), int(b)), -1) for a, b in zip(pair_a, pair_b)], dtype=np.int64)

    def bound(self, t: int, angles: np.ndarray) -> np.ndarray:
        """``(N,)`` table ``t``'s bound [m] at joint angles ``angles (N, 2)`` [rad] (numpy; its unused axis ignored)."""
        return _lookup(self.child, self.split, self.low, int(self.root[t]), angles)


def _lookup(child: np.ndarray, split: np.ndarray, low: np.ndarray, root: int, angles: np.ndarray) -> np.ndarray:
    """``(N,)`` the bound [m] of the tree from node ``root`` at joint angles ``angles (N, 2)`` [rad]."""
    A = np.atleast_2d(np.asarray(angles, dtype=float))
    out = np.empty(A.shape[0])
    for i, v in enumerate(A):
        v = np.mod(v + math.pi, 2.0 * math.pi) - math.pi
        lo, w, n = np.full(2, -math.pi), np.full(2, 2.0 * math.pi), root
        while child[n] >= 0:
            s = int(split[n])
            w[s] *= 0.5
            up = v[s] >= lo[s] + w[s]
            lo[s] += w[s] if up else 0.0
            n = int(child[n]) + int(up)
        out[i] = low[n]
    return out


def no_tables() -> PairTables:
    """No tables (a cover built without them)."""
    i2, f3 = np.zeros((0, 2), dtype=np.int64), np.zeros((0, 2, 3))
    i1 = np.zeros(0, dtype=np.int64)
    return PairTables(i1, i1, i2, i2, f3, f3, f3, i1, i1, i1, np.zeros(0))


def _chain(parent: np.ndarray, j: int) -> list[int]:
    out = []
    while j > 0:
        out.append(j)
        j = int(parent[j])
    return out


def table_paths(cell: CellModel, pairs: Sequence[tuple[int, int]]) -> list[tuple[int, int, list[int], list[int]]]:
    """The pairs ``(a, b)`` that get a table, each with its path joints top-down on ``a``'s side and on
    ``b``'s (at most two in all, revolute, at least one of the two geometries a mesh)."""
    objs = cell.collision_model.geometryObjects
    bp = cell.batched_placements
    parent = np.asarray(bp.parent)
    out = []
    for a, b in pairs:
        a, b = int(a), int(b)
        ca, cb = _chain(parent, int(objs[a].parentJoint)), _chain(parent, int(objs[b].parentJoint))
        side_a = [j for j in ca if j not in cb][::-1]
        side_b = [j for j in cb if j not in ca][::-1]
        path = side_a + side_b
        if not 1 <= len(path) <= 2 or not all(bool(bp.revolute[j]) and bp.scale[j] != 0.0 for j in path):
            continue
        if mesh_arrays(objs[a].geometry) is None and mesh_arrays(objs[b].geometry) is None:
            continue
        out.append((a, b, side_a, side_b))
    return out


def _key(cell: CellModel, a: int, b: int, side_a: list, side_b: list) -> str:
    """A digest of what a table depends on: both geometries (vertices, triangles or shape and size, placements),
    the path joints' placements and axes, the build's constants, its code (:data:`_CODE`) and coal's version."""
    import coal

    bp = cell.batched_placements
    objs = cell.collision_model.geometryObjects
    h = hashlib.sha256(repr((_VERSION, TOL, REL, CAP, CONTACT_TOL, TURNING, TURN_SAMPLES, TURN_NEAR, SLACK, MAX_NODES,
                             EXACT_LOSS, PART_LENGTH, MAX_PARTS, len(side_a), len(side_b), code_digest(_CODE),
                             getattr(coal, "__version__", ""))).encode())
    path = side_a + side_b
    root = next((j for j in path if int(bp.parent[j]) == 0), None)
    if root is not None:  # a chain from the world: all relative to the root joint's placement (a moved base)
        G = np.eye(4)
        G[:3, :3], G[:3, 3] = bp.M_R[root], bp.M_p[root]
        G = np.linalg.inv(G)
    for g in (a, b):
        obj = objs[g]
        got = mesh_arrays(obj.geometry)
        if got is None:
            h.update(geometry_points(obj).tobytes())
        else:
            h.update(got[0].tobytes() + got[1].tobytes())
        M = np.asarray(obj.placement.homogeneous, dtype=float)
        h.update(np.round(G @ M if root is not None and int(obj.parentJoint) == 0 else M, 12).tobytes())
    for j in path:
        M = [] if j == root else [np.asarray(bp.M_R[j]).ravel(), bp.M_p[j]]
        h.update(np.concatenate([*M, bp.axis[j]]).astype(float).tobytes())
    return h.hexdigest()


_FIELDS = {"axis": (np.int64, (2,)), "child": (np.int64, None), "split": (np.int64, None),
           "low": (np.float64, None)}


def _path(key: str) -> Path:
    """The disk cache file of the table ``key`` (:mod:`.disk_cache`)."""
    return cache_folder("pair_tables") / f"{key}.npz"


def _load(key: str) -> dict | None:
    """A table from the disk cache, its structure checked (names, types, shapes, the tree's links); None if absent
    or bad. Its values are checked by :func:`_trusted`."""
    got = read_arrays(_path(key), list(_FIELDS))
    if got is None:
        return None
    n = got["child"].size
    for k, (dtype, shape) in _FIELDS.items():
        if got[k].dtype != dtype or (shape is not None and got[k].shape != shape) or (shape is None and
                                                                                      got[k].shape != (n,)):
            return None
    c = got["child"]
    if np.any((got["axis"] < -1) | (got["axis"] > 1)):
        return None
    if n == 0 or np.any((c != -1) & ((c <= np.arange(n)) | (c + 1 >= n))) or np.any((got["split"] < 0) |
                                                                                       (got["split"] > 1)):
        return None
    return got


def _trusted(cell: CellModel, a: int, b: int, side_a: list, side_b: list, table: dict) -> bool:
    """Whether ``table``'s bound stays at most coal's exact distance of the pair ``(a, b)`` (+ :data:`CHECK_TOL`)
    at :data:`CHECK_STATES` seeded random configurations of ``cell`` (NaN bounds fail)."""
    import coal

    bp = cell.batched_placements
    path = side_a + side_b
    Q = cell.random_q(CHECK_STATES, seed=1)
    angles = np.zeros((CHECK_STATES, 2))
    for i, k in enumerate(table["axis"]):
        if k >= 0:
            j = path[int(k)]
            angles[:, i] = bp.scale[j] * Q[:, bp.index[j]] + bp.offset[j]
    low = _lookup(table["child"], table["split"], table["low"], 0, angles)
    Rg, pg = cell.geometry_placements(Q)
    objs = cell.collision_model.geometryObjects
    req = coal.DistanceRequest()
    d = np.array([coal.distance(objs[a].geometry, coal.Transform3s(Rg[i, a], pg[i, a]), objs[b].geometry,
                                coal.Transform3s(Rg[i, b], pg[i, b]), req, coal.DistanceResult())
                  for i in range(CHECK_STATES)])
    return bool(np.all(low <= np.maximum(d, 0.0) + CHECK_TOL))


def _save(key: str, table: dict) -> None:
    write_arrays(_path(key), table)


def _table(cell: CellModel, a: int, b: int, side_a: list, side_b: list) -> tuple[dict, float]:
    """The table of the pair: from memory, else from the disk cache if its values hold (:func:`_trusted`), else
    built (and saved)."""
    key = _key(cell, a, b, side_a, side_b)
    got = _MEMORY.get(key)
    if got is None:
        got = _load(key)
        if got is not None and not _trusted(cell, a, b, side_a, side_b, got):
            got = None  # stale, damaged or planted: built again, never used
    seconds = 0.0
    if got is None:
        t0 = time.perf_counter()
        got = build_table(cell, a, b, side_a, side_b, turning_sides(cell, a, b, side_a, side_b))
        seconds = time.perf_counter() - t0
        _save(key, got)
    _MEMORY[key] = got
    return got, seconds


def loose_pairs(cell: CellModel, cover: Any, found: list) -> list:
    """The pairs of ``found`` (:func:`table_paths`) whose sphere ``cover`` (without tables) leaves open at least
    :data:`NEED_SHARE` of :data:`NEED_STATES` seeded random configurations where coal finds the pair more than
    2 mm beyond the threshold, at the thresholds :data:`NEED_THRESHOLDS` (a self margin, a usual margin):
    only those are worth a table's build."""
    import coal

    if not found:
        return []
    objs = cell.collision_model.geometryObjects
    a = np.array([f[0] for f in found], dtype=np.int64)
    b = np.array([f[1] for f in found], dtype=np.int64)
    Q = cell.random_q(NEED_STATES, seed=0)
    pairs = cover.prepare(a, b)
    opened = [~cover.pair_screen(Q, pairs, np.full(a.size, t)) for t in NEED_THRESHOLDS]
    Rg, pg = cell.geometry_placements(Q)
    req = coal.DistanceRequest()
    keep = []
    for k in range(len(found)):
        ga, gb = int(a[k]), int(b[k])
        rows = np.flatnonzero(np.any([o[:, k] for o in opened], axis=0))
        d = np.array([coal.distance(objs[ga].geometry, coal.Transform3s(Rg[i, ga], pg[i, ga]), objs[gb].geometry,
                                    coal.Transform3s(Rg[i, gb], pg[i, gb]), req, coal.DistanceResult()) for i in rows])
        loose = [int(np.sum(o[rows, k] & (d > t + 2e-3))) for o, t in zip(opened, NEED_THRESHOLDS)]
        if max(loose, default=0) >= NEED_SHARE * NEED_STATES:
            keep.append(found[k])
    return keep


def pair_tables(cell: CellModel, pairs: Sequence[tuple[int, int]], cover: Any = None) -> PairTables:
    """The tables of the geometry pairs ``(a, b)`` of ``cell`` that qualify (:func:`table_paths`) and, given the
    cell's sphere ``cover`` without tables, that it leaves loose (:func:`loose_pairs`), from the caches where
    they were built before (module docstring)."""
    found = table_paths(cell, pairs)
    if cover is not None:  # decided once per content (a moved base keeps its arm's pairs' verdicts)
        keys = [_key(cell, *f) for f in found]
        todo = [f for f, k in zip(found, keys) if k not in _LOOSE]
        loose = {id(f) for f in loose_pairs(cell, cover, todo)}
        _LOOSE.update({k: id(f) in loose for f, k in zip(found, keys) if k not in _LOOSE})
        found = [f for f, k in zip(found, keys) if _LOOSE[k]]
    tabs, seconds = [], 0.0
    for a, b, side_a, side_b in found:
        got, s = _table(cell, a, b, side_a, side_b)
        tabs.append(got)
        seconds += s
    return assemble(cell, found, tabs, seconds)


def assemble(cell: CellModel, found: list, tabs: list, seconds: float = 0.0) -> PairTables:
    """The :class:`PairTables` of the pairs ``found`` (:func:`table_paths`) and their tables ``tabs`` (axes as
    positions on the pair's path, so that a table serves every cell of the same content)."""
    sizes = np.array([t["child"].size for t in tabs], dtype=np.int64)
    root = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64) if tabs else np.zeros(0, dtype=np.int64)
    child = [np.where(t["child"] >= 0, t["child"] + r, -1) for t, r in zip(tabs, root)]
    axes = [axis_arrays(cell.batched_placements, f[2] + f[3], t["axis"]) for f, t in zip(found, tabs)]

    def cat(i: int, shape: tuple, dtype: Any) -> np.ndarray:
        return np.ascontiguousarray(np.stack([x[i] for x in axes]) if tabs else np.zeros(shape, dtype=dtype))

    return PairTables(np.array([f[0] for f in found], dtype=np.int64), np.array([f[1] for f in found], dtype=np.int64),
                      cat(0, (0, 2), np.int64), cat(1, (0, 2), np.int64), cat(2, (0, 2, 3), float),
                      cat(3, (0, 2, 3), float), cat(4, (0, 2, 3), float), root,
                      np.concatenate(child).astype(np.int64) if tabs else np.zeros(0, dtype=np.int64),
                      np.concatenate([t["split"] for t in tabs]).astype(np.int64) if tabs else np.zeros(0, np.int64),
                      np.concatenate([t["low"] for t in tabs]) if tabs else np.zeros(0), seconds)
