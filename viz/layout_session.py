"""A layout search as a session: the arm at its best placement, its cycle, the candidates.

:func:`layout_search_session` builds a :class:`pinarms.viz.Session` from an
:class:`pinarms.optim.LayoutSearch`: the robot stands at the best placement (``base_to_world``), its
best cycle is the animated trajectory, the candidate base positions are a point cloud
coloured by picks per minute (stored as a workspace cloud whose value is picks/min, in the
robot's base frame as clouds are), and the picks and places are target points (line frame).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pinarms.errors import InvalidInput

from pinarms.viz.session import Session

if TYPE_CHECKING:
    from pinarms.optim.layout.result import LayoutSearch
    from pinarms.robots.cell.cell import Cell
    from pinarms.robots.robot import Robot

__all__ = ["layout_search_session"]


def layout_search_session(result: LayoutSearch, robot: Robot, *, title: str | None = None, cell: Cell | None = None,
                          carry: tuple[str, ...] = ()) -> Session:
    """Session of a layout search of ``robot`` (see the module docstring).

    With the ``cell`` the search ran in, its box-shaped fixtures are added as boxes (other
    shapes by their bounding box: cylinders as square prisms; meshes are left out); the
    fixtures in ``carry`` are drawn where they stand with the arm at its best placement.

    Raises:
        InvalidInput: no candidate could run the cycle (nothing to place), or a result of another robot.
    """
    from pinarms.optim.layout.search import base_to_world

    if getattr(result, "best_placement", None) is None:
        raise InvalidInput("the layout search found no placement that runs the cycle: nothing to show")
    if getattr(result, "robot", None) != robot.name:
        raise InvalidInput(f"the layout search is of {result.robot!r}, not of {robot.name!r}")
    T = base_to_world(result.best_placement)
    session = Session(robot, title=title or f"layout search of {robot.name}", base_to_world=T)
    if result.best_cycle is not None:
        session.add_trajectory("best_cycle", result.best_cycle.trajectory)
    world = np.column_stack([result.candidates[:, :3], np.ones(len(result.candidates))])
    in_base = (np.linalg.inv(T) @ world.T).T[:, :3]
    session.add_workspace("candidates_picks_per_minute", points=in_base,
                          manipulability=np.asarray(result.picks_per_minute, dtype=float))
    if cell is not None:
        if carry:
            cell = cell.with_arm_base(result.robot, T, carry=tuple(carry))
        for fixture in cell.fixtures:
            for k, shape in enumerate(fixture.shapes):
                if shape.kind == "box":
                    size = shape.size
                elif shape.kind in ("cylinder", "capsule"):
                    size = (2 * shape.size[0], 2 * shape.size[0], shape.size[1])
                else:
                    continue
                name = fixture.name if len(fixture.shapes) == 1 else f"{fixture.name}_{k}"
                session.add_box(name, size, shape.shape_to_world, color=(0.7, 0.7, 0.7, 1.0))
    session.add_points("picks", result.picks, kind="target")
    session.add_points("places", result.places, kind="target")
    return session
