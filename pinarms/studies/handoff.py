"""The demo's hand-off study: what pinarms planned, opened by the team's other tools.

- **MuJoCo re-checks** the demo's planned cell motions (the AUBO-i3 station's crate cycle,
  the planned move under the crate guard, each SCARA's cycle on the mushroom line and the
  two-arm schedule) through the exported MJCF: smallest distance by each engine, the
  largest difference, contacts (:func:`pinarms.export.compare_in_mujoco`).
- **MoveIt**: the mushroom line as URDF + SRDF + MJCF, with the studies' pick and place
  poses as named states; the SRDF's ``disable_collisions`` by reason, "Never" only where
  pinarms proved the pair out of reach (:func:`pinarms.export.export_cell`).
- **A controller**: the left SCARA's cycle as a ROS 2 ``JointTrajectory`` (YAML) and CSV at
  500 Hz, read back and compared with the planned trajectory
  (:func:`pinarms.export.controller_trajectory`).

The files land in the demo's ``export/`` folder (``export/mushroom_line/``,
``export/controller/``).
"""

from __future__ import annotations

import re
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["demo_study", "handoff_motions", "CONTROLLER_RATE_HZ"]

#: Rate of the demo's controller files [Hz].
CONTROLLER_RATE_HZ = 500.0

_SEED_OF_CELL = {"aubo_food_station": "001", "aubo_crate_guard": "001", "mushroom_line": "000"}
_WHAT = {
    "station_cycle": "aubo_food_station table → crate cycle (20 mm)",
    "crate_guard_move": "planned move under the crate guard (10 mm)",
    "line_left_cycle": "mushroom_line left SCARA cycle (20 mm)",
    "line_right_cycle": "mushroom_line right SCARA cycle (20 mm)",
    "line_schedule": "mushroom_line two-arm schedule",
}


def handoff_motions() -> list:
    """The shipped motions in :func:`~pinarms.export.shipped.shipped_motions`'s order (station
    cycle, crate-guard move, the line's left and right cycles, the line schedule), taking what the
    cell study kept (:mod:`~pinarms.studies.handoff_plans`) and planning the rest; the crate-guard
    move is seed 001's (:func:`~pinarms.optim.motion.crate_guard.crate_guard_move`, planned once per
    process)."""
    from pinarms.export.shipped import ShippedMotion, shipped_motions
    from pinarms.studies.handoff_plans import KEPT_NAMES, kept
    from pinarms.optim.motion.crate_guard import crate_guard_move

    plans = kept()
    if not all(k in plans for k in KEPT_NAMES):
        return shipped_motions(line=True)
    plan = crate_guard_move().plan
    line, cycles = plans["line"], plans["line_cycles"]
    out = [ShippedMotion("station_cycle", plans["station"], plans["station_cycle"], arm="aubo"),
           ShippedMotion("crate_guard_move", plan.cell, plan)]
    out += [ShippedMotion(f"line_{name}_cycle", line, cycle, arm=name) for name, cycle in cycles.items()]
    out.append(ShippedMotion("line_schedule", line, plans["schedule"], cycles=dict(cycles)))
    return out


def _mujoco_rows(motions: list, samples: int) -> list:
    from pinarms.export import compare_in_mujoco
    from pinarms.report import Row

    rows = []
    for m in motions:
        r = compare_in_mujoco(m.cell, m.source, arm=m.arm, cycles=m.cycles or None, samples=samples)
        note = (f"pinarms (coal) {r.min_pinarms * 1e3:.4f} mm ({r.min_pinarms_pair}); max |difference| "
                f"{r.max_abs_difference:.1e} m over {r.samples} instants x {r.pairs} pairs; contacts pinarms "
                f"{r.contacts_pinarms}, MuJoCo {r.contacts_mujoco}, MuJoCo only {r.mujoco_only}"
                f"{'' if r.agrees else ' -- DISAGREE'}")
        rows.append(Row(_SEED_OF_CELL[m.cell.name], f"MuJoCo re-check: {_WHAT.get(m.name, m.name)}, smallest distance",
                        None, round(r.min_mujoco * 1e3, 4), "mm", None, note))
    return rows


def _srdf_counts(text: str) -> dict[str, int]:
    reasons = re.findall(r'<disable_collisions [^>]*reason="([A-Za-z]+)"', text)
    return {k: reasons.count(k) for k in ("Adjacent", "Never", "Default")}


def _controller_check(cycle: Any, cell: Any, arm: str, folder: Path) -> tuple[list[Path], int, float]:
    """Write the cycle's controller files; return them, the samples and the largest read-back error."""
    from pinarms.export import (controller_trajectory, read_trajectory_csv, read_trajectory_yaml,
                                write_trajectory_csv, write_trajectory_yaml)

    traj = controller_trajectory(cycle, CONTROLLER_RATE_HZ, robot=cell, arm=arm)
    folder.mkdir(parents=True, exist_ok=True)
    paths = [write_trajectory_yaml(folder / f"{arm}_cycle.yaml", traj),
             write_trajectory_csv(folder / f"{arm}_cycle.csv", traj)]
    err = 0.0
    for back in (read_trajectory_yaml(paths[0]), read_trajectory_csv(paths[1])):
        err = max(err, float(np.max(np.abs(back.positions - traj.positions))),
                  float(np.max(np.abs(back.velocities - traj.velocities))))
    return [Path(p) for p in paths], int(traj.time_ns.size), err


def demo_study(quick: bool = False) -> Any:
    """The hand-off rows (module doc) and the writers of the export files."""
    from pinarms.studies.study import Study
    from pinarms.export import export_cell, srdf_text
    from pinarms.export.srdf import cycle_states
    from pinarms.report import Row

    motions = handoff_motions()  # the cell study's plans when it ran in this process
    rows = _mujoco_rows(motions, samples=200 if quick else 400)
    line = next(m for m in motions if m.name == "line_schedule")
    cell = line.cell
    states = {f"{arm}_{k}": {arm: q} for arm, cycle in line.cycles.items() for k, q in cycle_states(cycle).items()}
    counts = _srdf_counts(srdf_text(cell, states=states))
    rows.append(Row("000", "mushroom_line SRDF for MoveIt: pairs never checked (Adjacent / Never / Default)", None,
                    (counts["Adjacent"], counts["Never"], counts["Default"]), "pairs", None,
                    f"'Never' only where proven out of reach (no sampling); the collision pairs left: "
                    f"{len(cell.pairs_for(0.0))}, as pinarms checks at contact"))
    left = line.cycles["left"]
    with tempfile.TemporaryDirectory() as tmp:  # the demo writes them again into its export/ folder
        _, n, err = _controller_check(left, cell, "left", Path(tmp))
    rows.append(Row("000", f"left SCARA cycle as ROS 2 JointTrajectory + CSV at {CONTROLLER_RATE_HZ:g} Hz: samples",
                    None, n, "", None, f"read back: largest difference {err:.1e} (rad, rad/s); every sample within "
                                       "the joint limits"))

    def controller(folder: Path) -> list[Path]:
        return _controller_check(left, cell, "left", folder)[0]

    def whole_cell(folder: Path) -> list[Path]:
        done = export_cell(cell, folder, states=states, overwrite=True)
        return [p for p in (done.urdf, done.srdf, done.mjcf) if p is not None]

    study = Study("handoff", "hand-off: MuJoCo re-check, SRDF for MoveIt, controller files", rows)
    study.exports = {"mushroom_line": whole_cell, "controller": controller}
    return study

