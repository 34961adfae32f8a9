"""Cells made for the tests from a SCARA pinarms does not ship, and an all-pairs reference.

The reference is plain Pinocchio + coal: a GeometryModel of its own with *every* pair of the
cell's collision geometries, minus only the pairs the cell allows by design (same link,
rigid, coaxial, adjacent, declared, constant gap) — not the project's pair list.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from pinarms.robots.cell import Cell
from pinarms.robots.cell.pairs import BY_DESIGN
from pinarms.robots.collision_requests import cold_start

SCARA_URDF = Path(__file__).resolve().parent.parent / "data" / "post_scara.urdf"
#: The post stands this far [m] from the nearest point the upper arm sweeps (its end corners).
POST_GAP = 0.013


def prefixed_scara(prefix: str, xyz: tuple[float, float, float], yaw: float = 0.0) -> str:
    """The SCARA's links and joints with ``prefix``, mounted on ``world`` at ``xyz`` turned by ``yaw``."""
    root = ET.parse(SCARA_URDF).getroot()
    for el in root:
        if el.tag in ("link", "joint"):
            el.set("name", prefix + el.get("name"))
        for tag in ("parent", "child"):
            ref = el.find(tag)
            if ref is not None:
                ref.set("link", prefix + ref.get("link"))
    body = "".join(ET.tostring(el, encoding="unicode") for el in root if el.tag in ("link", "joint"))
    x, y, z = xyz
    mount = (f'<joint name="{prefix}mount" type="fixed"><parent link="world"/><child link="{prefix}base_link"/>'
             f'<origin xyz="{x} {y} {z}" rpy="0 0 {yaw}"/></joint>')
    return mount + body


def post_cell_text() -> str:
    """One SCARA and a post (cylinder r 20 mm up to the upper arm's top) 13 mm beyond the upper arm's end."""
    x_post = float(np.hypot(0.325, 0.04)) + POST_GAP + 0.02  # the end face's corner sweeps radius hypot(0.325, 0.04)
    post = (f'<joint name="post_mount" type="fixed"><parent link="world"/><child link="post"/>'
            f'<origin xyz="{x_post} 0 0.23"/></joint>'
            '<link name="post"><collision><geometry><cylinder radius="0.02" length="0.46"/></geometry></collision></link>')
    return f'<robot name="post_cell"><link name="world"/>{prefixed_scara("arm_", (0, 0, 0))}{post}</robot>'


def facing_cell_text(spacing: float = 0.9) -> str:
    """Two of the SCARAs ``spacing`` apart on x, facing each other."""
    return ('<robot name="facing_scaras"><link name="world"/>'
            f'{prefixed_scara("one_", (0, 0, 0))}{prefixed_scara("two_", (spacing, 0, 0), np.pi)}</robot>')


def make_cell(text: str, name: str) -> Cell:
    return Cell(text, source=f"test:{name}", base_dir=SCARA_URDF.parent)


class Reference:
    """Every pair of the cell's geometries but those allowed by design, measured by coal directly."""

    def __init__(self, cell: Cell) -> None:
        self.model = cell.model
        gm = cell.collision_model.copy()
        gm.removeAllCollisionPairs()
        by_design = {frozenset((p.geometry_a, p.geometry_b)) for p in cell.allowed if p.reason in BY_DESIGN}
        names = [g.name for g in gm.geometryObjects]
        self.names = []
        for a in range(len(names)):
            for b in range(a + 1, len(names)):
                if frozenset((names[a], names[b])) not in by_design:
                    gm.addCollisionPair(pin.CollisionPair(a, b))
                    self.names.append(frozenset((names[a], names[b])))
        self.gm = gm
        self.gd = cold_start(pin.GeometryData(gm), distance_tolerance=1e-10)
        self.data = self.model.createData()
        self.to_pin = cell.robot.q_to_pinocchio

    def distances(self, q: np.ndarray) -> np.ndarray:
        """``(P,)`` distance of every reference pair [m] at one cell configuration."""
        pin.updateGeometryPlacements(self.model, self.data, self.gm, self.gd, self.to_pin(np.asarray(q, dtype=float)))
        pin.computeDistances(self.gm, self.gd)
        return np.array([r.min_distance for r in self.gd.distanceResults])

    def minimum(self, Q: np.ndarray) -> np.ndarray:
        """``(N,)`` smallest distance over the reference pairs for each row of ``Q``."""
        return np.array([self.distances(q).min() for q in np.atleast_2d(Q)])
