"""Distance tables for pairs of geometries close in the kinematic chain: a proven lower bound of
their distance, looked up from the joint angles, for :mod:`.cover`'s screens.

**Which pairs.** Two geometries whose relative placement depends on at most two revolute joints
(the joints on the tree path between their parent joints: the UR5's forearm and wrist_2 on
``q4, q5``, its base and upper arm on ``q1, q2``, an upper arm and a fixed table on ``q1, q2``),
at least one of them a triangle mesh (spheres round a mesh's slices overshoot a housing's flat
end by nearly its radius; the covers of primitives are already tight).

**What is tabulated.** Each side is taken as a convex shape holding it: a mesh as the convex
hull of its vertices (a triangle is a combination of its vertices, so the hull holds the mesh),
a primitive as itself. A side that turns about a path joint's axis — its own joint, or the
first joint below it — is replaced by the cylinder about that axis holding its vertices when
that cylinder is at most :data:`TURNING` times its hull's volume (the UR5's base under joint 1,
a wrist housing about its own joint): the cylinder is the same at every angle of that joint,
so the distance no longer depends on it and the table loses that axis. The distance between
the two holding shapes is a lower bound of the geometries' distance; where it is at most a
node's loss + 1 mm the meshes' exact distance (coal, as the exact check) is taken instead when
larger.

**The bound over a cell of angles.** Turning joint ``j`` by ``Δ`` moves every point of the
geometry it carries (relative to the other) by at most ``λ_j |Δ|``, ``λ_j`` the largest
distance of that geometry's points (its holding shape's) from the axis of ``j``, over every
angle of the joint below ``j``. The distance therefore changes by at most ``Σ λ_j |Δ_j|``
(every term a path in angle space), and a cell ``c ± w/2`` of angles keeps at least
``d(c) − Σ λ_j w_j / 2``. The cells form a k-d tree over ``[−π, π)²`` (revolute joints are
periodic in 2π): a cell is split in half along the axis with the larger ``λ_j w_j`` while its
loss exceeds :data:`TOL` + :data:`REL` · ``d(c)`` (fine cells near contact, coarse far away),
a cell in contact only down to :data:`CONTACT_TOL`, and not at all once its bound exceeds
:data:`CAP`; a child keeps the larger of its own and its parent's bound. Each leaf stores the
bound less :data:`SLACK` (GJK's and coal's tolerances, the angles' rounding).

**In the kernels** (:mod:`._cover_kernel`): a pair with a table takes the larger of the table's
bound and its cover's; the angles come from the joint frames already placed (no joint values
are passed). Any lower bound at a state keeps the edge proofs (the Lipschitz ladder, the
per-group levers) valid: they need only ``d ≥ bound`` at their samples.

**Cost** (UR5, 2 cores shared): tables are built once per cell and content (meshes, placements,
axes), kept in memory and on disk (``__pycache__/pair_tables/<sha256>.npz`` beside this file,
written atomically, read with ``allow_pickle=False`` and checked; an unwritable folder only
costs the build). Angles in rad, lengths in m.
"""

from __future__ import annotations

import hashlib
import io
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .mesh_cover import mesh_arrays, split_triangles

__all__ = ["PairTables", "pair_tables", "no_tables", "table_paths", "TOL", "REL", "CAP", "CONTACT_TOL", "TURNING", "SLACK", "PART_LENGTH", "MAX_PARTS", "TURN_SAMPLES",
           "MAX_NODES"]

#: Loss [m] a cell may keep at zero distance; :data:`REL` times the distance is added.
TOL = 1.5e-3
REL = 0.35
#: Cells whose bound exceeds this [m] are not split (the cover proves such pairs).
CAP = 0.025
#: Cells whose centre is in contact are split only down to this loss [m].
CONTACT_TOL = 8e-3
#: A turning side is replaced by its coaxial cylinder when, at :data:`TURN_SAMPLES` seeded angles where the
#: parts are nearer than :data:`CAP`, the cylinder's distance keeps this share of theirs (less 0.5 mm).
TURNING = 0.9
TURN_SAMPLES = 64
TURN_NEAR = 0.15
#: Taken off every stored bound [m].
SLACK = 1e-6
#: Longest part [m] of a mesh along its longest side, and most parts per mesh.
PART_LENGTH = 0.08
MAX_PARTS = 8
#: Most nodes of one table (then no cell is split further; the bounds stay proven).
MAX_NODES = 30_000
_VERSION = 1
_MEMORY: dict = {}
_DISK = Path(__file__).resolve().parent / "__pycache__" / "pair_tables"


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
        """The arrays in the kernels' order (:func:`._cover_kernel.table_low`)."""
        return (self.joint, self.parent, self.ea, self.eb, self.e, self.root, self.child, self.split, self.low)

    def of_pairs(self, pair_a: np.ndarray, pair_b: np.ndarray) -> np.ndarray:
        """``(P,)`` the table of each pair ``(pair_a[k], pair_b[k])`` (either order), −1 where none."""
        index = {(int(a), int(b)): t for t, (a, b) in enumerate(zip(self.pair_a, self.pair_b))}
        index.update({(b, a): t for (a, b), t in list(index.items())})
        return np.array([index.get((int(a), int(b)), -1) for a, b in zip(pair_a, pair_b)], dtype=np.int64)

    def bound(self, t: int, angles: np.ndarray) -> np.ndarray:
        """``(N,)`` table ``t``'s bound [m] at joint angles ``angles (N, 2)`` [rad] (numpy; its unused axis ignored)."""
        A = np.atleast_2d(np.asarray(angles, dtype=float))
        out = np.empty(A.shape[0])
        for i, v in enumerate(A):
            v = np.mod(v + math.pi, 2.0 * math.pi) - math.pi
            lo, w, n = np.full(2, -math.pi), np.full(2, 2.0 * math.pi), int(self.root[t])
            while self.child[n] >= 0:
                s = int(self.split[n])
                w[s] *= 0.5
                up = v[s] >= lo[s] + w[s]
                lo[s] += w[s] if up else 0.0
                n = int(self.child[n]) + int(up)
            out[i] = self.low[n]
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


def table_paths(cell: Any, pairs: Sequence[tuple[int, int]]) -> list[tuple[int, int, list[int], list[int]]]:
    """The pairs ``(a, b)`` that get a table, each with its path joints top-down on ``a``'s side and on
    ``b``'s (at most two in all, revolute, at least one of the two geometries a mesh)."""
    objs = cell.collision_model.geometryObjects
    bp = cell._placements
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


def _points(obj: Any) -> np.ndarray:
    """Points ``(n, 3)`` in the parent joint's frame whose convex hull holds the geometry."""
    from .cover import geometry_spheres

    got = mesh_arrays(obj.geometry)
    M = obj.placement
    if got is not None:
        return got[0] @ np.asarray(M.rotation).T + np.asarray(M.translation)
    c, r = geometry_spheres(obj)  # a primitive: the boxes round its cover's spheres
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    return (c[:, None, :] + r[:, None, None] * corners[None]).reshape(-1, 3)


def _mesh_parts(obj: Any) -> list[np.ndarray]:
    """A mesh's triangles cut into pieces of edges at most :data:`.mesh_cover.SPLIT_EDGE` and grouped in
    slabs of at most :data:`PART_LENGTH` along its longest side: each slab's vertices ``(n, 3)`` in the
    parent joint's frame (the slabs' hulls hold every piece, so the mesh)."""
    V, T = mesh_arrays(obj.geometry)
    M = obj.placement
    V = V @ np.asarray(M.rotation).T + np.asarray(M.translation)
    S, _ = split_triangles(V[T])
    mid = S.mean(axis=1)
    lo, hi = mid.min(axis=0), mid.max(axis=0)
    axis = int(np.argmax(hi - lo))
    k = int(min(MAX_PARTS, max(1, math.ceil((hi[axis] - lo[axis]) / PART_LENGTH))))
    at = np.minimum(((mid[:, axis] - lo[axis]) / max(hi[axis] - lo[axis], 1e-12) * k).astype(np.int64), k - 1)
    return [np.unique(S[at == i].reshape(-1, 3), axis=0) for i in range(k) if np.any(at == i)]


def _hull(points: np.ndarray) -> Any:
    import coal

    return coal.Convex.convexHull([v for v in points], False, "")


class _Side:
    """One geometry of a pair: its convex parts (hulls, in its parent joint's frame), the points of each,
    its exact shape (a mesh) and placement, and its joints (top-down, those of the path on its side)."""

    def __init__(self, obj: Any, joints: list[int], bp: Any, first_other: int | None, turning: bool):
        self.joints = list(joints)
        M = obj.placement
        self.M = (np.asarray(M.rotation, dtype=float), np.asarray(M.translation, dtype=float))
        mesh = mesh_arrays(obj.geometry) is not None
        self.exact = obj.geometry if mesh else None
        if mesh:
            self.points = _mesh_parts(obj)
            self.shapes = [_hull(P) for P in self.points]
            self.frames = [(np.eye(3), np.zeros(3))] * len(self.points)
        else:
            self.points, self.shapes, self.frames = [_points(obj)], [obj.geometry], [self.M]
        # the axis fixed in this side's frame: its own joint's (on the path), else the first joint of the other side's
        self.turn = None
        if not turning or not mesh:
            return
        if self.joints:
            j, o, d = self.joints[-1], np.zeros(3), np.asarray(bp.axis[self.joints[-1]], dtype=float)
        elif first_other is not None:
            j, o, d = first_other, np.asarray(bp.M_p[first_other], dtype=float), \
                np.asarray(bp.M_R[first_other]) @ bp.axis[first_other]
        else:
            return
        self.cylinder(j, o, d / np.linalg.norm(d))

    def cylinder(self, j: int, o: np.ndarray, d: np.ndarray) -> None:
        """Replace the side by the cylinder about joint ``j``'s axis (through ``o`` along ``d``) holding it."""
        import coal

        P = np.concatenate(self.points)
        z = (P - o) @ d
        r = float(np.linalg.norm(P - o - z[:, None] * d, axis=1).max()) * (1.0 + 1e-9) + 1e-9
        z0, z1 = float(z.min()) - 1e-9, float(z.max()) + 1e-9
        e = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
        e /= np.linalg.norm(e)
        rim = np.linspace(0.0, 2.0 * math.pi, 721)[:-1]
        circle = r / math.cos(math.pi / 720) * (np.cos(rim)[:, None] * e + np.sin(rim)[:, None] * np.cross(d, e))
        self.turn, self.exact = j, None
        self.shapes = [coal.Cylinder(r, z1 - z0)]
        self.frames = [(np.column_stack([e, np.cross(d, e), d]), o + 0.5 * (z0 + z1) * d)]
        self.points = [np.concatenate([circle + o + z0 * d, circle + o + z1 * d])]


def _lever(side: _Side, j: int, bp: Any) -> np.ndarray:
    """``λ_j`` of each part of ``side``: the largest distance [m] of its points from joint ``j``'s axis, over
    every angle of the joint below ``j`` on that side (module docstring)."""
    u = np.asarray(bp.axis[j], dtype=float)
    k = side.joints[-1]
    out = []
    for Y in side.points:
        if k == j:
            out.append(float(np.linalg.norm(Y - np.outer(Y @ u, u), axis=1).max()))
            continue
        uk = np.asarray(bp.axis[k], dtype=float)
        along = Y @ uk
        across = np.linalg.norm(Y - np.outer(along, uk), axis=1)
        X = bp.M_p[k] + np.outer(along, np.asarray(bp.M_R[k]) @ uk)
        out.append(float((np.linalg.norm(X - np.outer(X @ u, u), axis=1) + across).max()))
    return np.array(out)


def _chains(side: _Side, axes: list[int], V: np.ndarray, bp: Any) -> tuple[np.ndarray, np.ndarray]:
    """World-free placements ``(R (N, 3, 3), p (N, 3))`` of ``side``'s joint frame in the pair's common frame at the
    angles ``V (N, 2)`` of ``axes`` (other joints at 0)."""
    N = V.shape[0]
    R, p = np.tile(np.eye(3), (N, 1, 1)), np.zeros((N, 3))
    for j in side.joints:
        u = np.asarray(bp.axis[j], dtype=float)
        v = V[:, axes.index(j)] if j in axes else np.zeros(N)
        K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
        L = np.eye(3) + np.sin(v)[:, None, None] * K + (1.0 - np.cos(v))[:, None, None] * (K @ K)
        p = p + R @ bp.M_p[j]
        R = R @ np.asarray(bp.M_R[j]) @ L
    return R, p


class _Pair:
    """The distance bounds of a pair's parts at a node's centre (module docstring)."""

    def __init__(self, cell: Any, a: int, b: int, side_a: list, side_b: list, turning: tuple[bool, bool]):
        import coal

        self.bp = bp = cell._placements
        objs = cell.collision_model.geometryObjects
        self.A = _Side(objs[a], side_a, bp, side_b[0] if side_b else None, turning[0])
        self.B = _Side(objs[b], side_b, bp, side_a[0] if side_a else None, turning[1])
        self.axes = [j for j in side_a + side_b if j not in (self.A.turn, self.B.turn)]
        lam = np.zeros((2, len(self.A.points), len(self.B.points)))
        for i, j in enumerate(self.axes):
            if j in side_a:
                lam[i] += _lever(self.A, j, bp)[:, None]
            else:
                lam[i] += _lever(self.B, j, bp)[None, :]
        self.lam = lam.reshape(2, -1)  # per axis, per part pair (a-major)
        self.whole = self.lam.max(axis=1)
        self.req = coal.DistanceRequest()

    def evaluate(self, V: np.ndarray, W: np.ndarray, parent_low: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per node (centres ``V (N, 2)``, widths ``W (N, 2)``): the bound of each part pair ``(N, P)`` and the
        exact meshes' distance bound ``(N,)`` (−inf where not taken). A part pair whose parent bound
        ``parent_low (N, P)`` leaves it far from binding keeps that bound (valid on the child's cell)."""
        import coal

        A, B = self.A, self.B
        Ra, pa = _chains(A, self.axes, V, self.bp)
        Rb, pb = _chains(B, self.axes, V, self.bp)
        loss = 0.5 * (W @ self.lam)  # (N, P)
        low = parent_low.copy()
        exact = np.full(V.shape[0], -np.inf)
        nb = len(B.shapes)
        for n in range(V.shape[0]):
            floor = float(parent_low[n].min())
            reach = floor + 2.0 * float(loss[n].max()) + TOL + REL * max(floor, 0.0)
            Ta: dict = {}
            Tb: dict = {}
            for k in np.flatnonzero(parent_low[n] <= reach):
                i, m = divmod(int(k), nb)
                if i not in Ta:
                    Ta[i] = coal.Transform3s(Ra[n] @ A.frames[i][0], Ra[n] @ A.frames[i][1] + pa[n])
                if m not in Tb:
                    Tb[m] = coal.Transform3s(Rb[n] @ B.frames[m][0], Rb[n] @ B.frames[m][1] + pb[n])
                d = max(coal.distance(A.shapes[i], Ta[i], B.shapes[m], Tb[m], self.req, coal.DistanceResult()), 0.0)
                low[n, k] = max(parent_low[n, k], d - loss[n, k])
            whole = 0.5 * float(W[n] @ self.whole)
            if low[n].min() <= 1e-3 and (A.exact is not None or B.exact is not None):
                ga, Ga = (A.exact, A.M) if A.exact is not None else (A.shapes[0], A.frames[0])
                gb, Gb = (B.exact, B.M) if B.exact is not None else (B.shapes[0], B.frames[0])
                d = coal.distance(ga, coal.Transform3s(Ra[n] @ Ga[0], Ra[n] @ Ga[1] + pa[n]), gb,
                                  coal.Transform3s(Rb[n] @ Gb[0], Rb[n] @ Gb[1] + pb[n]), self.req,
                                  coal.DistanceResult())
                exact[n] = max(d, 0.0) - whole
        return low, exact


def _build_one(cell: Any, a: int, b: int, side_a: list, side_b: list, turning: tuple = (False, False)) -> dict:
    """One table's nodes and axes (module docstring), breadth first, a level's centres at once."""
    pair = _Pair(cell, a, b, side_a, side_b, turning)
    na = len(pair.axes)
    P = pair.lam.shape[1]
    lo, w = np.full((1, 2), -math.pi), np.full((1, 2), 2.0 * math.pi)
    w[:, na:] = 0.0
    parent_low, up = np.full((1, P), -np.inf), np.full(1, -np.inf)
    child, split, low = [], [], []
    while lo.shape[0]:
        part, exact = pair.evaluate(lo + 0.5 * w, w, parent_low)
        bound = np.maximum(np.maximum(part.min(axis=1), exact), up)
        k = np.argmin(part, axis=1)
        loss = 0.5 * np.einsum("ni,in->n", w, pair.lam[:, k])
        d = bound + loss
        tol = np.where(d <= loss + 1e-12, CONTACT_TOL, TOL + REL * d)
        room = MAX_NODES - len(low) - lo.shape[0]
        go = (loss > tol) & (bound < CAP)
        go &= np.cumsum(go) * 2 <= room
        s = np.argmax(w * pair.lam[:, k].T, axis=1)
        first = len(low) + lo.shape[0] + 2 * (np.cumsum(go) - 1)
        child.extend(np.where(go, first, -1).tolist())
        split.extend(np.where(go, s, 0).tolist())
        low.extend(bound.tolist())
        g = np.flatnonzero(go)
        w2 = np.repeat(w[g], 2, axis=0)
        s2 = np.repeat(s[g], 2)
        w2[np.arange(w2.shape[0]), s2] *= 0.5
        lo2 = np.repeat(lo[g], 2, axis=0)
        lo2[np.arange(lo2.shape[0]), s2] += np.tile([0.0, 1.0], g.size) * w2[np.arange(w2.shape[0]), s2]
        lo, w = lo2, w2
        parent_low, up = np.repeat(part[g], 2, axis=0), np.repeat(bound[g], 2)
    e_, ea, eb = np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3))
    joint, par = np.full(2, -1), np.full(2, -1)
    bp = pair.bp
    for i, j in enumerate(pair.axes):
        u = np.asarray(bp.axis[j], dtype=float)
        e = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
        e /= np.linalg.norm(e)
        e_[i], ea[i], eb[i] = e, np.asarray(bp.M_R[j]) @ e, np.asarray(bp.M_R[j]) @ np.cross(u, e)
        joint[i], par[i] = j, int(bp.parent[j])
    return dict(joint=joint, parent=par, e=e_, ea=ea, eb=eb, child=np.array(child, dtype=np.int64),
                split=np.array(split, dtype=np.int64), low=np.array(low) - SLACK)


def _turning(cell: Any, a: int, b: int, side_a: list, side_b: list) -> tuple[bool, bool]:
    """Which sides are taken as their coaxial cylinders (:data:`TURNING`)."""
    path = side_a + side_b
    rng = np.random.default_rng(0)
    angles = rng.uniform(-math.pi, math.pi, (TURN_SAMPLES, len(path)))

    def distances(turning: tuple) -> np.ndarray:
        pair = _Pair(cell, a, b, side_a, side_b, turning)
        V = np.zeros((TURN_SAMPLES, 2))
        for i, j in enumerate(pair.axes):
            V[:, i] = angles[:, path.index(j)]
        got, _ = pair.evaluate(V, np.zeros_like(V), np.full((TURN_SAMPLES, pair.lam.shape[1]), -np.inf))
        return got.min(axis=1)

    full = distances((False, False))
    near = full < TURN_NEAR
    out = []
    for side in (0, 1):
        trial = (side == 0, side == 1)
        pair = _Pair(cell, a, b, side_a, side_b, trial)
        if (pair.A.turn, pair.B.turn)[side] is None:
            out.append(False)
            continue
        got = distances(trial)
        out.append(bool(np.all(got[near] >= TURNING * full[near] - 5e-4)))
    return out[0], out[1]


def _key(cell: Any, a: int, b: int, side_a: list, side_b: list) -> str:
    """A digest of what a table depends on: both geometries (vertices, triangles or shape and size, placements),
    the path joints' placements and axes, and the build's constants."""
    bp = cell._placements
    objs = cell.collision_model.geometryObjects
    h = hashlib.sha256(repr((_VERSION, TOL, REL, CAP, CONTACT_TOL, TURNING, TURN_SAMPLES, TURN_NEAR, SLACK, MAX_NODES,
                             PART_LENGTH, MAX_PARTS, len(side_a),
                             len(side_b))).encode())
    for g in (a, b):
        obj = objs[g]
        got = mesh_arrays(obj.geometry)
        if got is None:
            h.update(_points(obj).tobytes())
        else:
            h.update(got[0].tobytes() + got[1].tobytes())
        h.update(np.asarray(obj.placement.homogeneous, dtype=float).tobytes())
    for j in side_a + side_b:
        h.update(np.concatenate([np.asarray(bp.M_R[j]).ravel(), bp.M_p[j], bp.axis[j]]).astype(float).tobytes())
    return h.hexdigest()


_FIELDS = {"joint": (np.int64, (2,)), "parent": (np.int64, (2,)), "e": (np.float64, (2, 3)),
           "ea": (np.float64, (2, 3)), "eb": (np.float64, (2, 3)), "child": (np.int64, None),
           "split": (np.int64, None), "low": (np.float64, None)}


def _load(key: str) -> dict | None:
    """A table from the disk cache, checked (names, types, shapes, the tree's links); None if absent or bad."""
    path = _DISK / f"{key}.npz"
    try:
        with np.load(path, allow_pickle=False) as z:
            got = {k: np.array(z[k]) for k in _FIELDS}
    except (OSError, KeyError, ValueError):
        return None
    n = got["child"].size
    for k, (dtype, shape) in _FIELDS.items():
        if got[k].dtype != dtype or (shape is not None and got[k].shape != shape) or (shape is None and
                                                                                      got[k].shape != (n,)):
            return None
    c = got["child"]
    if n == 0 or np.any((c != -1) & ((c <= np.arange(n)) | (c + 1 >= n))) or np.any((got["split"] < 0) |
                                                                                       (got["split"] > 1)):
        return None
    return got


def _save(key: str, table: dict) -> None:
    from pinarms.files import atomic_write

    try:
        _DISK.mkdir(parents=True, exist_ok=True)
        buf = io.BytesIO()
        np.savez(buf, **table)
        atomic_write(_DISK / f"{key}.npz", lambda f: f.write(buf.getvalue()))
    except OSError:
        pass


def _table(cell: Any, a: int, b: int, side_a: list, side_b: list) -> tuple[dict, float]:
    key = _key(cell, a, b, side_a, side_b)
    got = _MEMORY.get(key)
    if got is None:
        got = _load(key)
    seconds = 0.0
    if got is None:
        t0 = time.perf_counter()
        got = _build_one(cell, a, b, side_a, side_b, _turning(cell, a, b, side_a, side_b))
        seconds = time.perf_counter() - t0
        _save(key, got)
    _MEMORY[key] = got
    return got, seconds


def pair_tables(cell: Any, pairs: Sequence[tuple[int, int]]) -> PairTables:
    """The tables of the geometry pairs ``(a, b)`` of ``cell`` that qualify (:func:`table_paths`), from the
    caches where they were built before (module docstring)."""
    found = table_paths(cell, pairs)
    tabs, seconds = [], 0.0
    for a, b, side_a, side_b in found:
        got, s = _table(cell, a, b, side_a, side_b)
        tabs.append(got)
        seconds += s
    sizes = np.array([t["child"].size for t in tabs], dtype=np.int64)
    root = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64) if tabs else np.zeros(0, dtype=np.int64)
    child = [np.where(t["child"] >= 0, t["child"] + r, -1) for t, r in zip(tabs, root)]

    def cat(name: str, shape: tuple, dtype: Any) -> np.ndarray:
        return np.ascontiguousarray(np.stack([t[name] for t in tabs]) if tabs else np.zeros(shape, dtype=dtype))

    return PairTables(np.array([f[0] for f in found], dtype=np.int64), np.array([f[1] for f in found], dtype=np.int64),
                      cat("joint", (0, 2), np.int64), cat("parent", (0, 2), np.int64), cat("e", (0, 2, 3), float),
                      cat("ea", (0, 2, 3), float), cat("eb", (0, 2, 3), float), root,
                      np.concatenate(child).astype(np.int64) if tabs else np.zeros(0, dtype=np.int64),
                      np.concatenate([t["split"] for t in tabs]).astype(np.int64) if tabs else np.zeros(0, np.int64),
                      np.concatenate([t["low"] for t in tabs]) if tabs else np.zeros(0), seconds)
