"""The shipped cells' planned motions (the demo's), for the MuJoCo re-check, the controller files and SRDF states.

- ``aubo_food_station``: the table → crate cycle keeping 20 mm (the demo's cell study);
- ``aubo_crate_guard``: the planned move food table → crate under the guard (the fastest of seed 001's seeded searches);
- ``mushroom_line``: each SCARA's cycle keeping 20 mm, and the two-arm line schedule.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, TYPE_CHECKING

import numpy as np

from pinarms.errors import InvalidInput

from pinarms.export.srdf import cycle_states

if TYPE_CHECKING:
    from pinarms.robots.cell.cell import Cell

__all__ = ["ShippedMotion", "shipped_motions", "study_states", "STUDY_CELLS"]

#: The built-in cells with study poses (:func:`study_states`).
STUDY_CELLS = ("aubo_food_station", "mushroom_line")


@dataclass(frozen=True, eq=False)
class ShippedMotion:
    """One planned motion: ``name``, the ``cell`` it was planned in, the ``source`` and how to replay it."""

    name: str
    cell: Any
    source: Any
    arm: str | None = None
    cycles: dict = field(default_factory=dict)


def _station_cycle(station: Any) -> Any:
    from pinarms import optim
    from pinarms.optim.cycle import CellSettings, CycleRequest

    arm = station.arm("aubo")
    spec = optim.PickPlace(arm.to_base(np.array([0.36, 0.0, 0.75])), arm.to_base(np.array([0.0, -0.42, 0.77])),
                           lift=0.05, dwell=0.2)
    return optim.plan_cycle(CycleRequest(arm.robot, spec, cell=CellSettings(station, clearance=0.02)))


def _line_cycles(cell: Any, step: Any = None) -> dict[str, Any]:
    from pinarms import optim
    from pinarms.optim.cycle import CellSettings, CycleRequest
    from pinarms.studies.cell import LINE_TASKS

    cycles = {}
    for name, (pick, place) in LINE_TASKS.items():
        a = cell.arm(name)
        spec = optim.PickPlace(a.to_base(np.array(pick)), a.to_base(np.array(place)), lift=0.03, dwell=0.15)
        cycles[name] = optim.plan_cycle(CycleRequest(a.robot, spec, cell=CellSettings(cell, clearance=0.02)))
        if step is not None:
            step(name, cycles[name])
    return cycles


def study_states(cell: Cell) -> dict[str, dict[str, np.ndarray]]:
    """SRDF states of a built-in cell from the demo's cycles in it (``pick``, ``place``, ...; ``left_pick`` with several arms).

    Raises:
        InvalidInput: the cell is not one of :data:`STUDY_CELLS`.
    """
    if cell.name == "aubo_food_station":
        return {k: {"aubo": q} for k, q in cycle_states(_station_cycle(cell)).items()}
    if cell.name == "mushroom_line":
        return {f"{arm}_{k}": {arm: q} for arm, cycle in _line_cycles(cell).items()
                for k, q in cycle_states(cycle).items()}
    raise InvalidInput(f"cell {cell.name!r} has no study poses; cells with them: {', '.join(STUDY_CELLS)}")


def shipped_motions(*, line: bool = True, n_offsets: int = 24, progress: Callable[[int, int], None] | None = None) -> list[ShippedMotion]:
    """Plan the shipped motions (about 10 s; ``line=False`` skips the mushroom line, 15 s more).

    ``progress(done, total)`` is called after each motion is planned.
    """
    from pinarms import optim
    from pinarms.optim.motion.crate_guard import crate_guard_move
    from pinarms.robots.cell import load_cell

    total = 5 if line else 2
    out: list[ShippedMotion] = []

    def step() -> None:
        if progress is not None:
            progress(len(out), total)

    station = load_cell("aubo_food_station")
    out.append(ShippedMotion("station_cycle", station, _station_cycle(station), arm="aubo"))
    step()
    plan = crate_guard_move().plan
    out.append(ShippedMotion("crate_guard_move", plan.cell, plan))
    step()
    if line:
        cell = load_cell("mushroom_line")

        def add(name: str, cycle: Any) -> None:
            out.append(ShippedMotion(f"line_{name}_cycle", cell, cycle, arm=name))
            step()

        cycles = _line_cycles(cell, add)
        schedule = optim.schedule_line(cell, cycles, margin=0.01, n_offsets=n_offsets)
        out.append(ShippedMotion("line_schedule", cell, schedule, cycles=cycles))
        step()
    return out
