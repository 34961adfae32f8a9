"""Tight covers of triangle meshes for :mod:`.cover`: spheres fitted to a mesh's parts, and the
box or cylinder holding a mesh.

**Spheres** (:func:`mesh_spheres`): the mesh's triangles are first cut (each halved across its
longest edge, again and again: :func:`split_triangles`) until no edge is longer than
:data:`SPLIT_EDGE`: the pieces tile each triangle exactly, and a long sliver along an arm's
tube no longer forces one sphere to span the tube. The pieces are grouped into **parts**
along the mesh's longest side, each close to a cylinder along one of the mesh's axes (an
arm link: a joint housing, the tube, the next housing; the cuts minimise the parts' cylinder
volumes), and each part's cylinder is sliced across its axis, one sphere per slice centred
on the axis. A sphere reaches the farthest vertex of the pieces whose centres lie in its
slice: holding a piece's three vertices it holds the piece (a sphere is convex), so the
union of the spheres holds every triangle.

**Primitives**: :func:`static_primitive` gives the smaller of the box and the cylinders (along
the mesh's axes) holding all vertices, screened exactly for a mesh fixed in the world (an
arm's base); :func:`mesh_cylinder` the smallest such cylinder, screened exactly for a moving
mesh where it is tight (:data:`.cover.CYLINDER_SHARE`); :func:`mesh_parts` the spheres with thin
cylinders on their parts' axes, each holding a group of a slice's pieces, screened exactly against
static boxes for a moving mesh that one cylinder holds loosely. A box or a cylinder is convex: holding the vertices it holds the mesh.

Lengths in m, in the mesh's own frame.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any

import numpy as np

__all__ = ["SLICE_CYLINDERS", "SPLIT_EDGE", "mesh_arrays", "mesh_cylinder", "mesh_parts", "mesh_parts_owned", "mesh_spheres",
           "split_triangles", "static_primitive"]

#: Longest edge [m] of the pieces the triangles are cut into before they are grouped.
SPLIT_EDGE = 0.01


#: :func:`mesh_arrays` of the last :data:`_KEPT` geometry objects of this process: ``coal id -> (object, vertices,
#: triangles)``, keyed by the C++ object (Pinocchio gives a new Python wrapper at each access), held so that
#: its address is not reused.
_ARRAYS: OrderedDict = OrderedDict()
_KEPT = 64


def mesh_arrays(geo: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """Vertices ``(V, 3)`` and triangles ``(T, 3)`` (vertex indices) of a coal ``BVHModel``, or None
    for a shape without them. A point cloud: each vertex a degenerate triangle. Read-only arrays, read
    from the object once per process (a Python call per triangle, about 0.1 s for 40 000): again while the
    object's vertices and triangle count are the same (pinarms never replaces a mesh's triangles)."""
    try:
        V = np.array(geo.vertices(), dtype=float).reshape(-1, 3)
        n = int(geo.num_tris)
    except (AttributeError, TypeError, RuntimeError):
        return None
    if V.shape[0] == 0:
        return None
    key = geo.id() if callable(getattr(geo, "id", None)) else id(geo)
    kept = _ARRAYS.get(key)
    if kept is not None and kept[2].shape[0] == (n or V.shape[0]) and np.array_equal(kept[1], V):
        _ARRAYS.move_to_end(key)
        return kept[1], kept[2]
    try:
        tri = geo.tri_indices
        T = np.fromiter((t[k] for t in (tri(i) for i in range(n)) for k in (0, 1, 2)), dtype=np.int64,
                        count=3 * n).reshape(-1, 3)
    except (AttributeError, TypeError, RuntimeError):
        return None
    if T.shape[0] == 0:
        T = np.repeat(np.arange(V.shape[0])[:, None], 3, axis=1)
    V.flags.writeable = False
    T.flags.writeable = False
    _ARRAYS[key] = (geo, V, T)
    if len(_ARRAYS) > _KEPT:
        _ARRAYS.popitem(last=False)
    return V, T


def split_triangles(P: np.ndarray, edge: float = SPLIT_EDGE) -> tuple[np.ndarray, np.ndarray]:
    """Triangles ``P (M, 3, 3)`` cut into pieces with no edge longer than ``edge`` [m] (each piece
    halved across its longest edge): ``(pieces (K, 3, 3), source triangle (K,))``. The pieces of a
    triangle tile it exactly."""
    if not edge > 0.0:
        raise ValueError(f"edge must be > 0 m, got {edge!r}")
    P = np.asarray(P, dtype=float)
    src = np.arange(P.shape[0])
    done, done_src = [], []
    while P.shape[0]:
        e = np.linalg.norm(P[:, [1, 2, 0]] - P, axis=2)  # edge k joins vertex k and k + 1
        k = e.argmax(axis=1)
        i = np.arange(P.shape[0])
        long = e[i, k] > edge
        done.append(P[~long])
        done_src.append(src[~long])
        P, k, src, i = P[long], k[long], src[long], i[: int(long.sum())]
        a, b, c = P[i, k], P[i, (k + 1) % 3], P[i, (k + 2) % 3]
        m = 0.5 * (a + b)
        P = np.concatenate([np.stack([a, m, c], axis=1), np.stack([m, b, c], axis=1)])
        src = np.concatenate([src, src])
    return np.concatenate(done), np.concatenate(done_src)


def _circle_centre(X: np.ndarray, rounds: int = 64) -> np.ndarray:
    """A centre of a small circle holding the 2-D points ``X (n, 2)`` (Bădoiu–Clarkson steps from the box
    centre: each moves towards the farthest point). Any centre is safe: the radius is measured after."""
    c = 0.5 * (X.min(axis=0) + X.max(axis=0))
    for k in range(1, rounds + 1):
        far = X[np.argmax(((X - c) ** 2).sum(axis=1))]
        c = c + (far - c) / (k + 1.0)
    return c


def _cylinder(X: np.ndarray, refine: bool = False) -> tuple[float, int, np.ndarray, float, float, float]:
    """The smallest of the three cylinders along the axes holding the points ``X (n, 3)``:
    ``(volume, axis, centre of its cross-section (3,; the axis coordinate 0), radius, low, high end)``."""
    lo, hi = X.min(axis=0), X.max(axis=0)
    best = None
    for axis in range(3):
        u, w = (axis + 1) % 3, (axis + 2) % 3
        c2 = _circle_centre(X[:, [u, w]]) if refine else 0.5 * (lo[[u, w]] + hi[[u, w]])
        radius = float(np.sqrt(((X[:, [u, w]] - c2) ** 2).sum(axis=1).max()))
        volume = np.pi * radius ** 2 * (hi[axis] - lo[axis])
        if best is None or volume < best[0]:
            centre = np.zeros(3)
            centre[[u, w]] = c2
            best = (volume, axis, centre, radius, float(lo[axis]), float(hi[axis]))
    return best


#: Cylinders each sphere's slice is cut into along its part's axis (:func:`mesh_parts`).
SLICE_CYLINDERS = 4

#: Places along a mesh's longest side where :func:`_parts` may cut it, and what each extra part costs
#: (a share of the whole mesh's cylinder volume).
PART_CUTS = 24
PART_COST = 0.02


def _parts(S: np.ndarray, mid: np.ndarray) -> list[np.ndarray]:
    """The pieces ``S`` (centres ``mid``) cut across the mesh's longest side into parts each close to a
    cylinder along one of the axes: the cuts (of :data:`PART_CUTS` places) that minimise the parts'
    cylinder volumes plus :data:`PART_COST` per part (dynamic programming)."""
    lo, hi = mid.min(axis=0), mid.max(axis=0)
    axis = int(np.argmax(hi - lo))
    cuts = np.linspace(lo[axis], hi[axis], PART_CUTS + 1)
    cuts[-1] = np.inf
    cuts[0] = -np.inf
    slab = np.searchsorted(cuts, mid[:, axis], side="left") - 1
    slab = np.clip(slab, 0, PART_CUTS - 1)
    X = np.unique(S.reshape(-1, 3), axis=0)  # the parts' volumes from the pieces' vertices, each once
    at = np.clip(np.searchsorted(cuts, X[:, axis], side="left") - 1, 0, PART_CUTS - 1)
    penalty = PART_COST * _cylinder(X)[0]
    cost = np.full(PART_CUTS + 1, np.inf)
    cost[0] = 0.0
    back = np.zeros(PART_CUTS + 1, dtype=np.int64)
    for j in range(1, PART_CUTS + 1):
        for i in range(j):
            inside = (at >= i) & (at < j)
            c = cost[i] + penalty + (_cylinder(X[inside])[0] if inside.any() else 0.0)
            if c < cost[j]:
                cost[j], back[j] = c, i
    out, j = [], PART_CUTS
    while j > 0:
        i = int(back[j])
        idx = np.flatnonzero((slab >= i) & (slab < j))
        if idx.size:
            out.append(idx)
        j = i
    return out[::-1]


def _slices(cyl: tuple, bulge: float) -> int:
    """Slices of a part's cylinder so that each slice's sphere about its axis overshoots the radius by ``bulge``."""
    _, _, _, radius, lo, hi = cyl
    t = 2.0 * np.sqrt(max((radius + bulge) ** 2 - radius ** 2, 1e-18))
    return max(1, int(np.ceil((hi - lo) / t)))


def _part_cylinders(V: np.ndarray, T: np.ndarray, count: int, edge: float) -> tuple:
    """The mesh's pieces ``S``, their centres, its parts (piece indices, :func:`_parts`; one part where
    there are more than ``count``) and each part's cylinder (:func:`_cylinder`, holding its pieces' vertices)."""
    if int(count) < 1:
        raise ValueError(f"count must be at least 1, got {count!r}")
    P = np.asarray(V, dtype=float)[np.asarray(T, dtype=np.int64)]
    S, _ = split_triangles(P, edge)
    mid = S.mean(axis=1)
    parts = _parts(S, mid)
    if len(parts) > int(count):  # more parts than spheres: one part
        parts = [np.arange(S.shape[0])]
    return S, mid, parts, [_cylinder(S[idx].reshape(-1, 3), refine=True) for idx in parts]


def mesh_parts(V: np.ndarray, T: np.ndarray, count: int, edge: float = SPLIT_EDGE) -> tuple[np.ndarray, ...]:
    """:func:`mesh_spheres` ``(centres (k, 3), radii (k,))`` and the cylinders of the slices: each sphere's
    slice cut across its part's axis into at most :data:`SLICE_CYLINDERS` groups of pieces (by their
    centres), each group held by a cylinder on that axis: axis ends ``a, b (c, 3)``, radii ``(c,)`` [m] in
    the mesh's frame, and ``sphere (c,)``: the sphere holding the same pieces. A cylinder holds its
    pieces' vertices, so (convex) the pieces: the union of the cylinders holds every triangle, and
    each group lies in the intersection of its cylinder and its sphere. Screened exactly against
    static boxes (:func:`.box_kernel.held_low`): a cylinder's flat ends where the sphere
    overshoots them, and a flaring housing in thin cylinders."""
    return _sphere_cover(V, T, count, edge)[:6]


def mesh_parts_owned(V: np.ndarray, T: np.ndarray, count: int, edge: float = SPLIT_EDGE) -> tuple[np.ndarray, ...]:
    """:func:`mesh_parts` and, last, the cylinder ``(K,)`` holding each piece of :func:`split_triangles`
    ``(V[T], edge)`` (with its sphere): what lets a stored cover be checked piece by piece."""
    return _sphere_cover(V, T, count, edge)


def mesh_spheres(V: np.ndarray, T: np.ndarray, count: int, edge: float = SPLIT_EDGE) -> tuple[np.ndarray, np.ndarray]:
    """At most ``count`` spheres ``(centres (k, 3), radii (k,))`` [m] whose union holds the mesh of
    vertices ``V (n, 3)`` and triangles ``T (m, 3)``, in the mesh's frame.

    The triangles are cut into pieces (:func:`split_triangles`), the pieces grouped into parts
    each close to a cylinder along one of the mesh's axes (the cuts across its longest side that
    minimise the parts' cylinder volumes, :func:`_parts`), and each part's cylinder sliced across its axis, one sphere
    per slice centred on the axis: the slices are as thick as the overshoot over the
    cylinder's radius allows, the smallest overshoot for which all parts take at most
    ``count`` slices. Each sphere reaches the farthest vertex of the pieces whose centres lie
    in its slice: holding a piece's vertices it holds the piece (a sphere is convex)."""
    return _sphere_cover(V, T, count, edge)[:2]


def _sphere_cover(V: np.ndarray, T: np.ndarray, count: int, edge: float) -> tuple[np.ndarray, ...]:
    """:func:`mesh_parts_owned` (:func:`mesh_parts` its first six arrays, :func:`mesh_spheres` its first two)."""
    S, mid, parts, cyls = _part_cylinders(V, T, count, edge)
    low, high = 1e-5, 1.0
    for _ in range(40):  # the smallest overshoot whose slices fit the count
        b = np.sqrt(low * high)
        low, high = (b, high) if sum(_slices(c, b) for c in cyls) > int(count) else (low, b)
    centres, radii, a, b, rad, sphere = [], [], [], [], [], []
    owner = np.full(S.shape[0], -1, dtype=np.int64)
    for idx, cyl in zip(parts, cyls):
        _, axis, centre, _, lo, hi = cyl
        k = _slices(cyl, high)
        at = np.minimum(((mid[idx, axis] - lo) / max(hi - lo, 1e-12) * k).astype(np.int64), k - 1)
        u, w = (axis + 1) % 3, (axis + 2) % 3
        for j in range(k):
            X = S[idx[at == j]].reshape(-1, 3)
            if X.shape[0] == 0:
                continue
            c = centre.copy()
            c[axis] = 0.5 * (X[:, axis].min() + X[:, axis].max())
            centres.append(c)
            radii.append(float(np.sqrt(((X - c) ** 2).sum(axis=1).max())))
            # the slice cut again into cylinders about the part's axis, each holding its pieces' vertices
            inside = idx[at == j]
            sub = np.minimum(((mid[inside, axis] - mid[inside, axis].min())
                              / max(np.ptp(mid[inside, axis]), 1e-12) * SLICE_CYLINDERS).astype(np.int64),
                             SLICE_CYLINDERS - 1)
            for m in np.unique(sub):
                Y = S[inside[sub == m]].reshape(-1, 3)
                owner[inside[sub == m]] = len(rad)
                a.append(c.copy())
                b.append(c.copy())
                a[-1][axis], b[-1][axis] = Y[:, axis].min(), Y[:, axis].max()
                rad.append(float(np.sqrt(((Y[:, [u, w]] - c[[u, w]]) ** 2).sum(axis=1).max())))
                sphere.append(len(radii) - 1)
    return (np.array(centres), np.array(radii), np.array(a), np.array(b), np.array(rad),
            np.array(sphere, dtype=np.int64), owner)


def static_primitive(V: np.ndarray) -> tuple[str, np.ndarray, np.ndarray, np.ndarray]:
    """The smaller (by volume) of the box and the cylinders (along the axes) holding the vertices
    ``V (n, 3)``: ``(kind "Box" or "Cylinder", rotation (3, 3), centre (3,), size (3,))`` in the mesh's
    frame; size: the box's half sides, or ``(radius, half length, 0)`` with the cylinder's axis the
    rotation's z column."""
    V = np.asarray(V, dtype=float)
    lo, hi = V.min(axis=0), V.max(axis=0)
    half = 0.5 * (hi - lo)
    volume, axis, centre, radius, a, b = _cylinder(V, refine=True)
    if float(np.prod(2.0 * half)) <= volume:
        return "Box", np.eye(3), 0.5 * (lo + hi), half
    u, w = (axis + 1) % 3, (axis + 2) % 3
    R = np.zeros((3, 3))
    R[u, 0], R[w, 1], R[axis, 2] = 1.0, 1.0, 1.0  # a cyclic turn of the axes: a rotation
    centre = centre.copy()
    centre[axis] = 0.5 * (a + b)
    return "Cylinder", R, centre, np.array([radius, 0.5 * (b - a), 0.0])


def mesh_cylinder(V: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
    """The smallest cylinder along one of the axes holding the vertices ``V (n, 3)``: its axis ends
    ``a, b (3,)``, radius [m], and its volume over the vertices' box's volume."""
    V = np.asarray(V, dtype=float)
    volume, axis, centre, radius, lo, hi = _cylinder(V, refine=True)
    a, b = centre.copy(), centre.copy()
    a[axis], b[axis] = lo, hi
    return a, b, radius, float(volume / max(np.prod(V.max(axis=0) - V.min(axis=0)), 1e-300))
