"""How :mod:`.pair_tables` builds one table: the pair's convex parts, their levers, the k-d tree of bounds
(the account is :mod:`.pair_tables`' docstring). Angles in rad, lengths in m.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from pinarms.robots.cell.cell_model import CellModel
from pinarms.robots.cell.mesh_cover import mesh_arrays, split_triangles

if TYPE_CHECKING:
    import pinocchio as pin

__all__ = ["axis_arrays", "geometry_points", "build_table", "turning_sides"]

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
#: The meshes' exact distance (coal, ~0.2 ms) is taken at a cell whose parts prove at most 1 mm only when the
#: whole geometry's loss over the cell is at most this [m] (else it could not prove more).
EXACT_LOSS = 3e-3
#: Taken off every stored bound [m].
SLACK = 1e-6
#: Longest part [m] of a mesh along its longest side, and most parts per mesh.
PART_LENGTH = 0.08
MAX_PARTS = 8
#: Most nodes of one table (then no cell is split further; the bounds stay proven).
MAX_NODES = 30_000

def geometry_points(obj: pin.GeometryObject) -> np.ndarray:
    """Points ``(n, 3)`` in the parent joint's frame whose convex hull holds the geometry: a mesh's vertices,
    another shape's local bounding box's corners."""
    got = mesh_arrays(obj.geometry)
    if got is not None:
        V = got[0]
    else:
        obj.geometry.computeLocalAABB()
        lo, hi = np.asarray(obj.geometry.aabb_local.min_), np.asarray(obj.geometry.aabb_local.max_)
        V = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    M = obj.placement
    return V @ np.asarray(M.rotation).T + np.asarray(M.translation)


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
            self.points, self.shapes, self.frames = [geometry_points(obj)], [obj.geometry], [self.M]
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

        self.bp = bp = cell.batched_placements
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
        exact meshes' distance bound ``(N,)`` (−inf where not taken). The part pairs are taken in the order of
        their parent bounds ``parent_low (N, P)``; once that bound is above the node's least so far, the rest
        keep their parents' bounds (valid on the child's cell, and above the node's bound)."""
        import coal

        A, B = self.A, self.B
        Ra, pa = _chains(A, self.axes, V, self.bp)
        Rb, pb = _chains(B, self.axes, V, self.bp)
        loss = 0.5 * (W @ self.lam)  # (N, P)
        low = parent_low.copy()
        exact = np.full(V.shape[0], -np.inf)
        nb = len(B.shapes)
        for n in range(V.shape[0]):
            Ta: dict = {}
            Tb: dict = {}
            best = np.inf
            for k in np.argsort(parent_low[n], kind="stable"):
                if parent_low[n, k] >= best:  # it and the rest keep their parents' bounds, above the node's
                    break
                i, m = divmod(int(k), nb)
                if i not in Ta:
                    Ta[i] = coal.Transform3s(Ra[n] @ A.frames[i][0], Ra[n] @ A.frames[i][1] + pa[n])
                if m not in Tb:
                    Tb[m] = coal.Transform3s(Rb[n] @ B.frames[m][0], Rb[n] @ B.frames[m][1] + pb[n])
                d = max(coal.distance(A.shapes[i], Ta[i], B.shapes[m], Tb[m], self.req, coal.DistanceResult()), 0.0)
                low[n, k] = max(parent_low[n, k], d - loss[n, k])
                best = min(best, low[n, k])
            whole = 0.5 * float(W[n] @ self.whole)
            if low[n].min() <= 1e-3 and whole <= EXACT_LOSS and (A.exact is not None or B.exact is not None):
                ga, Ga = (A.exact, A.M) if A.exact is not None else (A.shapes[0], A.frames[0])
                gb, Gb = (B.exact, B.M) if B.exact is not None else (B.shapes[0], B.frames[0])
                d = coal.distance(ga, coal.Transform3s(Ra[n] @ Ga[0], Ra[n] @ Ga[1] + pa[n]), gb,
                                  coal.Transform3s(Rb[n] @ Gb[0], Rb[n] @ Gb[1] + pb[n]), self.req,
                                  coal.DistanceResult())
                exact[n] = max(d, 0.0) - whole
        return low, exact


def build_table(cell: CellModel, a: int, b: int, side_a: list, side_b: list, turning: tuple = (False, False)) -> dict:
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
    path = side_a + side_b
    axis = np.array([path.index(j) for j in pair.axes] + [-1] * (2 - len(pair.axes)), dtype=np.int64)
    return {"axis": axis, "child": np.array(child, dtype=np.int64), "split": np.array(split, dtype=np.int64),
            "low": np.array(low) - SLACK}


def axis_arrays(bp: Any, path: list, axis: np.ndarray) -> tuple:
    """``(joint, parent (2,), e, ea, eb (2, 3))`` of a table's axes ``axis`` (positions in ``path``, −1: none) in a
    cell's joints ``bp`` (:class:`.pair_tables.PairTables`)."""
    e_, ea, eb = np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3))
    joint, par = np.full(2, -1, dtype=np.int64), np.full(2, -1, dtype=np.int64)
    for i, k in enumerate(axis):
        if k < 0:
            continue
        j = int(path[int(k)])
        u = np.asarray(bp.axis[j], dtype=float)
        e = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
        e /= np.linalg.norm(e)
        e_[i], ea[i], eb[i] = e, np.asarray(bp.M_R[j]) @ e, np.asarray(bp.M_R[j]) @ np.cross(u, e)
        joint[i], par[i] = j, int(bp.parent[j])
    return joint, par, e_, ea, eb


def turning_sides(cell: CellModel, a: int, b: int, side_a: list, side_b: list) -> tuple[bool, bool]:
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


