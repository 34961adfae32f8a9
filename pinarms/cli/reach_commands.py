"""``pinarms reach``: the reachability map of an arm (which tool poses, with which orientations, per voxel)."""

from __future__ import annotations

import click
import numpy as np

from pinarms.units import parse_angle, parse_length

from pinarms.cli._common import cli, emit, json_option, load_robot, new_session, progress_bar, save_session, scheduler_value


@cli.command("reach")
@click.argument("robot")
@click.option("--resolution", default="0.025", show_default=True,
              help="Voxel edge: metres, or with a unit (25mm, 2.5cm).")
@click.option("--orientations", "orientations", default=None, type=click.IntRange(min=1),
              help="Rotations per voxel over SO(3) [default 50]; with --tool-down, tool-axis directions in the cone [default 16].")
@click.option("--tool-down", "tool_down", default=None,
              help="Only the tool pointing down within this cone half-angle (15deg, 0.26rad; a bare number is degrees), roll free.")
@click.option("--roll-steps", default=8, show_default=True, type=click.IntRange(min=1),
              help="Rolls tried per tool-down direction (any counts).")
@click.option("--ik", "ik", default="auto", show_default=True, type=click.Choice(["auto", "analytic", "numerical"]))
@click.option("--self-collision", is_flag=True, help="Drop IK solutions where the arm hits itself.")
@click.option("--seed", default=0, show_default=True, type=click.IntRange(min=0), help="Seed of the samples and IK restarts.")
@click.option("--scheduler", default=None, callback=scheduler_value,
              help="Where to run the chunks: omit (here, serially), processes[:N] (local Dask workers), "
                   "tcp://HOST:8786 (a Dask cluster) or env (DASK_SCHEDULER_ADDRESS).")
@click.option("--out", "out_path", default=None, type=click.Path(dir_okay=False),
              help="Save the whole map (every pose and stored solution) to this HDF5 file.")
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Also save a session that shows the map as coloured voxels (pinarms view / html).")
@json_option
def reach_cmd(robot: str, resolution: str, orientations: int | None, tool_down: str | None, roll_steps: int, ik: str,
              self_collision: bool, seed: int, scheduler: str | None, out_path: str | None, session_path: str | None,
              as_json: bool) -> None:
    """Reachability map of ROBOT's tool: per voxel, which orientations have an IK solution within the limits.

    Closed-form arms get every branch; any other URDF the seeded numerical solver. The index of a
    voxel is the fraction of orientations (or tool-down directions) reached.
    """
    from pinarms.robots.reach.reachability import reachability_map

    arm = load_robot(robot)
    res = parse_length(resolution, "--resolution")
    cone = None if tool_down is None else parse_angle(tool_down, "--tool-down")
    n = orientations if orientations is not None else (50 if cone is None else 16)
    sched = _scheduler(scheduler)
    with progress_bar("reachability voxels", None, as_json) as bar:
        m = reachability_map(arm, res, n, tool_down=cone, roll_steps=roll_steps, ik=ik, self_collision=self_collision,
                             seed=seed, keep_solutions=False, out=out_path, scheduler=sched, progress=bar)
    reach = m.index > 0
    data = {
        "robot": m.robot,
        "tcp_frame": m.tcp_frame,
        "resolution_m": m.resolution,
        "solver": m.solver,
        "orientations": m.orientations.describe(),
        "poses_per_voxel": m.n_orientations,
        "voxels_computed": m.n_voxels,
        "poses": m.n_poses,
        "poses_reached": m.n_reached,
        "voxels_reachable": int(reach.sum()),
        "voxels_index_at_least_half": int(np.count_nonzero(m.index >= 0.5)),
        "mean_index_of_reachable_voxels": float(m.index[reach].mean()) if reach.any() else 0.0,
        "reachable_volume_m3": float(reach.sum()) * m.resolution**3,
        "seconds": m.parameters["seconds"],
        "poses_per_second": m.parameters["poses_per_second"],
        "grid_origin_m": m.origin,
        "grid_shape": list(m.shape),
    }
    lines = [m.text()]
    if out_path:
        data["file"] = out_path
        lines.append(f"map written: {out_path} (every pose, its stored IK solution streamed chunk by chunk)")
    if m.n_reached == 0 and cone is None and arm.nq < 6:
        note = (f"{arm.name} has {arm.nq} joints: it cannot take arbitrary orientations, so no rotation of an SO(3) set "
                "is reached; use --tool-down (its tool axis stays vertical)")
        data["note"] = note
        lines.append("note: " + note)
    if session_path:
        session = new_session(arm, f"reachability map of {arm.name}")
        session.add_reachability("tool down" if cone is not None else "reachability", m)
        save_session(session, session_path, data, lines)
    emit(as_json, data, lines)


def _scheduler(text: str | None):
    """The ``--scheduler`` value as the execution layer takes it (``None``: serial, here)."""
    return text
