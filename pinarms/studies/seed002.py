"""Seed 002: the gantry flower-handling path of the paper, redone with pinarms (:func:`study_002`)."""

from __future__ import annotations

import numpy as np

from pinarms import robots
from pinarms.papers import SEED002
from pinarms.report import Row
from pinarms.robots import conventions as conv

from pinarms.studies.study import Study, trajectory_plots, study_session

__all__ = ["study_002", "BOUNDS_002_S"]


#: Segment-time bounds (s) of the seed-002 searches: from the paper's 0.001 s precision up to
#: 0.5 s (pinarms's choice: about twice the paper's longest segment, 0.27 s).
BOUNDS_002_S = (SEED002.precision_s, 0.5)


def study_002(quick: bool = False) -> Study:
    """Flower gantry: quintic B-spline through 10 segments, improved-GA time (and time–jerk) optimisation, cycle."""
    from pinarms import optim, planning
    from pinarms.optim.cycle import CycleRequest, CycleTiming
    from pinarms.scenarios import GANTRY_PATH_AXIS_M, gantry_path_motor_rad

    arm = robots.load("gantry_flower")
    paper = SEED002
    path = gantry_path_motor_rad()
    v, a, j = paper.limits_motor
    h0 = paper.initial_durations_s
    t0_printed = paper.initial_total_s
    initial = planning.quintic_bspline(np.concatenate([[0.0], np.cumsum(h0)]), path)
    rows: list[Row] = [Row("002", "initial total time (10 segments)", t0_printed, float(initial.duration), "s", 1e-9)]
    gens = 60 if quick else 300
    settings = optim.GASettings.seed002()
    totals = []
    for k in range(3):
        res = optim.minimize_time(optim.TimingRequest(path[:, k], "quintic-bspline", v, a, j, method="ga", seed=k,
                                  settings=settings, max_generations=gens, initial=h0[None, :],
                                  bounds=BOUNDS_002_S))
        totals.append(res.total)
        rows.append(Row("002", f"time-optimal total, joint {k + 1} alone", paper.per_joint_totals_s[k], res.total, "s",
                        None, "the paper's via points are not printed: ours is a representative path"))
    for k in range(3):
        rows.append(Row("002", f"time saved vs 1.89 s, joint {k + 1}",
                        100.0 * (1 - paper.per_joint_totals_s[k] / t0_printed), 100.0 * (1 - totals[k] / t0_printed),
                        "%", None, "depends on the unpublished via points"))
    together = optim.minimize_time(optim.TimingRequest(path, "quintic-bspline", v, a, j, method="ga", seed=0,
                                                       settings=settings,
                                   max_generations=gens, initial=h0[None, :], bounds=BOUNDS_002_S))
    rows.append(Row("002", "time-optimal total, 3 joints together", None, together.total, "s", None,
                    "one timing shared by all axes (what a real gantry runs)"))
    exact = optim.minimize_time(optim.TimingRequest(path, "quintic-bspline", v, a, j, method="exact", seed=0,
                                                    bounds=BOUNDS_002_S))
    rows.append(Row("002", "time-optimal total, 3 joints, deterministic optimiser", None, exact.total, "s", None,
                    "reference for the GA row above (GA ≥ this; equal when converged)"))
    # jerk continuity of the quintic B-spline at the interior knots (C^4: jerk continuous)
    kt = together.trajectory.knot_times[1:-1]
    eps = 1e-9
    jl = together.trajectory.sample(kt - eps)[3]
    jr = together.trajectory.sample(kt + eps)[3]
    jump = float(np.max(np.abs(jr - jl)) / j)
    rows.append(Row("002", "jerk jump at interior knots / jerk limit", 0.0, jump, "-", 1e-4,
                    "quintic B-spline is C4: jerk continuous"))
    tj = optim.minimize_time_jerk(optim.TimingRequest(path, "quintic-bspline", v, a, j, seed=0, settings=settings,
                                  max_generations=gens, bounds=BOUNDS_002_S))
    rows.append(Row("002", "time–jerk two-stage: total", None, float(tj.total), "s", None,
                    "minimum jerk with the total at most 1.05 × its own stage-one optimum"))

    # the whole cycle of that move: clamp, lift-feed-lower, release, and back (dwell 0.2 s, pinarms's choice)
    transmission = conv.GANTRY_TRANSMISSION_M_PER_RAD
    tcp = arm.position(np.array(GANTRY_PATH_AXIS_M))
    spec = optim.PickPlace(tcp[0], tcp[-1], lift=float(tcp[1, 2] - tcp[0, 2]), dwell=0.2, via=list(tcp[2:-2]))
    timing = CycleTiming("quintic-bspline", arm.velocity_limit, a * transmission, j * transmission)
    cycle = optim.plan_cycle(CycleRequest(arm, spec, timing=timing))
    what = ("pick-and-place cycle of the gantry (the lift-feed-lower move and back, dwell 0.2 s, axis limits "
            f"{arm.velocity_limit[0]:g} m/s of the model, {a * transmission:g} m/s², {j * transmission:g} m/s³)")
    rows.append(Row("002", f"{what}: cycle time", None, cycle.cycle_time, "s", None,
                    f"moves {cycle.move_times[0]:.3f} + {cycle.move_times[1]:.3f} s (optim.plan_cycle, exact)"))
    rows.append(Row("002", f"{what}: picks per minute", paper.grasps_per_minute, cycle.picks_per_minute, "1/min",
                    None, "different path (the paper's is not printed), limits of the model, not the machine's"))

    session = study_session(arm, "seed 002: flower gantry, quintic B-spline, improved GA")
    axis_traj = planning.quintic_bspline(together.knot_times, path * transmission)
    session.add_trajectory("lift-feed-lower_time_optimal", axis_traj)
    session.add_points("via_points", arm.position(np.array(GANTRY_PATH_AXIS_M)), kind="via")
    session.add_history("improved_ga_3axes", together.history)
    limits = planning.JointLimits(v, a, j)
    plots = trajectory_plots(together.trajectory, limits, together.history, "seed 002: motor side, time-optimal B-spline",
                   joint_names=[f"{name} motor" for name in arm.joint_names], joint_units=["rad"] * 3)
    return Study("002", "flower gantry: quintic B-spline + improved GA", rows, session, plots)
