"""The cell study: two SCARAs of ``mushroom_line`` on one belt and the AUBO-i3's crate cycle in
``aubo_food_station`` (:func:`study_cell`, docs/cells.md)."""

from __future__ import annotations

import numpy as np

from pinarms.report import Row

from pinarms.studies.handoff_plans import remember
from pinarms.studies.study import MM, Study

__all__ = ["study_cell", "LINE_TASKS"]


#: The mushroom line's tasks: each SCARA picks in the middle of the belt and places in its
#: own packing box (world frame, m).
LINE_TASKS = {"left": ((-0.05, -0.03, 0.84), (0.22, 0.68, 0.84)), "right": ((0.05, 0.03, 0.84), (0.22, -0.68, 0.84))}


def study_cell(quick: bool = False) -> Study:
    """Cells: the two-SCARA mushroom line scheduled on one belt, and the AUBO-i3 food station's crate cycle."""
    from pinarms import optim, viz
    from pinarms.optim.cycle import CellSettings, CycleRequest
    from pinarms.robots.cell import ArmMotion, load_cell
    from pinarms.viz import plots as vplots

    rows: list[Row] = []
    line = load_cell("mushroom_line")
    cycles = {}
    for name, (pick, place) in LINE_TASKS.items():
        arm = line.arm(name)
        spec = optim.PickPlace(arm.to_base(np.array(pick)), arm.to_base(np.array(place)), lift=0.03, dwell=0.15)
        request = CycleRequest(arm.robot, spec, cell=CellSettings(line, clearance=0.02))
        cycles[name] = optim.plan_cycle(request).raise_for_status()
    for name, res in cycles.items():
        rep = res.cell_report
        rows.append(Row("000", f"mushroom_line, {name} SCARA: cycle keeping 20 mm from belt, box and the other arm",
                        None, res.cycle_time, "s", None,
                        f"lift raised 30 → {rep.lift / MM:.0f} mm after {len(rep.attempts)} attempts: "
                        f"+{rep.extra_time:.3f} s against the cycle through the box wall"))
    schedule = optim.schedule_line(line, cycles, margin=0.01, n_offsets=24)
    rows.append(Row("000", "mushroom_line, two SCARAs on one belt: line rate (every time offset checked continuously)",
                    None, schedule.picks_per_minute, "1/min", None,
                    f"period {schedule.period:.3f} s, right arm {schedule.offsets['right']:.3f} s behind; "
                    f"{int(schedule.clear.sum())} of {schedule.clear.size} offsets collision-free"))
    rows.append(Row("000", "mushroom_line: one SCARA alone (its own cycle)", None,
                    schedule.single_arm_picks_per_minute["left"], "1/min", None, "the paper's line has one arm"))
    rows.append(Row("000", "mushroom_line: closest approach of the two arms over a period", None,
                    schedule.arm_check.min_clearance / MM, "mm", None,
                    "exact distance at every sample of the continuous check"))

    station = load_cell("aubo_food_station")
    arm = station.arm("aubo")
    spec = optim.PickPlace(arm.to_base(np.array([0.36, 0.0, 0.75])), arm.to_base(np.array([0.0, -0.42, 0.77])),
                           lift=0.05, dwell=0.2)
    crate = optim.plan_cycle(CycleRequest(arm.robot, spec, cell=CellSettings(station, clearance=0.02)))
    crate.raise_for_status()
    rep = crate.cell_report
    rows.append(Row("001", "aubo_food_station: table → crate cycle keeping 20 mm (table and crate in the band)",
                    None, crate.cycle_time, "s", None,
                    f"lift 50 → {rep.lift / MM:.0f} mm: +{rep.extra_time:.3f} s against the cycle through the crate wall"))

    remember(line=line, line_cycles=cycles, schedule=schedule, station=station, station_cycle=crate)  # hand-off study
    motions = [ArmMotion(n, cycles[n].trajectory, schedule.offsets[n], schedule.period) for n in schedule.arms]
    session = viz.Session(title="cells: mushroom_line, two SCARAs on one belt")
    session.add_cell(line, motions=motions, name="two-arm schedule", hz=50.0)
    plots = {
        "schedule": lambda path: vplots.plot_schedule(path, schedule),
        "clearance": lambda path: vplots.plot_clearance(path, schedule.arm_check,
                                                       title="mushroom_line: distance between the two arms"),
    }
    return Study("cell", "cells: two SCARAs on one belt, AUBO-i3 food station", rows, session, plots)
