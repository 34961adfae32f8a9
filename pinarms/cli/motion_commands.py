"""Collision-free motion in a cell: ``motion`` (OMPL search, continuous proof, time-optimal timing).

Named ``motion``, not ``plan``: ``pinarms plan`` builds joint trajectories through given via
points (its options --kind, --via, --times, --robot ...); a planned motion takes a cell, an
arm and a target pose instead. Folding both into one command would leave half of its
options meaningless in each mode (docs/motion.md).
"""

from __future__ import annotations

from typing import Any

import click
import numpy as np

from pinarms.robots.errors import InvalidInput
from pinarms.units import angle_scale, length_scale

from ._common import NUMBERS, cli, emit, floats, fmt, json_option, save_session, show_progress
from .line_commands import _pose, _PoseCommand

__all__ = ["load_any_cell"]


def load_any_cell(name: str) -> Any:
    """A planning scene (``aubo_crate_guard`` ...), a built-in cell, or a cell file (.xacro/.urdf).

    Cell files may place example-robot-data arms with ``$(find pinarms_examples)/<arm>.xacro``.
    """
    from pinarms import robots
    from pinarms.optim.motion.arm_macros import example_packages
    from pinarms.optim.motion.scenes import load_scene, scene_names

    if name in scene_names():
        return load_scene(name)
    if name.endswith((".xacro", ".urdf")) or "/" in name:
        return robots.load_cell(name, packages=example_packages())
    return robots.load_cell(name)


@cli.command("motion", cls=_PoseCommand, context_settings=NUMBERS)
@click.argument("cell")
@click.option("--arm", "arm_name", default=None, help="The arm to move (default: the cell's only arm).")
@click.option("--to", "goal", required=True, help="X Y Z [ROLL PITCH YAW] of the goal (tcp in the world frame).")
@click.option("--from", "start", default=None,
              help="X Y Z [ROLL PITCH YAW] of the start pose (the clear IK solution nearest the arm's neutral; "
                   "without ROLL PITCH YAW the tool points down on six-axis arms).")
@click.option("--from-q", "start_q", default=None, help="Comma-separated joint values of the start (default: neutral).")
@click.option("--margin", default=0.01, show_default=True, type=float,
              help="Clearance kept to fixtures and other arms [m, or mm with --mm].")
@click.option("--planner", default="rrtconnect", show_default=True, help="OMPL planner (rrtconnect, rrt, prm, ...).")
@click.option("--time-limit", default=2.0, show_default=True, type=float, help="Seconds the search may take.")
@click.option("--seed", default=0, show_default=True, type=int, help="Seed of the search (same seed, same path).")
@click.option("--goals", "goal_choice", type=click.Choice(["first", "best"]), default="first", show_default=True,
              help="With several clear IK branches of the goal: the path to the first one reached, or each searched "
                   "and the path with the shortest time bound kept (a move planned once, run many times).")
@click.option("--amax", default=None, help="Joint acceleration limit(s) [rad/s² or m/s²] (torque limits apply too).")
@click.option("--no-torque", is_flag=True, help="Time under velocity (and --amax) limits only, not the URDF's torques.")
@click.option("--deg", is_flag=True, help="ROLL PITCH YAW and --from-q in degrees.")
@click.option("--mm", is_flag=True, help="Positions and --margin in millimetres.")
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Save the whole cell and the planned motion (tool path, goal) into a session file.")
@click.option("--plot", "plot_path", default=None, type=click.Path(dir_okay=False),
              help="Write the clearance-over-time plot (PNG).")
@json_option
def motion_cmd(cell: str, arm_name: str | None, goal: str, start: str | None, start_q: str | None, margin: float,
               planner: str, time_limit: float, seed: int, goal_choice: str, amax: str | None, no_torque: bool,
               deg: bool, mm: bool, session_path: str | None, plot_path: str | None, as_json: bool) -> None:
    """Plan a collision-free move of an arm in CELL to a tool pose, prove it clear, time it optimally.

    CELL is a planning scene (aubo_crate_guard, panda_shelf, ...), a built-in cell
    (aubo_food_station, mushroom_line) or a cell file. Poses are in the world frame; a pose
    without ROLL PITCH YAW keeps the tool's orientation at the start.

    Example: pinarms motion aubo_crate_guard --to 0 -0.46 0.78 --margin 0.01
    """
    import sys

    from pinarms.optim.motion import MotionChecker, plan_motion
    from pinarms.optim.motion.goals import ik_candidates

    def progress(message: str) -> None:
        if show_progress(as_json):
            click.echo(f"  … {message}", err=True)
            sys.stderr.flush()

    progress(f"loading {cell}")
    c = load_any_cell(cell)
    if arm_name is None:
        if len(c.arms) != 1:
            raise InvalidInput(f"cell {c.name!r} has several arms ({', '.join(a.name for a in c.arms)}): give --arm")
        arm_name = c.arms[0].name
    arm = c.arm(arm_name)
    lu = length_scale(mm)
    margin_m = margin * lu
    if start is not None and start_q is not None:
        raise click.UsageError("give --from (a pose) or --from-q (joint values), not both")
    if start_q is not None:
        q0 = floats(start_q, "--from-q")
        if q0.size != arm.nq:
            raise InvalidInput(f"--from-q needs {arm.nq} values for arm {arm.name!r} "
                               f"({', '.join(arm.robot.joint_names)}), got {q0.size}")
        units = np.array([angle_scale(deg) if u == "rad" else lu for u in arm.robot.joint_units])
        q0 = q0 * units
    elif start is not None:
        from pinarms.robots.reach.layout import default_orientation

        T0 = _pose(start, "--from", mm, deg, arm.base_to_world[:3, :3] @ default_orientation(arm.robot))
        checker = MotionChecker(c, [arm.name], margin=margin_m)
        cands, _ = ik_candidates(arm.robot, arm.to_base(T0), c.neutral[arm.q_slice], seed=seed)
        clear = [q for q in cands if checker.state_valid(q)]
        if not clear:
            raise InvalidInput(f"--from: no clear IK solution of arm {arm.name!r} reaches "
                               f"{np.round(T0[:3, 3], 4).tolist()} m ({len(cands)} solutions tried)")
        q0 = clear[0]
    else:
        q0 = np.array(c.neutral[arm.q_slice])
    R0 = arm.tcp_to_world(q0)[:3, :3]
    T = _pose(goal, "--to", mm, deg, R0)
    a = None if amax is None else floats(amax, "--amax")
    plan = plan_motion(c, arm.name, q0, T, margin=margin_m, planner=planner, time_limit=time_limit, seed=seed,
                       amax=None if a is None else (float(a[0]) if a.size == 1 else a), torque=not no_torque,
                       goals=goal_choice, progress=progress)
    u = "mm" if mm else "m"
    cl = plan.clearance
    data: dict[str, Any] = {"cell": c.name, "arm": arm.name, **plan.as_dict(),
                            "goal_pose_world_m": T, "tool_path_world_m": plan.tool_path(samples=50)}
    valid = sum(g.valid for g in plan.goals)
    lines = [
        f"{c.name}: arm {arm.name} to {fmt(T[:3, 3] / lu, 4)} {u} ({valid} of {len(plan.goals)} goal configuration(s) "
        f"clear)",
        f"  search: {plan.planner} in {plan.seconds['search']:.3f} s, {plan.states} states; path "
        f"{plan.raw_length:.3f} → {plan.path_length:.3f} rad after shortcutting, {plan.smoothing}",
        f"  time-optimal: {plan.duration:.4f} s under "
        + ", ".join(k for k, v in plan.limits.items() if v is not None)
        + " limits; limit use " + ", ".join(f"{k} {100 * r:.1f} %" for k, r in plan.timing.ratios.items()),
        f"  {plan.clearance_summary()}; {plan.check.n_samples} samples",
        f"  total {plan.seconds['total']:.3f} s (search {plan.seconds['search']:.3f}, shortcut "
        f"{plan.seconds['shortcut']:.3f}, smooth {plan.seconds['smooth']:.3f}, time {plan.seconds['time']:.3f}, "
        f"check {plan.seconds['check']:.3f})",
    ]
    if plot_path:
        from pinarms.viz.plots import plot_clearance

        plot_clearance(plot_path, cl, title=f"{c.name}: arm {arm.name}, clearance to fixtures and other arms",
                           mm=True)
        data["plot"] = plot_path
        lines.append(f"clearance plot written: {plot_path}")
    if session_path:
        from pinarms import viz

        session = viz.Session(robot=c.robot, title=f"{c.name}: arm {arm.name} planned around the cell")
        session.add_trajectory("motion", plan.cell_trajectory(), hz=100.0)
        session.add_points("tool_path", plan.tool_path(samples=100), kind="via")
        session.add_points("goal", T[:3, 3][None], kind="target")
        save_session(session, session_path, data, lines)
    emit(as_json, data, lines)
