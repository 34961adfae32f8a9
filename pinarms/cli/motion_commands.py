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

from pinarms.errors import InvalidInput
from pinarms.units import angle_scale, length_scale

from pinarms.cli._common import NUMBERS, cli, emit, floats, fmt, json_option, save_session, show_progress
from pinarms.cli._common import package_map
from pinarms.cli.pose_options import PoseCommand, parse_pose

__all__ = ["load_any_cell", "hold_option"]


def hold_option(cell: Any, holds: tuple[str, ...], planned: str | tuple[str, ...], deg: bool, mm: bool,
                why: str = "give its start with --from or --from-q") -> np.ndarray:
    """The cell configuration of the arms that do not move: :attr:`Cell.hold` with each ``--hold ARM=...`` applied.

    ``ARM=Q1,Q2,...`` gives joint values (rad and m; degrees with ``deg``, millimetres with
    ``mm``), ``ARM=STATE`` one of the arm's named states. Every error names ``--hold``; an
    arm of ``planned`` (it moves) is refused, saying ``why``.
    """
    moving = (planned,) if isinstance(planned, str) else tuple(planned)
    q = cell.hold
    for item in holds:
        name, sep, value = item.partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise InvalidInput(f"--hold must be ARM=Q1,Q2,... or ARM=STATE, got {item!r}")
        if name not in {a.name for a in cell.arms}:
            raise InvalidInput(f"--hold: cell {cell.name!r} has no arm {name!r}; arms: {', '.join(a.name for a in cell.arms)}")
        arm = cell.arm(name)
        if name in moving:
            raise InvalidInput(f"--hold {name}: arm {name!r} is the arm planned; {why}")
        if value[0].isalpha():
            if value not in arm.states:
                raise InvalidInput(f"--hold {name}: arm {name!r} has no state {value!r}; states: "
                                   f"{', '.join(arm.states) or 'none (states in the cell description)'}")
            q[arm.q_slice] = arm.states[value]
            continue
        values = floats(value, f"--hold {name}")
        if values.size != arm.nq:
            raise InvalidInput(f"--hold {name} needs {arm.nq} values ({', '.join(arm.robot.joint_names)}), got {values.size}")
        units = np.array([angle_scale(deg) if u == "rad" else length_scale(mm) for u in arm.robot.joint_units])
        values = values * units
        bad = [f"{j} = {v:g} outside [{lo:g}, {hi:g}]" for j, v, lo, hi in
               zip(arm.robot.joint_names, values, arm.robot.lower, arm.robot.upper) if not lo - 1e-9 <= v <= hi + 1e-9]
        if bad:
            raise InvalidInput(f"--hold {name} is outside the joint limits [rad or m]: {'; '.join(bad)}")
        q[arm.q_slice] = values
    return q


def load_any_cell(name: str, packages: dict[str, str] | None = None) -> Any:
    """A planning scene (``aubo_crate_guard`` ...), a built-in cell, or a cell file (.xacro/.urdf/.toml).

    Cell files may place example-robot-data arms with ``$(find pinarms_examples)/<arm>.xacro``,
    and read the folders of ``packages`` (``--package NAME=FOLDER``) besides.
    """
    from pinarms import robots
    from pinarms.optim.motion.arm_macros import example_packages
    from pinarms.optim.motion.scenes import load_scene, scene_names

    if name in scene_names():
        return load_scene(name)
    if name.endswith((".xacro", ".urdf", ".toml")) or "/" in name:
        return robots.load_cell(name, packages={**example_packages(), **(packages or {})})
    return robots.load_cell(name, packages=packages or None)


@cli.command("motion", cls=PoseCommand, context_settings=NUMBERS)
@click.argument("cell")
@click.option("--package", "packages", multiple=True, metavar="NAME=FOLDER",
              help="A folder for $(find NAME) and package://NAME/ in CELL (repeatable).")
@click.option("--arm", "arm_name", default=None, help="The arm to move (default: the cell's only arm).")
@click.option("--to", "goal", required=True, help="X Y Z [ROLL PITCH YAW] of the goal (tcp in the world frame).")
@click.option("--from", "start", default=None,
              help="X Y Z [ROLL PITCH YAW] of the start pose (the clear IK solution nearest the arm's neutral; "
                   "without ROLL PITCH YAW the tool points down on six-axis arms).")
@click.option("--from-q", "start_q", default=None,
              help="Comma-separated joint values of the start (default: the arm's hold pose, else neutral).")
@click.option("--hold", "holds", multiple=True, metavar="ARM=Q1,Q2,...|ARM=STATE",
              help="Where an arm that does not move stays (repeatable): its joint values (rad and m, or --deg/--mm) "
                   "or a named state of the cell description (default: the description's hold, else neutral).")
@click.option("--margin", default=0.01, show_default=True, type=float,
              help="Clearance kept to fixtures and other arms [m, or mm with --mm].")
@click.option("--planner", default="rrtconnect", show_default=True, help="OMPL planner (rrtconnect, rrt, prm, ...).")
@click.option("--time-limit", default=2.0, show_default=True, type=float, help="Seconds the search may take.")
@click.option("--seed", default=0, show_default=True, type=int, help="Seed of the search (same seed, same path).")
@click.option("--goals", "goal_choice", type=click.Choice(["first", "best"]), default="best", show_default=True,
              help="With several clear IK branches of the goal: each searched and the path with the shortest time "
                   "bound kept, or the path to the first one reached (a little less planning).")
@click.option("--amax", default=None, help="Joint acceleration limit(s) [rad/s² or m/s²] (torque limits apply too; "
                                            "default: each arm's, velocity limit / 0.25 s unless set).")
@click.option("--no-torque", is_flag=True, help="Time under velocity (and --amax) limits only, not the URDF's torques.")
@click.option("--deg", is_flag=True, help="ROLL PITCH YAW and --from-q in degrees.")
@click.option("--mm", is_flag=True, help="Positions and --margin in millimetres.")
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Save the whole cell and the planned motion (tool path, goal) into a session file.")
@click.option("--plot", "plot_path", default=None, type=click.Path(dir_okay=False),
              help="Write the clearance-over-time plot (PNG).")
@json_option
def motion_cmd(cell: str, packages: tuple[str, ...], arm_name: str | None, goal: str, start: str | None,
               start_q: str | None, holds: tuple[str, ...], margin: float,
               planner: str, time_limit: float, seed: int, goal_choice: str, amax: str | None, no_torque: bool,
               deg: bool, mm: bool, session_path: str | None, plot_path: str | None, as_json: bool) -> None:
    """Plan a collision-free move of an arm in CELL to a tool pose, prove it clear, time it optimally.

    CELL is a planning scene (aubo_crate_guard, panda_shelf, ...), a built-in cell
    (aubo_food_station, mushroom_line) or a cell file. Poses are in the world frame; a pose
    without ROLL PITCH YAW keeps the tool's orientation at the start.

    Example: pinarms motion aubo_crate_guard --from 0.41 0.10 0.79 --to 0 -0.465 0.78 --margin 0.01
    """
    import sys

    from pinarms.optim.motion import MotionChecker, MotionLimits, MotionOptions, MotionRequest, plan_motion
    from pinarms.optim.motion.goals import ik_candidates

    def progress(message: str) -> None:
        if show_progress(as_json):
            click.echo(f"  … {message}", err=True)
            sys.stderr.flush()

    progress(f"loading {cell}")
    c = load_any_cell(cell, package_map(packages))
    if arm_name is None:
        if len(c.arms) != 1:
            raise InvalidInput(f"cell {c.name!r} has several arms ({', '.join(a.name for a in c.arms)}): give --arm")
        arm_name = c.arms[0].name
    arm = c.arm(arm_name)
    lu = length_scale(mm)
    margin_m = margin * lu
    if start is not None and start_q is not None:
        raise click.UsageError("give --from (a pose) or --from-q (joint values), not both")
    hold = hold_option(c, holds, arm.name, deg, mm)
    if start_q is not None:
        q0 = floats(start_q, "--from-q")
        if q0.size != arm.nq:
            raise InvalidInput(f"--from-q needs {arm.nq} values for arm {arm.name!r} "
                               f"({', '.join(arm.robot.joint_names)}), got {q0.size}")
        units = np.array([angle_scale(deg) if u == "rad" else lu for u in arm.robot.joint_units])
        q0 = q0 * units
    elif start is not None:
        from pinarms.robots.reach.layout import default_orientation

        T0 = parse_pose(start, "--from", mm, deg, arm.base_to_world[:3, :3] @ default_orientation(arm.robot))
        checker = MotionChecker(c, [arm.name], margin=margin_m, hold=hold)
        cands, _ = ik_candidates(arm.robot, arm.to_base(T0), arm.hold, seed=seed)
        clear = [q for q in cands if checker.state_valid(q)]
        if not clear:
            raise InvalidInput(f"--from: no clear IK solution of arm {arm.name!r} reaches "
                               f"{np.round(T0[:3, 3], 4).tolist()} m ({len(cands)} solutions tried)")
        q0 = clear[0]
    else:
        q0 = np.array(arm.hold)
    R0 = arm.tcp_to_world(q0)[:3, :3]
    T = parse_pose(goal, "--to", mm, deg, R0)
    a = None if amax is None else floats(amax, "--amax")
    options = MotionOptions(margin=margin_m, planner=planner, time_limit=time_limit, seed=seed, goals=goal_choice)
    limits = MotionLimits(amax=None if a is None else (float(a[0]) if a.size == 1 else a), torque=not no_torque)
    plan = plan_motion(MotionRequest(c, arm.name, q0, T, options=options, limits=limits, hold=hold),
                       progress=progress).raise_for_status()  # not solved: one Error line saying why
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
        + ", ".join(k for k, v in plan.limits.items() if v is not None and k != "amax_source")
        + f" limits (amax: {plan.limits['amax_source']}); limit use " + ", ".join(f"{k} {100 * r:.1f} %" for k, r in plan.timing.ratios.items()),
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
