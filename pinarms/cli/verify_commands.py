"""``pinarms verify``: an independent engine (MuJoCo) replays pinarms' planned motions; controller files."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from pinarms.cli._common import NUMBERS, PinarmsGroup, cli, emit, floats, json_option


@cli.group("verify", cls=PinarmsGroup)
def verify_group() -> None:
    """Re-check cells and planned motions in MuJoCo through the exported MJCF (docs/export.md).

    `verify cell CELL` re-checks any cell (yours, with --package), `verify shipped` the demo's motions.
    """


@verify_group.command("cell", context_settings=NUMBERS)
@click.argument("cell")
@click.option("--package", "packages", multiple=True, metavar="NAME=FOLDER",
              help="A folder for $(find NAME) and package://NAME/ in CELL (repeatable).")
@click.option("--arg", "xacro_args", multiple=True, metavar="NAME=VALUE", help="A xacro:arg value of CELL (repeatable).")
@click.option("--samples", default=200, show_default=True, type=int,
              help="Random cell configurations compared (seeded), and instants of the planned move with --plan.")
@click.option("--seed", default=0, show_default=True, type=int, help="Seed of the random configurations and the search.")
@click.option("--plan", "plan_ends", nargs=2, default=None, metavar="FROM TO",
              help="Also plan a move of --arm from FROM to TO and replay it: each comma-separated joint values "
                   "[rad or m] or a named state (neutral, or a state of the arm in the cell description).")
@click.option("--arm", "arm_name", default=None, help="The arm --plan moves (default: the cell's only arm).")
@click.option("--margin", default=0.01, show_default=True, type=float,
              help="Clearance the planned move keeps to fixtures and other arms [m].")
@click.option("--time-limit", default=2.0, show_default=True, type=float, help="Seconds the search may take.")
@click.option("--amax", default=None,
              help="Joint acceleration limit(s) of the planned move [rad/s² or m/s²] (torque limits apply too).")
@json_option
def verify_cell_cmd(cell: str, packages: tuple[str, ...], xacro_args: tuple[str, ...], samples: int, seed: int,
                    plan_ends: tuple[str, str] | None, arm_name: str | None, margin: float, time_limit: float,
                    amax: str | None, as_json: bool) -> None:
    """Compare CELL's collision state in pinarms and MuJoCo (exported MJCF) at random configurations.

    With --plan FROM TO, also plan a collision-free move of --arm (pinarms motion's planner)
    and replay it in MuJoCo. Prints the agreement figures; exit status 1 when the engines
    disagree. Example: pinarms verify cell my_cell.urdf --package vendor=./vendor --plan neutral 0.5,1.0
    """
    from pinarms.export.verify import compare_configurations_in_mujoco, compare_in_mujoco

    from pinarms.cli._common import package_map
    from pinarms.cli.cell_commands import load_cell_option

    from pinarms.errors import InvalidInput

    if samples < 2:
        raise InvalidInput(f"--samples must be 2 or more, got {samples}")
    c = load_cell_option(cell, xacro_args, packages)
    pkgs = package_map(packages)
    results = [("configurations", compare_configurations_in_mujoco(
        c, c.random_q(samples, seed=seed), label=f"{samples} random configurations (seed {seed})", packages=pkgs))]
    if plan_ends is not None:
        a = None if amax is None else floats(amax, "--amax")
        if a is not None and not (a.size and np.all(np.isfinite(a)) and np.all(a > 0.0)):
            raise InvalidInput(f"--amax must be one positive acceleration limit or one per planned joint "
                               f"[rad/s² or m/s²], got {amax!r}")
        plan = _plan_between(c, arm_name, plan_ends, margin=margin, time_limit=time_limit, seed=seed,
                             amax=None if a is None else (float(a[0]) if a.size == 1 else a))
        results.append(("plan", compare_in_mujoco(c, plan, samples=samples, packages=pkgs)))
    elif arm_name is not None or amax is not None:
        raise InvalidInput("--arm and --amax apply to the move of --plan FROM TO: add --plan")
    lines = [line for _, r in results for line in r.lines()]
    emit(as_json, {"cell": c.name, **{name: r.as_dict() for name, r in results}}, lines)
    if not all(r.agrees for _, r in results):
        raise SystemExit(1)


def _arm_state(c, arm, text: str, end: str):
    """A --plan end: a named state of ``arm`` or its comma-separated joint values, checked against its length."""
    import numpy as np

    from pinarms.errors import InvalidInput

    states = {"neutral": np.array(c.neutral[arm.q_slice]), **dict(getattr(arm, "states", None) or {})}
    if text.strip() in states:
        return np.asarray(states[text.strip()], dtype=float)
    if not any(ch.isdigit() for ch in text):
        raise InvalidInput(f"--plan {end}: arm {arm.name!r} has no state {text!r}; states: {', '.join(states)} "
                           f"(or {arm.nq} comma-separated joint values)")
    q = floats(text, f"--plan {end}")
    if q.size != arm.nq:
        raise InvalidInput(f"--plan {end} needs {arm.nq} values for arm {arm.name!r} "
                           f"({', '.join(arm.robot.joint_names)}), got {q.size}")
    return q


def _plan_between(c, arm_name: str | None, ends: tuple[str, str], *, margin: float, time_limit: float, seed: int,
                  amax):
    """The planned move of ``--plan FROM TO`` (errors name --plan, --arm, --margin or --time-limit)."""
    from pinarms.optim.motion import MotionLimits, MotionOptions, MotionRequest, MotionStatus, plan_motion
    from pinarms.errors import InvalidInput

    if arm_name is None:
        if len(c.arms) != 1:
            raise InvalidInput(f"cell {c.name!r} has several arms ({', '.join(a.name for a in c.arms)}): "
                               "give --arm with --plan")
        arm_name = c.arms[0].name
    names = [a.name for a in c.arms]
    if arm_name not in names:
        raise InvalidInput(f"--arm: cell {c.name!r} has no arm {arm_name!r}; arms: {', '.join(names)}")
    arm = c.arm(arm_name)
    q0, q1 = _arm_state(c, arm, ends[0], "FROM"), _arm_state(c, arm, ends[1], "TO")
    request = MotionRequest(c, arm.name, q0, q1, options=MotionOptions(margin=margin, time_limit=time_limit, seed=seed),
                            limits=MotionLimits(amax=amax))
    plan = plan_motion(request)
    what = {MotionStatus.START_IN_COLLISION: "--plan FROM: {} (choose another start, or lower --margin)",
            MotionStatus.GOAL_IN_COLLISION: "--plan TO: {} (choose another goal, or lower --margin)",
            MotionStatus.NO_PATH: "--plan: {} (raise --time-limit, or lower --margin)"}.get(plan.status)
    if what is not None:
        raise InvalidInput(what.format(plan.reason))
    return plan.raise_for_status()


@verify_group.command("shipped")
@click.option("--samples", default=400, show_default=True, type=int, help="Instants compared per motion.")
@click.option("--no-line", is_flag=True, help="Skip the mushroom line (its two cycles and schedule: about 15 s).")
@click.option("--controller-dir", default=None, type=click.Path(file_okay=False),
              help="Also write each motion as JointTrajectory YAML and CSV (one file per arm) into this folder.")
@click.option("--rate", default=500.0, show_default=True, type=float, help="Controller rate of those files [Hz].")
@json_option
def verify_shipped_cmd(samples: int, no_line: bool, controller_dir: str | None, rate: float, as_json: bool) -> None:
    """Replay the shipped cells' planned motions in MuJoCo and compare distances and contacts with pinarms.

    The motions: the AUBO-i3 food station's crate cycle, the planned move under the crate
    guard, and (unless --no-line) the mushroom line's two cycles and two-arm schedule.
    MuJoCo measures with its own primitives and the convex hull of a mesh; pinarms with
    coal (exact primitives, mesh triangles).
    """
    from pinarms.export import compare_in_mujoco
    from pinarms.export.shipped import shipped_motions
    from pinarms.export.trajectory import check_rate
    from pinarms.progress import ProgressBar, wanted

    if controller_dir is not None:
        check_rate(rate)  # a bad rate fails before the planning
    with ProgressBar("planning the shipped motions", enabled=wanted(as_json)) as bar:
        motions = shipped_motions(line=not no_line, progress=bar)
    results, written = [], []
    with ProgressBar("replaying in MuJoCo", total=len(motions), enabled=wanted(as_json)) as bar:
        for k, motion in enumerate(motions):
            result = compare_in_mujoco(motion.cell, motion.source, arm=motion.arm, cycles=motion.cycles or None,
                                       samples=samples)
            results.append((motion.name, result))
            if controller_dir is not None:
                written += _write_controller_files(Path(controller_dir), motion, rate)
            bar(k + 1)
    lines = [line for _, r in results for line in r.lines()]
    lines += [f"wrote {p}" for p in written]
    emit(as_json, {"motions": {name: r.as_dict() for name, r in results}, "written": [str(p) for p in written]}, lines)
    if not all(r.agrees for _, r in results):
        raise SystemExit(1)


def _write_controller_files(folder: Path, motion, rate: float) -> list[Path]:
    from pinarms.export import controller_trajectory, write_trajectory_csv, write_trajectory_yaml
    from pinarms.optim import LineSchedule
    from pinarms.optim.motion import MotionPlan

    folder.mkdir(parents=True, exist_ok=True)
    if isinstance(motion.source, MotionPlan):
        parts = {motion.name: controller_trajectory(motion.source, rate)}
    elif isinstance(motion.source, LineSchedule):
        parts = {f"{motion.name}_{arm}": controller_trajectory(motion.source, rate, robot=motion.cell, arm=arm,
                                                                cycles=motion.cycles) for arm in motion.source.arms}
    else:
        parts = {motion.name: controller_trajectory(motion.source, rate, robot=motion.cell, arm=motion.arm)}
    out = []
    for name, traj in parts.items():
        out.append(write_trajectory_yaml(folder / f"{name}.yaml", traj))
        out.append(write_trajectory_csv(folder / f"{name}.csv", traj))
    return out
