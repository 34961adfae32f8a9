"""``pinarms verify``: an independent engine (MuJoCo) replays pinarms' planned motions; controller files."""

from __future__ import annotations

from pathlib import Path

import click

from ._common import PinarmsGroup, cli, emit, json_option


@cli.group("verify", cls=PinarmsGroup)
def verify_group() -> None:
    """Re-check planned motions in MuJoCo through the exported MJCF (docs/export.md)."""


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
    from pinarms.export.trajectory import _rate
    from pinarms.progress import ProgressBar, wanted

    if controller_dir is not None:
        _rate(rate)  # a bad rate fails before the planning
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
