"""The shipped cells' planned motions (the demo's), for the MuJoCo re-check and the controller files.

- ``aubo_food_station``: the table → crate cycle keeping 20 mm (the demo's cell study);
- ``aubo_crate_guard``: the planned move food table → crate under the guard (OMPL, seed 0);
- ``mushroom_line``: each SCARA's cycle keeping 20 mm, and the two-arm line schedule.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["ShippedMotion", "shipped_motions"]


@dataclass(frozen=True, eq=False)
class ShippedMotion:
    """One planned motion: ``name``, the ``cell`` it was planned in, the ``source`` and how to replay it."""

    name: str
    cell: Any
    source: Any
    arm: str | None = None
    cycles: dict = field(default_factory=dict)


def shipped_motions(*, line: bool = True, n_offsets: int = 24, progress: Any = None) -> list[ShippedMotion]:
    """Plan the shipped motions (about 10 s; ``line=False`` skips the mushroom line, 15 s more).

    ``progress(done, total)`` is called after each motion is planned.
    """
    total = 5 if line else 2

    def step(done: int) -> None:
        if progress is not None:
            progress(done, total)

    from pinarms import optim
    from pinarms.demo import LINE_TASKS, _planned_move_001
    from pinarms.robots.cell import load_cell

    out = []
    station = load_cell("aubo_food_station")
    arm = station.arm("aubo")
    spec = optim.PickPlace(arm.to_base(np.array([0.36, 0.0, 0.75])), arm.to_base(np.array([0.0, -0.42, 0.77])),
                           lift=0.05, dwell=0.2)
    out.append(ShippedMotion("station_cycle", station, optim.plan_cycle(arm.robot, spec, cell=station, clearance=0.02),
                             arm="aubo"))
    step(1)
    plan = _planned_move_001()[1]["plan"]
    out.append(ShippedMotion("crate_guard_move", plan.cell, plan))
    step(2)
    if line:
        cell = load_cell("mushroom_line")
        cycles = {}
        for name, (pick, place) in LINE_TASKS.items():
            a = cell.arm(name)
            spec = optim.PickPlace(a.to_base(np.array(pick)), a.to_base(np.array(place)), lift=0.03, dwell=0.15)
            cycles[name] = optim.plan_cycle(a.robot, spec, cell=cell, clearance=0.02)
            out.append(ShippedMotion(f"line_{name}_cycle", cell, cycles[name], arm=name))
            step(len(out))
        schedule = optim.schedule_line(cell, cycles, margin=0.01, n_offsets=n_offsets)
        out.append(ShippedMotion("line_schedule", cell, schedule, cycles=cycles))
        step(len(out))
    return out
