"""Seed 000: the SCARA mushroom picker of the paper, redone with pinarms (:func:`study_000`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms import robots
from pinarms.papers import SEED000
from pinarms.report import Row

from pinarms.studies.study import DEG, Study, trajectory_plots, study_session

__all__ = ["study_000"]


def study_000(quick: bool = False) -> Study:
    """SCARA mushroom packer: 3-5-3 trajectory of joint 1, its GA time optimisation, the pick-and-place cycle."""
    from pinarms import optim, planning
    from pinarms.optim.cycle import CycleRequest

    arm = robots.load("scara_mushroom")
    paper = SEED000
    path = paper.path_rad
    vmax = paper.vmax_rad_s
    rows: list[Row] = []
    paper_h = np.array(paper.paper_times_s)
    peak_printed = paper.peak_velocity_deg_s
    total_printed = paper.paper_total_s

    initial = planning.piecewise_polynomial(paper.initial_knot_times_s, path, degrees=(3, 5, 3))
    v_init = float(initial.peaks().velocity[0]) / DEG
    rows.append(Row("000", "3-5-3 joint 1, times 2/2/2 s: peak |v|", None, v_init, "deg/s", None,
                    "the paper prints no peak for its initial times"))
    at_paper = planning.piecewise_polynomial(paper.paper_knot_times_s, path, degrees=(3, 5, 3))
    v_paper = float(at_paper.peaks().velocity[0]) / DEG
    rows.append(Row("000", "3-5-3 at the paper's optimised times: peak |v|", peak_printed, v_paper, "deg/s", 0.1,
                    "" if abs(v_paper - peak_printed) <= 0.1 else
                    "exact peak of the paper's own 3-5-3 at its times; its 54.2 does not follow (limit 55)"))

    settings = optim.GASettings.seed000()
    gens = 60 if quick else 200
    ga = optim.minimize_time(optim.TimingRequest(path, "3-5-3", vmax, method="ga", seed=0, settings=settings,
                             max_generations=gens, initial=np.array([paper.initial_times_s])))
    exact = optim.minimize_time(optim.TimingRequest(path, "3-5-3", vmax, method="exact", seed=0))
    rows.append(Row("000", "initial total time", paper.initial_total_s, float(initial.duration), "s", 1e-12))
    rows.append(Row("000", "GA optimised total time", total_printed, ga.total, "s", 0.05,
                    "" if abs(ga.total - total_printed) <= 0.05 else
                    "the paper's times are not tight: at them the exact peak is well under 55 deg/s"))
    rows.append(Row("000", "GA segment times t1, t2, t3", tuple(paper_h), tuple(ga.durations), "s", 0.1,
                    "" if np.max(np.abs(ga.durations - paper_h)) <= 0.1 else
                    "shorter total (see above); the split follows the path's segment lengths"))
    rows.append(Row("000", "GA peak |v| joint 1", peak_printed, float(ga.peaks.velocity[0]) / DEG, "deg/s", 1.0,
                    "ours touches the 55 deg/s limit by construction (rescaled)"))
    rows.append(Row("000", "deterministic optimum (scaling-law) total", total_printed, exact.total, "s", 0.05,
                    "" if abs(exact.total - total_printed) <= 0.05 else
                    "the true optimum under 55 deg/s; the paper's GA stopped short of it"))
    reduction = 100.0 * (1.0 - ga.total / paper.initial_total_s)
    rows.append(Row("000", "total time reduced by", paper.reduction_percent, reduction, "%", 1.0,
                    "" if abs(reduction - paper.reduction_percent) <= 1.0 else "follows from the totals above"))

    session = study_session(arm, "seed 000: SCARA 3-5-3 time-optimal (joint 1)")
    # joints 2-4 held still for the animation (the paper studies joint 1 only)
    hold = np.clip(np.array([0.0, 60.0 * DEG, 0.05, 0.0]), arm.lower, arm.upper)
    q_via = np.tile(hold, (4, 1))
    q_via[:, 0] = path

    # the whole pick-and-place cycle between the same pick (conveyor) and place (box) poses
    spec = optim.PickPlace(arm.fk(q_via[0]), arm.fk(q_via[-1]), lift=0.05, dwell=0.2)
    cycle = optim.plan_cycle(CycleRequest(arm, spec, q_start=q_via[0]))
    what = ("pick-and-place cycle of the SCARA (pick on the conveyor, place in the box, lift 50 mm, dwell 0.2 s, "
            "joint limits of the model)")
    why = (f"the paper gives none for the SCARA; moves {cycle.move_times[0]:.3f} + {cycle.move_times[1]:.3f} s "
           "(optim.plan_cycle, exact)")
    rows.append(Row("000", f"{what}: cycle time", None, cycle.cycle_time, "s", None, why))
    rows.append(Row("000", f"{what}: picks per minute", None, cycle.picks_per_minute, "1/min", None,
                    "the paper gives none for the SCARA"))
    session.add_trajectory("pick_place_cycle", cycle.trajectory)
    anim = planning.piecewise_polynomial(ga.knot_times, q_via, degrees=(3, 5, 3))
    session.add_trajectory("353_optimised", anim)
    session.add_trajectory("353_initial_2-2-2s",
                           planning.piecewise_polynomial(paper.initial_knot_times_s, q_via, degrees=(3, 5, 3)))
    session.add_history("ga_time", ga.history)
    _add_line_objects(session, arm.position(q_via[0]), arm.position(q_via[-1]))
    # the paper draws its joint curves in degrees: so do ours (joint 1 is revolute)
    plots = trajectory_plots(ga.trajectory, planning.JointLimits(vmax), ga.history, "seed 000: joint 1, 3-5-3 optimised",
                   degrees=True, joint_names=[arm.joint_names[0]], joint_units=[arm.joint_units[0]])
    return Study("000", "SCARA enoki-mushroom packer: 3-5-3 + GA timing", rows, session, plots)


def _add_line_objects(session: Any, pick_m: np.ndarray, place_m: np.ndarray) -> None:
    """The packing line around the SCARA: the mushroom conveyor under the pick point and
    the box under the place point (both tops 20 mm below the tool point), for the viewer."""
    belt = np.array([0.12, 0.70, 0.03])  # m: width (radial), length (tangential), thickness
    crate = np.array([0.15, 0.20, 0.10])  # m
    for name, size, at, rgba in (("mushroom_conveyor", belt, pick_m, (0.25, 0.25, 0.25, 1.0)),
                                 ("packing_box", crate, place_m, (0.80, 0.65, 0.40, 1.0))):
        yaw = np.arctan2(at[1], at[0])  # local x radial from the base axis, local y tangential
        pose = np.eye(4)
        pose[:2, :2] = [[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]
        pose[:3, 3] = [at[0], at[1], at[2] - 0.02 - size[2] / 2]
        session.add_box(name, size, pose, color=rgba)
