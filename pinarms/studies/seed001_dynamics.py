"""Seed 001, dynamics and reach: the AUBO-i3's torques under payload and its tool-down band
(:func:`pinarms.studies.seed001.study_001` calls them)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from pinarms.papers import SEED001
from pinarms.report import Row, signed_percent
from pinarms.robots import conventions as conv

from pinarms.studies.study import DEG, MM

if TYPE_CHECKING:
    from pinarms.robots import Robot

__all__ = ["AUBO_PAYLOADS_KG", "dynamics_001", "tool_down_band_001"]


#: Payloads of the AUBO-i3 rows [kg]: empty gripper, half and full rated payload (3 kg, AUBO's datasheet).
AUBO_PAYLOADS_KG = (0.0, 1.5, 3.0)

#: The AUBO-i3 pick-and-place of the dynamics rows: conveyor pick and tray place 115° apart at
#: about 0.46 m radius, inside the paper's recommended band (200 mm < r < 500 mm, z > 0).
AUBO_PICK_M, AUBO_PLACE_M = (0.45, -0.10, 0.02), (-0.10, 0.45, 0.02)


def dynamics_001(arm: Robot, table2: np.ndarray, quick: bool) -> tuple[list[Row], dict[str, Callable[[Path], Any]]]:
    """Seed 001 under joint torque limits: P1→P4 and a pick-and-place with 0, 1.5 and 3 kg.

    The paper's joints are converted to the manufacturer's convention (robots.conventions;
    the arm's real configurations, within ±170°): torques depend on the actual pose.
    """
    from pinarms import optim
    from pinarms.optim.cycle import CycleLoad, CycleRequest
    from pinarms.robots.ties import near_max

    rows: list[Row] = []
    q = conv.aubo_mdh_to_joint(table2)
    v = arm.velocity_limit
    speed = optim.minimize_time(optim.TimingRequest(q, "multi-quintic", v, method="exact"))
    for kg in AUBO_PAYLOADS_KG:
        ex = optim.minimize_time(optim.TimingRequest(q, "multi-quintic", v, method="exact", robot=arm, payload=kg,
                                                     torque_limits=True))
        ratios = ex.torque_ratios
        tight = [arm.joint_names[k] for k in near_max(ratios)]
        ref = optim.toppra_limit(ex.trajectory, v, robot=arm, payload=kg, torque_limits=True)
        rows.append(Row(
            "001", f"P1→P4 with {kg:g} kg: time-optimal under joint speed + torque (exact)", None, ex.total, "s", None,
            f"speed only {speed.total:.3f} s ({signed_percent(ex.total / speed.total - 1.0)}); peak torque/limit "
            f"{ratios.max():.3f} ({', '.join(tight)}); TOPP-RA along the same path {ref:.3f} s "
            f"(bang-bang, the path's optimum: ×{ex.total / ref:.2f})"))
        if kg == AUBO_PAYLOADS_KG[-1]:
            gens = 30 if quick else 120
            ga = optim.minimize_time(optim.TimingRequest(q, "multi-quintic", v, method="ga", seed=0, max_generations=gens,
                                     robot=arm, payload=kg, torque_limits=True))
            rows.append(Row(
                "001", f"P1→P4 with {kg:g} kg: GA under joint speed + torque", None, ga.total, "s", None,
                f"{gens} generations, seed 0; ×{ga.total / ex.total:.3f} the exact optimum above; peak torque/limit "
                f"{ga.torque_ratios.max():.3f}"))
    spec = optim.PickPlace(AUBO_PICK_M, AUBO_PLACE_M, lift=0.08, dwell=0.3)
    free = optim.plan_cycle(CycleRequest(arm, spec))
    what = "AUBO-i3 pick-and-place (r ≈ 0.46 m, 115° apart, lift 80 mm, dwell 0.3 s)"
    rows.append(Row("001", f"{what}: cycle time, joint speed only", None, free.cycle_time, "s", None,
                    f"{free.picks_per_minute:.1f} picks/min; the paper gives none"))
    for kg in AUBO_PAYLOADS_KG:
        cyc = optim.plan_cycle(CycleRequest(arm, spec, load=CycleLoad(kg, torque_limits=True)))
        tight = [arm.joint_names[k] for k in near_max(cyc.torque_ratios)]
        rows.append(Row(
            "001", f"{what}: cycle time with {kg:g} kg, speed + torque", None, cyc.cycle_time, "s", None,
            f"{cyc.picks_per_minute:.1f} picks/min ({signed_percent(cyc.cycle_time / free.cycle_time - 1.0)}); "
            f"loaded move {cyc.move_times[0]:.3f} s, empty return {cyc.move_times[1]:.3f} s; peak torque/limit "
            f"{cyc.torque_ratios.max():.3f} ({', '.join(tight)})"))

    heavy = arm.with_payload(AUBO_PAYLOADS_KG[-1])
    limited = optim.minimize_time(optim.TimingRequest(q, "multi-quintic", v, method="exact", robot=arm,
                                                      payload=AUBO_PAYLOADS_KG[-1],
                                  torque_limits=True)).trajectory

    def write(path: Path) -> Any:
        from pinarms.viz import plots as vplots

        t = np.linspace(0.0, limited.duration, 600)
        ts = np.linspace(0.0, speed.trajectory.duration, 600)
        return vplots.plot_torques(
            path, t, limited.torques(heavy, t), arm.effort_limit, joint_names=arm.joint_names,
            series={"speed-only timing (torque not checked)": (ts, speed.trajectory.torques(heavy, ts))},
            title=f"seed 001: P1→P4 with {AUBO_PAYLOADS_KG[-1]:g} kg, joint torques against the limits")

    return rows, {"torques": write}


def tool_down_band_001(arm: Robot, quick: bool) -> tuple[list[Row], Any, Callable[[Path], Any]]:
    """The paper's table band (z > 0, 200 mm < r < 500 mm around its sphere centre) over the
    tool-down reachability map of the tcp (15° cone, roll free; coarse voxels to stay fast).

    ``quick`` is accepted for symmetry with the other helpers; the map is the same either way."""
    from pinarms.robots.reach.reachability import reachability_map

    paper = SEED001
    res = 0.06  # the same map in quick and full runs (about 4 s on one core): the rows are reproducible
    m = reachability_map(arm, res, 6, tool_down=15.0 * DEG, roll_steps=6)
    centre = paper.sphere_centre_m
    c = m.centres()
    r = np.linalg.norm(c - centre, axis=1)
    up = c[:, 2] > paper.table_z_min_mm * MM
    band = up & (r > paper.table_r_min_mm * MM) & (r < paper.table_r_max_mm * MM)
    outside = up & (r >= paper.table_r_max_mm * MM) & (r < paper.table_r_max_mm * MM + 0.1)
    # outer edge: the first shell (a third of a voxel wide) beyond r_min whose mean index is below 0.5
    width = res / 3.0
    edge = float("nan")
    for k in range(int(np.ceil((r.max() - paper.table_r_min_mm * MM) / width))):
        lo = paper.table_r_min_mm * MM + k * width
        sel = up & (r >= lo) & (r < lo + width)
        if sel.any() and m.index[sel].mean() < 0.5:
            edge = lo
            break
    unreached = band & (m.index == 0)
    top = float(c[unreached, 2].min()) if unreached.any() else float("nan")
    what = f"tool-down map ({res * 1000:.0f} mm voxels, tcp z within 15° of down, any roll)"
    rows = [
        Row("001", f"{what}: mean index in the paper's table band", "recommended band",
            round(float(m.index[band].mean()), 3), "", None,
            "z > 0, 200 < r < 500 mm around the paper's sphere centre; kinematics only (no collisions)"),
        Row("001", "tool-down map: band voxels reached pointing down (index > 0)", None,
            round(float(np.mean(m.index[band] > 0)), 3), "share", None,
            f"the unreached band voxels all lie at z >= {top / MM:.0f} mm (the band's top, above the shoulder)"),
        Row("001", "tool-down map: mean index just outside the band (500-600 mm, z > 0)", "sparse, near-singular",
            round(float(m.index[outside].mean()), 3), "", None, "the paper's 'sparse between 500 and 600 mm'"),
        Row("001", "tool-down map: outer edge of the band (first shell with mean index < 0.5)", paper.table_r_max_mm,
            round(edge / MM, 1), "mm", res / MM,
            f"shells {width * 1000:.0f} mm wide from r = 200 mm, z > 0; tolerance one voxel"),
    ]
    band_spec = {"centre": centre, "r_inner": paper.table_r_min_mm * MM, "r_outer": paper.table_r_max_mm * MM,
                 "z_min": paper.table_z_min_mm * MM, "label": "paper's table band (z > 0, 200 < r < 500 mm)"}

    def plot(path: Path) -> Any:
        from pinarms.viz.reach_plots import plot_reachability_section

        return plot_reachability_section(path, m, band=band_spec,
                                         title=f"seed 001: AUBO-i3 {what}, paper's table band in red")

    return rows, m, plot
