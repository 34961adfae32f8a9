"""Seed 004: the koji-block turner of the paper, redone with pinarms (:func:`study_004`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms import robots
from pinarms.papers import SEED004
from pinarms.report import Row, signed_percent
from pinarms.robots import conventions as conv

from pinarms.optim.cycle.vertical import segment_distance
from pinarms.studies.study import DEG, MM, Study, trajectory_plots, study_session

__all__ = ["study_004", "KOJI_LIFT_M", "KOJI_BLOCK_KG"]


def _print_step(value: float) -> float:
    """Last printed digit of a paper value (-19.8 → 0.1, 13.625 → 0.001); whole numbers taken as exact (0)."""
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    if "." not in text:
        return 0.0
    return 10.0 ** (-len(text.split(".")[1]))


def study_004(quick: bool = False) -> Study:
    """Koji turner: the paper's forward-kinematics examples, its IK example, the joint-rate simulation."""
    from pinarms import planning

    arm = robots.load("koji_turner")
    paper = SEED004
    rows: list[Row] = []
    # FK examples in the paper's order (section 2); the second has no printed θ4: pinarms takes
    # θ4 = −θ1 like the other two (hand heading kept, R = I).
    angles_deg = np.array(paper.fk_angles_deg)
    angles_deg[:, 3] = np.where(np.isnan(angles_deg[:, 3]), -angles_deg[:, 0], angles_deg[:, 3])
    notes = {
        (0, 2): "printed z does not follow from the printed angles (typo): ours is the FK",
        (1, 0): "printed x does not follow (typo or other θ4); y/z reproduced",
        (1, 1): "paper prints 1005.1 and 1105 (simulation); θ4 not printed, 49.5° assumed",
    }
    for i, (printed_deg, angles, xyz) in enumerate(zip(paper.fk_angles_deg, angles_deg, paper.fk_positions_mm)):
        q = angles * DEG
        p = arm.position(q) / MM
        # tolerance: 0.05 mm print rounding + the effect of the angles' print rounding
        step = np.array([_print_step(x) for x in printed_deg]) * DEG / 2
        J = arm.jacobian(q)[:3] / MM
        tol = 0.05 + np.abs(J) @ step
        for k, axis in enumerate("xyz"):
            rows.append(Row("004", f"FK example {i + 1} {axis}", xyz[k], float(np.round(p[k], 2)), "mm",
                            float(np.round(tol[k], 2)), notes.get((i, k), "")
                            if abs(p[k] - xyz[k]) > tol[k] else ""))

    # IK example (section 3): the closed-form branch nearest the paper's answer, limits ignored
    target = np.eye(4)
    target[:3, 3] = paper.ik_target_m
    answer_deg = paper.ik_answer_deg
    sols = arm.ik_all(target, respect_limits=False)
    from pinarms.robots.ties import argmin_tied

    best = sols[argmin_tied(np.abs(sols[:, :3] / DEG - answer_deg).max(axis=1))] / DEG
    # tolerance: the error the paper itself states for its one-decimal target (section 3)
    ik_note = ("ours solve the printed target (the FK rounded to 0.1 mm); the paper's digits follow from x rounded "
               "to 1197.0 mm (docs/ik.md)")
    for k, label in enumerate(("θ1", "θ2 upper arm", "θ3 forearm")):
        rows.append(Row("004", f"IK of ({', '.join(f'{x:g}' for x in paper.ik_target_mm)}) mm: {label}",
                        float(answer_deg[k]), float(best[k]), "deg", paper.ik_stated_error_deg, ik_note if k else ""))
    in_limits = arm.ik_all(target)
    note = ""
    if in_limits.shape[0] != 1 and arm.ik_failure_reason(target) is not None:
        lo, hi = arm.lower / DEG, arm.upper / DEG
        past = [f"{name} {best[k]:.4f}° past its {hi[k] if best[k] > hi[k] else lo[k]:g}° end"
                for k, name in enumerate(arm.joint_names) if not lo[k] <= best[k] <= hi[k]]
        note = "needs " + ", ".join(past) + f" (ik_failure_reason); the paper keeps its {paper.ik_theta2_deg}° anyway"
    rows.append(Row("004", "IK solutions within the joint ranges", 1, int(in_limits.shape[0]), "-", 0, note))

    rates = paper.simulation_rates_rad_s
    q0 = np.array([45.0, 0.0, -30.0, -45.0]) * DEG
    t = np.linspace(0.0, paper.simulation_duration_s, 101)
    q_t = q0 + t[:, None] * rates
    p_model = arm.position(q_t)
    p_paper = conv.koji_fk_paper(q_t)[:, :3, 3]
    rows.append(Row("004", "simulation 10 s at (-9, 2.5, 3, 9) deg/s: |p_model - p_paper FK|", 0.0,
                    float(np.max(np.linalg.norm(p_model - p_paper, axis=1)) / MM), "mm", 1e-6,
                    "URDF model with mimic parallelogram vs the paper's closed form"))

    lift_rows, lift = _koji_lift_004(arm, angles_deg[0] * DEG)
    rows.extend(lift_rows)
    rows.extend(_koji_block_rows(arm))

    session = study_session(arm, "seed 004: koji turner, joints at constant rates")
    session.add_trajectory("block_lifted_straight_up", lift.trajectory, hz=200.0)
    knots = np.linspace(0.0, paper.simulation_duration_s, 6)
    traj = planning.multi_quintic(knots, q0 + knots[:, None] * rates,
                                  velocities=np.tile(rates, (6, 1)), accelerations=np.zeros((6, 4)))
    session.add_trajectory("constant_rates_10s", traj)
    session.add_points("fk_examples", arm.position(angles_deg * DEG), kind="target")
    plots = trajectory_plots(traj, planning.JointLimits(arm.velocity_limit), None, "seed 004: joint rates", robot=arm)
    return Study("004", "koji-block turner: FK examples, IK, simulation", rows, session, plots)


#: Height [m] the koji block is lifted straight up in seed 004's study (pinarms's choice: a block's
#: clearance above the stack; 0.15 m is where that lift leaves the arm's workspace).
KOJI_LIFT_M = 0.1


def _koji_lift_004(arm: Any, q0: np.ndarray) -> tuple[list[Row], Any]:
    """The block at FK example 1 lifted straight up ``KOJI_LIFT_M``, beside a joint-space lift."""
    from pinarms import optim, planning

    T0 = arm.fk(q0)
    T1 = T0.copy()
    T1[2, 3] += KOJI_LIFT_M
    path = planning.cartesian_path(arm, np.stack([T0, T1]), q_start=q0)
    v = planning.JointVelocityConstraint(arm.velocity_limit)
    straight = optim.time_scaled(path, [v], shape="quintic")
    joint_line = planning.joint_spline(path.q_knots[[0, -1]])
    joint = optim.time_scaled(joint_line, [v], shape="quintic")
    s = np.linspace(0.0, path.length, 10 * (path.breaks.size - 1) + 1)
    off = segment_distance(arm.position(path(s)), T0[:3, 3], T1[:3, 3]).max()
    bow = segment_distance(arm.position(joint_line(np.linspace(0.0, joint_line.length, 2001))), T0[:3, 3],
                            T1[:3, 3]).max()
    mm = f"{KOJI_LIFT_M / MM:.0f} mm"
    return [
        Row("004", f"block lifted straight up {mm} from FK example 1: tcp off the vertical", None,
            float(np.round(off / MM, 4)), "mm", None, f"Cartesian path, 0.1 mm tolerance; FK at 10x its {path.breaks.size} knots"),
        Row("004", "the same lift as a joint-space line: tcp off the vertical", None, float(np.round(bow / MM, 3)), "mm",
            None, "joints linear between the same two configurations: the hand bows"),
        Row("004", f"straight {mm} lift, quintic time law at the joint speed limits", None,
            float(np.round(straight.duration, 4)), "s", None,
            f"joint-space line at the same limits {joint.duration:.4f} s (straight costs "
            f"{100 * (straight.duration / joint.duration - 1):.1f} %)"),
    ], straight


#: Mass [kg] of one koji block as pinarms assumes it (the paper gives none): a pressed block of moist
#: wheat koji about 0.32 × 0.19 × 0.055 m (3.3 dm³) at about 1.2 kg/dm³ (docs/robots/koji_turner.md).
KOJI_BLOCK_KG = 4.0


def _koji_block_rows(arm: Any) -> list[Row]:
    """The koji arm turning one block: lift it, swing 90°, turn it 90° on the wrist, set it down (and back)."""
    from pinarms import optim
    from pinarms.optim import InfeasibleProblem
    from pinarms.optim.cycle import CycleLoad, CycleRequest
    from pinarms.robots.ties import near_max

    q_pick = np.array([0.0, 0.15, -0.35, 0.0])
    q_place = np.array([np.pi / 2, 0.15, -0.35, np.pi / 2])
    spec = optim.PickPlace(arm.fk(q_pick), arm.fk(q_place), lift=0.10, dwell=0.5)
    free = optim.plan_cycle(CycleRequest(arm, spec))
    what = "koji block turn (swing 90°, turn the block 90°, lift 0.1 m, dwell 0.5 s)"
    rows = [Row("004", f"{what}: cycle time, joint speed only", None, free.cycle_time, "s", None,
                "the paper times no cycle; joint speeds of the model (0.3–1 rad/s)")]
    loaded = optim.plan_cycle(CycleRequest(arm, spec, load=CycleLoad(KOJI_BLOCK_KG, torque_limits=True)))
    tight = [arm.joint_names[k] for k in near_max(loaded.torque_ratios)]
    rows.append(Row("004", f"{what}: cycle time with one {KOJI_BLOCK_KG:g} kg block, speed + torque", None,
                    loaded.cycle_time, "s", None,
                    f"block mass assumed (0.32 × 0.19 × 0.055 m of pressed moist koji, ≈1.2 kg/dm³); "
                    f"{signed_percent(loaded.cycle_time / free.cycle_time - 1.0)}; peak torque/limit "
                    f"{loaded.torque_ratios.max():.3f} ({', '.join(tight)})"))
    try:
        optim.plan_cycle(CycleRequest(arm, spec, load=CycleLoad(2 * KOJI_BLOCK_KG, torque_limits=True)))
        two = "feasible"
    except InfeasibleProblem as exc:
        two = str(exc).split(":")[1].split(";")[0].strip()
    rows.append(Row("004", f"{what}: two blocks ({2 * KOJI_BLOCK_KG:g} kg) at once", None,
                    "infeasible" if two != "feasible" else "feasible", "", None,
                    f"{two}; efforts sized for one block, no balancing cylinder or counterweight modelled "
                    "(the paper's fig. 1 has both)"))
    return rows
