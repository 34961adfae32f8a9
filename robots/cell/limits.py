"""Bounds on what a cell file may hold, checked before the expensive work, and its geometry checked.

A real production cell has a few arms and some tens of collision geometries (the built-in
``mushroom_line``: 2 arms, 21 fixtures, 39 geometries). The caps below are far above that
and keep a hostile or mistaken file from taking minutes or gigabytes: files and meshes are
sized by ``stat`` before they are read (and then read up to the cap only), and the counts of
arms, fixtures, collision geometries and geometry pairs are taken from the XML before
Pinocchio builds anything. Every refusal is a :class:`~pinarms.errors.CellTooLarge`
stating the limit.

Collision primitives must have finite, positive sizes up to :data:`MAX_CELL_EXTENT` (a box of
size −0.2 or 0 is no obstacle coal can check): :func:`check_geometry` raises
:class:`~pinarms.errors.CollisionGeometryError` naming the fixture (or link); so does
:func:`check_extent` for a geometry placed farther than :data:`MAX_CELL_EXTENT` from the world
origin (coal's broadphase fails on a box at 1e15 m: "negative volume").
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

from pinarms.files import read_bounded_text

from pinarms.errors import CellTooLarge, CollisionGeometryError, ModelError

__all__ = [
    "MAX_CELL_FILE_BYTES", "MAX_MESH_BYTES", "MAX_ARMS", "MAX_FIXTURES", "MAX_GEOMETRIES", "MAX_GEOMETRY_PAIRS",
    "read_cell_file", "check_file_size", "check_counts", "check_pairs", "check_geometry", "check_mesh_size",
    "MAX_CELL_EXTENT", "check_extent",
]

#: Largest cell file (URDF or xacro) read [bytes].
MAX_CELL_FILE_BYTES = 16 * 2**20
#: Largest mesh file a cell's collision geometry may name [bytes].
MAX_MESH_BYTES = 64 * 2**20
#: Most arms in one cell.
MAX_ARMS = 16
#: Most fixtures in one cell.
MAX_FIXTURES = 500
#: Most collision geometries (``<collision>`` elements) in one cell (so at most 179 700 pairs to classify).
MAX_GEOMETRIES = 600
#: Most pairs of collision geometries left to check after the proven rules (each is sampled
#: 200 times by the sampled rules at load, and checked by every query).
MAX_GEOMETRY_PAIRS = 5000
#: Largest size of a primitive and largest distance of a collision geometry from the world
#: origin at the neutral configuration [m]. A production cell spans tens of metres; at 1 km a
#: double still resolves 1e-13 m, while coal's bounding volumes break down long before 1e15 m.
MAX_CELL_EXTENT = 1000.0


def check_file_size(path: str | os.PathLike, limit: int, what: str) -> int:
    """The size of ``path`` [bytes] by ``stat``; :class:`CellTooLarge` above ``limit`` (nothing is read)."""
    try:
        size = os.stat(path).st_size
    except OSError as exc:
        raise ModelError(f"cannot read {what} {str(path)!r}: {exc.strerror or exc}") from exc
    if size > limit:
        raise CellTooLarge(f"{what} {str(path)!r} is {size} bytes; the limit is {limit} bytes ({limit / 2**20:.0f} MiB)")
    return size


def read_cell_file(path: str | os.PathLike) -> str:
    """The text of a cell file: a regular file (not a FIFO or a device), sized first and read up
    to :data:`MAX_CELL_FILE_BYTES` only (UTF-8)."""
    return read_bounded_text(path, MAX_CELL_FILE_BYTES, "cell file", error=ModelError, too_large=CellTooLarge)


def check_counts(root: ET.Element, n_arms: int, n_fixtures: int, source: str) -> None:
    """:class:`CellTooLarge` when the cell has more arms, fixtures or collision geometries than the caps."""
    n_geom = sum(1 for _ in root.iter("collision"))
    for count, limit, what in ((n_arms, MAX_ARMS, "arms"), (n_fixtures, MAX_FIXTURES, "fixtures"),
                               (n_geom, MAX_GEOMETRIES, "collision geometries")):
        if count > limit:
            raise CellTooLarge(f"{source} has {count} {what}; a cell may have at most {limit}")


def check_pairs(n_pairs: int, source: str) -> None:
    """:class:`CellTooLarge` when more than :data:`MAX_GEOMETRY_PAIRS` pairs are left to check."""
    if n_pairs > MAX_GEOMETRY_PAIRS:
        raise CellTooLarge(
            f"{source} has {n_pairs} pairs of collision geometries to check (not proven apart, not allowed by design); "
            f"a cell may have at most {MAX_GEOMETRY_PAIRS}: fewer or coarser geometries, or arms farther apart"
        )


def _numbers(text: str | None, n: int, where: str) -> list[float]:
    try:
        values = [float(v) for v in (text or "").split()]
    except ValueError:
        values = []
    if len(values) != n:
        raise CollisionGeometryError(f"{where}: expected {n} number(s), got {text!r}")
    return values


def check_geometry(root: ET.Element, fixtures: tuple[str, ...], source: str) -> None:
    """Every ``<collision>`` primitive of the cell has finite sizes > 0 (mesh scales finite and ≠ 0)."""
    fixture_set = set(fixtures)
    for link in root.findall("link"):
        name = link.get("name", "?")
        owner = f"fixture {name!r}" if name in fixture_set else f"link {name!r}"
        for k, geometry in enumerate(link.findall("collision/geometry")):
            where = f"{source}: {owner}, collision {k}"
            for shape in geometry:
                if shape.tag == "box":
                    values = {"size": _numbers(shape.get("size"), 3, f"{where}: box size")}
                elif shape.tag in ("cylinder", "capsule"):
                    values = {a: _numbers(shape.get(a), 1, f"{where}: {shape.tag} {a}") for a in ("radius", "length")}
                elif shape.tag == "sphere":
                    values = {"radius": _numbers(shape.get("radius"), 1, f"{where}: sphere radius")}
                elif shape.tag == "mesh":
                    scale = shape.get("scale")
                    values = {} if scale is None else {"scale": _numbers(scale, 3, f"{where}: mesh scale")}
                    if any(not math.isfinite(v) or v == 0.0 for v in values.get("scale", [])):
                        raise CollisionGeometryError(f"{where}: mesh scale must be finite and non-zero, got {scale!r}")
                    continue
                else:
                    continue
                for attr, vals in values.items():
                    if not all(math.isfinite(v) and 0.0 < v <= MAX_CELL_EXTENT for v in vals):
                        raise CollisionGeometryError(
                            f"{where}: {shape.tag} {attr} must be finite, > 0 and at most {MAX_CELL_EXTENT:g} [m], "
                            f"got {shape.get(attr)!r}"
                        )


def check_mesh_size(path: Path) -> None:
    """:class:`CellTooLarge` when a mesh file is above :data:`MAX_MESH_BYTES` (by ``stat``, unread)."""
    check_file_size(path, MAX_MESH_BYTES, "mesh")


def check_extent(model: Any, geometry_model: Any, fixtures: tuple[str, ...], source: str) -> None:
    """:class:`CollisionGeometryError` naming the fixture (or link) of a collision geometry placed
    farther than :data:`MAX_CELL_EXTENT` from the world origin at the neutral configuration."""
    import numpy as np
    import pinocchio as pin

    data, gdata = model.createData(), geometry_model.createData()
    pin.updateGeometryPlacements(model, data, geometry_model, gdata, pin.neutral(model))
    fixture_set = set(fixtures)
    for k, placement in enumerate(gdata.oMg):
        far = float(np.max(np.abs(placement.translation))) if np.all(np.isfinite(placement.translation)) else math.inf
        if far > MAX_CELL_EXTENT:
            link = model.frames[geometry_model.geometryObjects[k].parentFrame].name
            owner = f"fixture {link!r}" if link in fixture_set else f"link {link!r}"
            raise CollisionGeometryError(
                f"{source}: {owner} is placed {far:g} m from the world origin; a cell may extend at most "
                f"{MAX_CELL_EXTENT:g} m: check the origin's units (metres) and the arm's base")
