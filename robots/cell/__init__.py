"""Cells: several arms at their bases, fixtures, one Pinocchio model and collision checks.

>>> from pinarms import robots
>>> cell = robots.load_cell("mushroom_line")
>>> cell.arms[0].name, cell.nq
('left', 8)
>>> bool(cell.in_collision(cell.neutral))
False
"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "Cell": "pinarms.robots.cell.cell",
    "Clearance": "pinarms.robots.cell.collision",
    "Collisions": "pinarms.robots.cell.collision",
    "CellArm": "pinarms.robots.cell.components",
    "Fixture": "pinarms.robots.cell.components",
    "Shape": "pinarms.robots.cell.components",
    "ArmPlacement": "pinarms.robots.cell.compose_file",
    "CellDescription": "pinarms.robots.cell.compose_file",
    "FixturePrimitive": "pinarms.robots.cell.compose_file",
    "ToolPoint": "pinarms.robots.cell.compose_file",
    "compose_cell": "pinarms.robots.cell.compose",
    "compose_cell_urdf": "pinarms.robots.cell.compose",
    "load_cell_description": "pinarms.robots.cell.compose",
    "read_cell_description": "pinarms.robots.cell.compose_file",
    "build_cell": "pinarms.robots.cell.library",
    "build_cells": "pinarms.robots.cell.library",
    "cell_names": "pinarms.robots.cell.library",
    "cell_source_path": "pinarms.robots.cell.library",
    "cell_urdf_path": "pinarms.robots.cell.library",
    "load_cell": "pinarms.robots.cell.library",
    "stale_cells": "pinarms.robots.cell.library",
    "check_motion": "pinarms.robots.cell.motion",
    "Contact": "pinarms.robots.cell.motion_report",
    "MotionCheck": "pinarms.robots.cell.motion_report",
    "AllowedPair": "pinarms.robots.cell.pairs",
    "CollisionPair": "pinarms.robots.cell.pairs",
    "PairReason": "pinarms.robots.cell.pairs",
    "ArmMotion": "pinarms.robots.cell.timeline",
    "CellTooLarge": "pinarms.errors",
    "PlacementError": "pinarms.errors",
}

__all__ = [
    "load_cell", "cell_names", "cell_source_path", "cell_urdf_path", "build_cell", "build_cells", "stale_cells",
    "Cell", "CellArm", "Fixture", "Shape", "CollisionPair", "AllowedPair", "PairReason", "Collisions", "Clearance",
    "ArmMotion", "Contact", "MotionCheck", "check_motion", "ArmPlacement", "FixturePrimitive", "ToolPoint",
    "CellDescription", "compose_cell", "compose_cell_urdf", "load_cell_description", "read_cell_description",
    "CellTooLarge", "PlacementError",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
