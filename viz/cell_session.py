"""A cell in a session: its arms and fixtures as one robot, their motions as one trajectory, contacts as points.

:meth:`pinarms.viz.Session.add_cell` stores a :class:`pinarms.robots.cell.Cell` with its URDF embedded (poses
in the world frame), the arms' motions sampled over their window as one trajectory of the
whole cell (the viewer animates all arms together), the arms' tcp frames in
``metadata["cells"]`` (the viewer draws each arm's tcp path) and, from a motion check, the
samples in contact as a red point set.
"""

from __future__ import annotations

from typing import Any, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.robots.cell import Cell
from pinarms.robots.cell.timeline import arm_motions, configurations, sample_motions
from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.robots.cell.motion_report import MotionCheck

__all__ = ["add_cell"]


def add_cell(session: Any, cell: Cell, *, key: str | None = None, motions: Any = None, check: MotionCheck | None = None,
             name: str = "cell motion", hz: float = 100.0, hold: ArrayLike | None = None) -> str:
    """Add ``cell`` to ``session`` (:meth:`pinarms.viz.Session.add_cell` says how); return its robot key."""
    if not isinstance(cell, Cell):
        raise InvalidInput(f"cell must be a robots.cell.Cell, got {type(cell).__name__}")
    hold_q = cell.hold if hold is None else cell.robot.check_q(hold)[0][0]
    key = session.add_robot(cell.robot, key=cell.name if key is None else key)
    session.metadata.setdefault("cells", {})[key] = {
        "name": cell.name,
        "args": dict(cell.args),
        "arms": {a.name: {"tcp_frame": a.prefix + a.robot.tcp_frame, "q_start": a.q_slice.start,
                          "q_stop": a.q_slice.stop} for a in cell.arms},
        "fixtures": [f.name for f in cell.fixtures],
        "hold": [float(v) for v in hold_q],
    }
    if motions is not None:
        t, q = sample_motions(cell, motions, hz=hz, window=None if check is None else check.window, hold=hold_q)
        session.add_trajectory(name, (t, q), robot=key)
    if check is not None:
        if motions is None:
            raise InvalidInput("a check needs the motions it was made of (motions=...)")
        inside = np.flatnonzero(np.asarray(check.clearance) <= 0.0)
        if inside.size:  # at most 400 contact samples, evenly spread
            inside = inside[np.linspace(0, inside.size - 1, min(inside.size, 400)).round().astype(int)]
            qs = configurations(cell, arm_motions(cell, motions), np.asarray(check.times)[inside], hold_q)
            cl = cell.clearance(qs)
            session.add_points(f"{name} contacts", 0.5 * (cl.point_a + cl.point_b), kind="contact")
    return key

