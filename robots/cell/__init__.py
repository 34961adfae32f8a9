"""Cells: several arms at their bases, fixtures, one Pinocchio model and collision checks.

>>> from pinarms import robots
>>> cell = robots.load_cell("mushroom_line")
>>> cell.arms[0].name, cell.nq
('left', 8)
>>> bool(cell.in_collision(cell.neutral))
False
"""

from .cell import Cell
from .collision import Clearance, Collisions
from .components import CellArm, Fixture, Shape
from .compose import (
    ArmPlacement,
    CellDescription,
    FixturePrimitive,
    ToolPoint,
    compose_cell,
    compose_cell_urdf,
    load_cell_description,
    read_cell_description,
)
from .library import build_cell, build_cells, cell_names, cell_source_path, cell_urdf_path, load_cell, stale_cells
from .motion import check_motion
from .motion_report import Contact, MotionCheck
from .pairs import AllowedPair, CollisionPair, PairReason
from .timeline import ArmMotion
from ..errors import CellTooLarge, PlacementError

__all__ = [
    "load_cell",
    "cell_names",
    "cell_source_path",
    "cell_urdf_path",
    "build_cell",
    "build_cells",
    "stale_cells",
    "Cell",
    "CellArm",
    "Fixture",
    "Shape",
    "CollisionPair",
    "AllowedPair",
    "PairReason",
    "Collisions",
    "Clearance",
    "ArmMotion",
    "Contact",
    "MotionCheck",
    "check_motion",
    "ArmPlacement",
    "FixturePrimitive",
    "ToolPoint",
    "CellDescription",
    "compose_cell",
    "compose_cell_urdf",
    "load_cell_description",
    "read_cell_description",
    "CellTooLarge",
    "PlacementError",
]
