"""The seeded sampling of the pair classification (:mod:`.pairs`), cached by content on disk.

For the pairs no rule of structure or reach settles, coal checks every pair at :data:`SAMPLES`
seeded random configurations of the cell: how many are in contact, and the deepest
penetration [m] among the contacts (what a :class:`PlacementError` reports). Only the pairs in
contact at a configuration get a distance query: a contact check stops at the first
overlapping triangles, while a distance between two meshes walks both trees to the nearest
triangles (0.1 ms against 66 ms per configuration for the 89 pairs of a Kinova Jaco2 on a
table; a cell with mesh arms spent 15-45 s here, now well under a second). The verdicts read
from it (:data:`.pairs.ALWAYS_SHARE`) need the contact counts only.

The result is kept in the user's cache folder (:mod:`.disk_cache`, ``pair_samples/<sha256>.npz``), named by a
digest of everything it depends on: the cell's URDF text, every collision geometry (shape,
size, mesh vertices and triangles (those as the digest of the mesh file they were read from),
placement, parent joint), the pairs sampled, the seed, the count, this module's and the joint sampler's source files, and the versions of coal,
Pinocchio and numpy.

Only a sampling that took at least :data:`MIN_SECONDS` is written (a cell of primitives samples
in milliseconds; a layout search builds one cell per base placement). A file is never trusted: besides its structure, :data:`VERIFY` of the same seeded
configurations (the first ones) are measured again and must give the stored contacts and
depths (within 1e-9 m), inside the stored counts and extremes; a file that fails is
sampled again and overwritten.
"""

from __future__ import annotations

import hashlib
import time
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from pinarms.robots import robot as _robot
from pinarms.robots.collision_requests import pair_probe
from pinarms.robots.cell.disk_cache import cache_folder, code_digest, read_arrays, write_arrays
from pinarms.robots.cell.mesh_cover import mesh_arrays

from pinarms.robots.cell.cell_model import CellModel

__all__ = ["SAMPLES", "VERIFY", "MIN_SECONDS", "sample_pairs"]

#: Seeded random configurations measured per cell.
SAMPLES = 200
#: Of them, the first ones measured again to check a cached file.
VERIFY = 8
#: A sampling quicker than this [s] is not written to the disk (cells of primitives take milliseconds).
MIN_SECONDS = 0.5
_CODE = (Path(__file__), Path(_robot.__file__))
_NAMES = ("hits", "depth", "first_depth", "first_hit")


def sample_pairs(cell: "CellModel", objs: list, data: pin.Data, checked: list[tuple[int, int]],
                 seed: int) -> tuple[np.ndarray, np.ndarray]:
    """``(hits, depth)`` per pair of ``checked`` over :data:`SAMPLES` seeded configurations: contacts counted, and
    the deepest penetration among them [m] (0 without contact); from the disk cache when a file of the same content
    passes its check."""
    if not checked:
        return np.zeros(0), np.zeros(0)
    path = cache_folder("pair_samples") / f"{_key(cell, objs, checked, seed)}.npz"
    probe = pair_probe(objs, checked, 1e-12)
    qs = np.atleast_2d(cell.robot.q_to_pinocchio(cell.random_q(SAMPLES, seed=seed)))
    got = read_arrays(path, _NAMES)
    if got is not None and _trusted(got, cell.model, data, probe, qs, len(checked)):
        return got["hits"], got["depth"]
    t0 = time.perf_counter()
    got = _measure(cell.model, data, probe, qs, len(checked))
    if time.perf_counter() - t0 >= MIN_SECONDS:  # a quick sampling is not worth a file (a layout's many cells)
        write_arrays(path, got)
    return got["hits"], got["depth"]


def _at(model: pin.Model, data: pin.Data, probe: tuple, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Contacts ``(P,)`` bool and penetration depths ``(P,)`` [m] (0 where apart) of the probe's pairs at one
    Pinocchio configuration: a distance query only for the pairs in contact."""
    gm, gd = probe
    pin.updateGeometryPlacements(model, data, gm, gd, q)
    pin.computeCollisions(gm, gd, False)
    hit = np.array([r.isCollision() for r in gd.collisionResults], dtype=bool)
    depth = np.zeros(hit.size)
    for k in np.flatnonzero(hit):
        depth[k] = max(0.0, -pin.computeDistance(gm, gd, int(k)).min_distance)
    return hit, depth


def _measure(model: pin.Model, data: pin.Data, probe: tuple, qs: np.ndarray, P: int) -> dict[str, np.ndarray]:
    hits, depth = np.zeros(P), np.zeros(P)
    first_depth, first_hit = np.zeros((VERIFY, P)), np.zeros((VERIFY, P), dtype=bool)
    for i, q in enumerate(qs):
        hit, d = _at(model, data, probe, q)
        hits += hit
        depth = np.maximum(depth, d)
        if i < VERIFY:
            first_depth[i], first_hit[i] = d, hit
    return {"hits": hits, "depth": depth, "first_depth": first_depth, "first_hit": first_hit}


def _trusted(got: dict, model: pin.Model, data: pin.Data, probe: tuple, qs: np.ndarray, P: int) -> bool:
    """Whether a cached file has the right shapes and agrees with coal at the first :data:`VERIFY` configurations."""
    shapes = {"hits": (P,), "depth": (P,), "first_depth": (VERIFY, P), "first_hit": (VERIFY, P)}
    if any(got[k].shape != s for k, s in shapes.items()) or got["first_hit"].dtype != bool:
        return False
    if any(got[k].dtype != np.float64 for k in ("hits", "depth", "first_depth")):
        return False
    hits, depth = got["hits"], got["depth"]
    if not (np.all(np.isfinite(depth)) and np.all(depth >= 0.0) and np.all(hits == np.round(hits))
            and np.all((hits > 0) | (depth == 0.0))):
        return False
    for i in range(VERIFY):
        hit, d = _at(model, data, probe, qs[i])
        if not (np.array_equal(hit, got["first_hit"][i])
                and np.allclose(d, got["first_depth"][i], rtol=0.0, atol=1e-9)):
            return False
    seen = got["first_hit"].sum(axis=0)
    return bool(np.all(depth >= got["first_depth"].max(axis=0)) and np.all(hits >= seen)
                and np.all(SAMPLES - hits >= VERIFY - seen))


def _key(cell: "CellModel", objs: list, checked: list[tuple[int, int]], seed: int) -> str:
    """A digest of everything the sampling depends on (module docstring)."""
    h = hashlib.sha256(repr((SAMPLES, VERIFY, int(seed), code_digest(_CODE), getattr(coal, "__version__", ""),
                             pin.__version__, np.__version__)).encode())
    h.update(cell.urdf_text.encode("utf-8"))
    for g in objs:
        geo = g.geometry
        geo.computeLocalAABB()
        h.update(repr((g.name, type(geo).__name__, int(g.parentJoint))).encode())
        h.update(np.asarray(g.placement.homogeneous, dtype=float).tobytes())
        h.update(np.concatenate([np.asarray(geo.aabb_local.min_), np.asarray(geo.aabb_local.max_)]).tobytes())
        h.update(_mesh_content(g))
    h.update(np.asarray(checked, dtype=np.int64).tobytes())
    return h.hexdigest()


def _mesh_content(g: Any) -> bytes:
    """A mesh's content for the key: its vertices, and for its triangles the digest of the mesh file coal read
    them from (the same file gives the same triangles; reading them back from coal costs a Python call per
    triangle, a second per cell with mesh arms); read from coal for a mesh without a file. ``b""``: no mesh."""
    geo = g.geometry
    try:
        V = np.asarray(geo.vertices(), dtype=float)
        n = int(geo.num_tris)
    except (AttributeError, TypeError, RuntimeError):
        return b""
    path = Path(str(getattr(g, "meshPath", "") or ""))
    if str(path) and path.is_file():
        return V.tobytes() + repr(n).encode() + hashlib.sha256(path.read_bytes()).digest()
    mesh = mesh_arrays(geo)
    return b"" if mesh is None else mesh[0].tobytes() + mesh[1].tobytes()
