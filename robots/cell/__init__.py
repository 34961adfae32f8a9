"""Cells: several arms at their bases, fixtures, one Pinocchio model and collision checks.

>>> from pinarms import robots
>>> cell = robots.load_cell("mushroom_line")
>>> cell.arms[0].name, cell.nq
('left', 8)
>>> bool(cell.in_collision(cell.neutral))
False
"""

from __future__ import annotations

from ...lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "Cell": ".cell",
    "Clearance": ".collision",
    "Collisions": ".collision",
    "CellArm": ".components",
    "Fixture": ".components",
    "Shape": ".components",
    "ArmPlacement": ".compose_file",
    "CellDescription": ".compose_file",
    "FixturePrimitive": ".compose_file",
    "ToolPoint": ".compose_file",
    "compose_cell": ".compose",
    "compose_cell_urdf": ".compose",
    "load_cell_description": ".compose",
    "read_cell_description": ".compose_file",
    "build_cell": ".library",
    "build_cells": ".library",
    "cell_names": ".library",
    "cell_source_path": ".library",
    "cell_urdf_path": ".library",
    "load_cell": ".library",
    "stale_cells": ".library",
    "check_motion": ".motion",
    "Contact": ".motion_report",
    "MotionCheck": ".motion_report",
    "AllowedPair": ".pairs",
    "CollisionPair": ".pairs",
    "PairReason": ".pairs",
    "ArmMotion": ".timeline",
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
