"""The pick-and-place cycle: ``cycle``."""

from __future__ import annotations

import click
import numpy as np

from pinarms.units import (
    length_scale,
    mass_kg,
)

from pinarms.cli._common import (
    NUMBERS,
    cli,
    emit,
    fmt,
    json_option,
    load_robot,
    new_session,
    save_session,
    si_limit,
)


# --------------------------------------------------------------------------- cycle
@cli.command("cycle", context_settings=NUMBERS)
@click.argument("robot")
@click.option("--pick", nargs=3, type=float, required=True, help="X Y Z of the pick point (base frame).")
@click.option("--place", nargs=3, type=float, required=True, help="X Y Z of the place point (base frame).")
@click.option("--via", nargs=3, type=float, multiple=True, help="X Y Z of a transfer via point (repeat, in order).")
@click.option("--lift", default=None, type=float, help="Vertical approach/retreat height [default 0.05 m, 50 mm].")
@click.option("--dwell", default=0.2, show_default=True, type=float, help="Gripper time at pick and at place [s].")
@click.option("--mm", is_flag=True, help="Points, lift and the straightness deviation in millimetres.")
@click.option("--kind", type=click.Choice(["multi-quintic", "quintic-bspline", "3-5-3"]), default="multi-quintic",
              show_default=True)
@click.option("--vmax", default=None, help="Joint speed limit(s) [rad/s or m/s], one or per joint (default: the URDF's).")
@click.option("--amax", default=None, help="Acceleration limit(s) [rad/s² or m/s²].")
@click.option("--jmax", default=None, help="Jerk limit(s) [rad/s³ or m/s³].")
@click.option("--method", type=click.Choice(["exact", "ga"]), default="exact", show_default=True)
@click.option("--seed", default=0, show_default=True, type=int, help="Random seed of the optimiser.")
@click.option("--payload", default=None,
              help="What the gripper carries from pick to place, e.g. 3kg or 800g (its centre of mass at the tcp); "
                   "times both moves also under joint torque limits (--torque-max, default the URDF's efforts).")
@click.option("--torque", "torque", is_flag=True, help="Also limit joint torques (the URDF's efforts), without a payload.")
@click.option("--torque-max", default=None, help="Joint torque limit(s) [N·m, or N for prismatic joints], one or per joint.")
@click.option("--straight", is_flag=True,
              help="Straight vertical lines at pick and place, time-optimal along them (needs --amax); "
                   "the joint-space cycle's time is reported beside it.")
@click.option("--vtool", default=None, type=float, help="With --straight: tcp speed limit on the lines [m/s, or mm/s with --mm].")
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Save the cycle (trajectory, via points, pick and place) into a session file.")
@json_option
def cycle_cmd(robot, pick, place, via, lift, dwell, mm, kind, vmax, amax, jmax, method, seed, payload, torque,
              torque_max, straight, vtool, session_path, as_json) -> None:
    """Time-optimal pick-and-place cycle of ROBOT: pick, lift, transfer, lower, place, and back.

    Prints the time of each move, the cycle time, picks per minute and how far the tcp
    leaves the straight vertical approach/retreat lines (optim.plan_cycle; the tool points
    down on 6+ joint arms). Limits are SI per joint; --mm converts only lengths.

    With --payload (or --torque) both moves are also timed under joint torque limits, the
    move to place carrying the payload and the move back empty (robots' inverse dynamics,
    Pinocchio's RNEA).

    With --straight the tcp rises and lowers on straight vertical lines (within 0.1 mm),
    timed time-optimally along them; the arm stops at the lift points.

    Example: pinarms cycle aubo_i3 --pick 350 200 150 --place -100 400 100 --mm --payload 3kg
    """
    from pinarms import optim
    from pinarms.optim.cycle import CycleApproach, CycleLoad, CycleRequest, CycleTiming

    arm = load_robot(robot)
    scale = length_scale(mm)
    lu = "mm" if mm else "m"
    lift_m = 0.05 if lift is None else lift * scale
    spec = optim.PickPlace(np.array(pick) * scale, np.array(place) * scale, lift=lift_m, dwell=dwell,
                           via=[np.array(v) * scale for v in via])
    kg = None if payload is None else mass_kg(payload)
    limits = si_limit(torque_max, "--torque-max", np.ones(arm.nq))
    torque_limits = limits if limits is not None else (True if (kg is not None or torque) else False)
    timing = CycleTiming(kind, si_limit(vmax, "--vmax", np.ones(arm.nq)), si_limit(amax, "--amax", np.ones(arm.nq)),
                         si_limit(jmax, "--jmax", np.ones(arm.nq)), method=method, seed=seed)
    shape = CycleApproach("straight" if straight else "joint", None if vtool is None else vtool * scale)
    res = optim.plan_cycle(CycleRequest(arm, spec, timing=timing, load=CycleLoad(kg, torque_limits), approach=shape))
    data = res.as_dict()
    data["units"] = {"lengths": "m", "times": "s", "limits": "rad or m per s^k", "given_points": lu}
    dev = res.line_deviation / scale
    lines = [
        (f"{arm.name}: pick-and-place cycle, {kind} ({method}), lift {lift_m / scale:g} {lu}, "
         f"dwell {dwell:g} s at pick and place"),
        f"  move to place: {res.move_times[0]:.4f} s  (segments {fmt(res.moves[0].durations, 4)} s)",
        f"  move to pick:  {res.move_times[1]:.4f} s  (segments {fmt(res.moves[1].durations, 4)} s)",
        f"cycle time {res.cycle_time:.4f} s, {res.picks_per_minute:.2f} picks per minute",
        "peak / limit: " + ", ".join(f"{k} {v.max():.4f}" for k, v in res.limit_ratios.items()),
        f"tcp off the vertical lines [{lu}]: "
        + ", ".join(f"{name} {d:.4g}" for name, d in zip(optim.cycle.LINE_NAMES, dev)),
        "IK: one branch for every waypoint" if res.one_branch else
        f"IK: branches {res.branches.tolist()} (the joint limits force a switch, or the arm is solved numerically)",
    ]
    if res.approach == "straight":
        lines.insert(4, f"straight lines: joint-space cycle {res.joint_cycle_time:.4f} s "
                        f"(straight {res.straight_cost:+.4f} s); the four lines take {res.line_cost:+.4f} s "
                        "beside joint-space lines between the same configurations")
    if res.torque_limit is not None:
        carried = "nothing" if res.payload is None else f"{res.payload.mass:g} kg"
        lines.insert(4, f"torque / limit (carrying {carried} to the place, empty back): "
                        + ", ".join(f"{n} {r:.3f}" for n, r in zip(arm.joint_names, res.torque_ratios)))
    if session_path:
        session = new_session(arm if res.payload is None else arm.with_payload(res.payload),
                              f"pick-and-place cycle of {arm.name}")
        session.add_trajectory("cycle", res.trajectory)
        session.add_points("cycle_via_points", res.waypoints[:, :3, 3], kind="via")
        place_m = res.waypoints[res.names.index("place"), :3, 3]
        session.add_points("pick_place", np.stack([res.waypoints[0, :3, 3], place_m]), kind="target")
        save_session(session, session_path, data, lines)
    emit(as_json, data, lines)


