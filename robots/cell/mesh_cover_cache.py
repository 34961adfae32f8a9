"""The sphere covers of meshes (:func:`.mesh_cover.mesh_parts`), cached by content on disk.

Building a mesh's cover cuts its triangles into pieces and searches the parts and slices
(:mod:`.mesh_cover`): seconds per arm link, which a planned move of a mesh arm paid at every
call. The cover is kept in the user's cache folder (:mod:`.disk_cache`,
``mesh_covers/<sha256>.npz``), named by a digest of the mesh's vertices and triangles (bytes and
shapes), the sphere count, the longest piece edge, the source files of :mod:`.mesh_cover` and of
this module, and numpy's version.

Only a build that took at least :data:`MIN_SECONDS` is written. A file is never trusted
(:func:`holds_mesh`): its arrays must have the shapes and types of a cover of at most ``count``
spheres, finite non-negative radii, every cylinder naming one of the spheres, and the mesh cut
again into its pieces (:func:`.mesh_cover.split_triangles`, cheap next to the search) must lie
piece by piece in the cylinder the file names for it (:func:`.mesh_cover.mesh_parts_owned`) **and** in
that cylinder's sphere, each vertex within :data:`TOLERANCE` (far below
the 1e-9 m slack :mod:`.cover` adds to every radius). A file that fails is built again and
overwritten: a cache costs time, never a verdict.
"""

from __future__ import annotations

import hashlib
import time
from pathlib import Path

import numpy as np

from pinarms.robots.cell import mesh_cover
from pinarms.robots.cell.disk_cache import cache_folder, code_digest, read_arrays, write_arrays

__all__ = ["MIN_SECONDS", "TOLERANCE", "cached_mesh_parts", "holds_mesh"]

#: A build quicker than this [s] is not written to the disk.
MIN_SECONDS = 0.05
#: How far [m] a piece's vertex may lie outside its cylinder or sphere in a cached cover (rounding only).
TOLERANCE = 1e-12
_CODE = (Path(mesh_cover.__file__), Path(__file__))
_NAMES = ("centres", "radii", "a", "b", "rad", "sphere", "owner")


def cached_mesh_parts(V: np.ndarray, T: np.ndarray, count: int,
                      edge: float = mesh_cover.SPLIT_EDGE) -> tuple[np.ndarray, ...]:
    """:func:`.mesh_cover.mesh_parts` ``(V, T, count, edge)``, read from the disk cache when a file of the same
    content passes :func:`holds_mesh`, else built (and written when the build took :data:`MIN_SECONDS`)."""
    V = np.ascontiguousarray(V, dtype=float)
    T = np.ascontiguousarray(T, dtype=np.int64)
    path = cache_folder("mesh_covers") / f"{_key(V, T, count, edge)}.npz"
    got = read_arrays(path, _NAMES)
    if got is not None:
        cover = tuple(got[k] for k in _NAMES)
        if holds_mesh(cover, V, T, count, edge):
            return cover[:6]
    t0 = time.perf_counter()
    cover = mesh_cover.mesh_parts_owned(V, T, count, edge)
    if time.perf_counter() - t0 >= MIN_SECONDS:
        write_arrays(path, dict(zip(_NAMES, cover)))
    return cover[:6]


def holds_mesh(cover: tuple, V: np.ndarray, T: np.ndarray, count: int,
               edge: float = mesh_cover.SPLIT_EDGE) -> bool:
    """Whether ``cover`` ``(centres, radii, a, b, rad, sphere, owner)`` (:func:`.mesh_cover.mesh_parts_owned`) is a
    cover of at most ``count`` spheres of the mesh ``V, T`` (module docstring): each piece ``i`` of
    :func:`.mesh_cover.split_triangles` within the cylinder ``k = owner[i]`` (axis ``a[k] b[k]``, radius ``rad[k]``)
    and within its sphere ``sphere[k]``."""
    if len(cover) != len(_NAMES):
        return False
    centres, radii, a, b, rad, sphere, owner = cover
    k, c = radii.shape[0] if radii.ndim == 1 else -1, rad.shape[0] if rad.ndim == 1 else -1
    shapes = ((centres, (k, 3)), (radii, (k,)), (a, (c, 3)), (b, (c, 3)), (rad, (c,)), (sphere, (c,)))
    if not 1 <= k <= int(count) or c < 1 or any(x.shape != s for x, s in shapes):
        return False
    if any(x.dtype != np.float64 for x in (centres, radii, a, b, rad)) or any(
            x.dtype != np.int64 for x in (sphere, owner)):
        return False
    floats = np.concatenate([centres.ravel(), radii, a.ravel(), b.ravel(), rad])
    if not (np.all(np.isfinite(floats)) and np.all(radii >= 0.0) and np.all(rad >= 0.0)
            and np.all((sphere >= 0) & (sphere < k))):
        return False
    S, _ = mesh_cover.split_triangles(np.asarray(V, dtype=float)[np.asarray(T, dtype=np.int64)], edge)
    if owner.shape != (S.shape[0],) or not np.all((owner >= 0) & (owner < c)):
        return False
    axis = b - a
    L = np.linalg.norm(axis, axis=1)
    u = axis / np.where(L > 0.0, L, 1.0)[:, None]  # a zero-length cylinder: a ball of radius rad (as screened)
    s = sphere[owner]
    in_sphere = np.sqrt(((S - centres[s][:, None]) ** 2).sum(axis=2)) <= radii[s][:, None] + TOLERANCE
    d = S - a[owner][:, None]  # (K, 3 vertices, 3)
    t = (d * u[owner][:, None]).sum(axis=2)
    radial = np.sqrt(((d - t[..., None] * u[owner][:, None]) ** 2).sum(axis=2))
    in_cyl = (t >= -TOLERANCE) & (t <= L[owner][:, None] + TOLERANCE) & (radial <= rad[owner][:, None] + TOLERANCE)
    return bool(np.all(in_sphere & in_cyl))


def _key(V: np.ndarray, T: np.ndarray, count: int, edge: float) -> str:
    """A digest of everything the cover depends on (module docstring)."""
    h = hashlib.sha256(repr((int(count), float(edge), V.shape, T.shape, code_digest(_CODE),
                             np.__version__)).encode())
    h.update(V.tobytes())
    h.update(T.tobytes())
    return h.hexdigest()
