"""Where one robot reaches: ``workspace`` (its Monte Carlo or streamed workspace) and ``layout``
(can it reach these points)."""

from __future__ import annotations

import click
import numpy as np

from pinarms import robots
from pinarms.errors import InvalidInput
from pinarms.units import length_scale

from pinarms.cli import _common as common
from pinarms.cli._common import (
    NUMBERS,
    cli,
    emit,
    json_option,
    jsonable,
    load_robot,
    new_session,
    save_session,
    scheduler_option,
    vectors_from_args,
)


# --------------------------------------------------------------------------- workspace
@cli.command("workspace")
@click.argument("robot")
@click.option("-n", "n", default=20000, show_default=True, type=click.IntRange(min=1), help="Samples.")
@click.option("--seed", default=0, show_default=True, type=int, help="Random seed.")
@click.option("--frame", default="tcp", show_default=True)
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Also save the cloud into a session file (with --stream: the reachable voxel centres).")
@click.option("--stream", is_flag=True,
              help="Keep only reductions (bounding box, voxel map, profile, hull sphere) in flat memory: "
                   "for 10^8 samples and more; no table region.")
@click.option("--voxel", "voxel_mm", default=None, type=float, help="With --stream: voxel edge [mm] (default >= 10 mm).")
@scheduler_option
@json_option
def workspace_cmd(robot: str, n: int, seed: int, frame: str, session_path: str | None, stream: bool,
                  voxel_mm: float | None, scheduler: str | None, as_json: bool) -> None:
    """Monte Carlo workspace of ROBOT: extent, sphere fit, manipulability, recommended table region.

    The region is robots.reach.table_band.recommend_region's radial band on the working side of
    the base plane (distances in the JSON in metres). With --stream the samples are
    reduced in tasks of 2e6 (serially, or on Dask with --scheduler) and never held.
    """
    arm = load_robot(robot)
    if stream:
        _streamed_workspace(arm, n, seed, frame, voxel_mm, scheduler, session_path, as_json)
        return
    from pinarms.robots.reach.table_band import recommend_region
    from pinarms.robots.reach.workspace import sample_workspace

    # a million samples take about a second: a bar from there on
    with common.progress_bar("workspace samples", n, as_json or n < 1_000_000) as bar:
        ws = sample_workspace(arm, n=n, seed=seed, frame=frame, progress=bar if bar.enabled else None)
    summary_obj = ws.summary()
    summary = jsonable(summary_obj)
    lo, hi = ws.points.min(axis=0), ws.points.max(axis=0)
    data = {
        "robot": arm.name,
        "n": n,
        "seed": seed,
        "frame": frame,
        "bounding_box_m": {"min": lo, "max": hi},
        "manipulability": {"mean": float(np.mean(ws.manipulability)), "max": float(np.max(ws.manipulability))},
        "summary": summary,
    }
    # the summary's text names robot, frame and samples and gives the bounding box [mm] and
    # the manipulability: printed once, with the seed added to its first line
    lines = summary_obj.text().splitlines()
    lines[0] += f" (seed {seed})"
    region = recommend_region(ws)
    data["region"] = {
        "about": region.about, "origin_m": region.origin, "r_inner_m": region.r_inner, "r_outer_m": region.r_outer,
        "side": region.side, "z_limit_m": region.z_limit, "criteria": region.criteria,
    }
    lines += region.text().splitlines()[:2]
    if session_path:
        session = new_session(arm, f"workspace of {arm.name}")
        session.add_workspace("workspace", ws)
        save_session(session, session_path, data, lines)
    emit(as_json, data, lines)


def _streamed_workspace(arm, n, seed, frame, voxel_mm, scheduler, session_path, as_json) -> None:
    from pinarms.execution import describe_scheduler
    from pinarms.robots.reach.workspace_stream import StreamGrid, stream_workspace

    with common.progress_bar("workspace tasks", None, as_json) as bar:
        res = stream_workspace(arm, n, seed=seed, frame=frame,
                               grid=StreamGrid(None if voxel_mm is None else voxel_mm * 1e-3),
                               scheduler=scheduler, progress=bar if bar.enabled else None)
    v = res.voxels
    data = {
        "robot": arm.name, "n": n, "seed": seed, "frame": frame, "streamed": True,
        "ran_on": describe_scheduler(scheduler), "tasks": res.n_tasks,
        "summary": jsonable(res.summary),
        "voxels": {"voxel_size_m": v.voxel_size, "shape": list(v.shape), "origin_m": v.origin,
                   "reachable": int(np.count_nonzero(v.reachable)), "reachable_volume_m3": v.reachable_volume},
    }
    lines = res.text().splitlines()
    lines[0] += f" (seed {seed}, streamed in {res.n_tasks} tasks, {describe_scheduler(scheduler)})"
    if session_path:
        session = new_session(arm, f"workspace of {arm.name} ({n:.0e} samples, voxel centres)")
        reach = v.reachable
        session.add_workspace("workspace_voxels", points=v.voxel_centres(),
                              manipulability=v.mean_manipulability[reach])
        save_session(session, session_path, data, lines)
    emit(as_json, data, lines)


# --------------------------------------------------------------------------- layout
@cli.command("layout", context_settings=NUMBERS)
@click.argument("robot")
@click.argument("xyz", nargs=-1, type=float, required=True)
@click.option("--mm", is_flag=True, help="Positions in and boundary margins out in millimetres.")
@click.option("--names", default=None, help="Comma-separated labels of the points (default P1, P2, ...).")
@click.option("-n", "n", default=100_000, show_default=True, type=click.IntRange(min=1),
              help="Workspace samples for the dexterity median and the boundary margin.")
@click.option("--seed", default=0, show_default=True, type=int, help="Random seed of the workspace and IK starts.")
@json_option
def layout_cmd(robot: str, xyz: tuple[float, ...], mm: bool, names: str | None, n: int, seed: int,
               as_json: bool) -> None:
    """Check a line layout: can ROBOT's tcp reach each pick/place point X Y Z [X Y Z ...] (base frame)?

    Per point: reachable or not, the number of IK branches within the joint limits, the
    best branch's position manipulability and dexterity ratio (its manipulability over the
    sampled workspace's median) and the distance to the workspace boundary
    (robots.check_layout; the tool points down for 6+ joint arms, its yaw is free for
    fewer). An unreachable point is reported, not an error (exit status 0).
    """
    arm = load_robot(robot)
    from pinarms.robots.reach.workspace import sample_workspace

    values = vectors_from_args(xyz)
    if values.size % 3:
        raise InvalidInput(f"give the points as X Y Z triples (a multiple of 3 numbers), got {values.size}")
    points = values.reshape(-1, 3)
    labels = None
    if names is not None:
        labels = [s.strip() for s in names.split(",")]
        if len(labels) != len(points) or not all(labels):
            raise InvalidInput(f"--names needs {len(points)} non-empty comma-separated label(s), got {names!r}")
    scale = length_scale(mm)
    ws = sample_workspace(arm, n=n, seed=seed, frame="tcp")
    report = robots.check_layout(arm, points * scale, names=labels, workspace=ws, seed=seed)
    lu = "mm" if mm else "m"
    rows = []
    for p, given in zip(report.points, points):
        best_w = float(p.manipulability[p.best]) if p.reachable else 0.0
        rows.append(
            {
                "name": p.name,
                "position": given,
                "reachable": p.reachable,
                "branches": p.n_branches,
                "solutions": p.n_solutions,
                "manipulability": best_w,
                "dexterity_ratio": p.dexterity_ratio,
                "inverse_condition": float(p.inverse_condition[p.best]) if p.reachable else 0.0,
                "boundary_margin": p.boundary_margin / scale,
                "q_best_si": p.solutions[p.best] if p.reachable else None,
            }
        )
    data = {
        "robot": arm.name,
        "method": report.method,
        "n": n,
        "seed": seed,
        "units": {"position": lu, "boundary_margin": lu, "manipulability": "SI", "q_best_si": "rad or m"},
        "median_manipulability": report.median_manipulability,
        "all_reachable": report.all_reachable,
        "points": rows,
    }
    width = max(8, *(len(r["name"]) for r in rows))
    position_head = f"position [{lu}]"
    lines = [
        (f"{arm.name}: {len(rows)} point(s), {report.method} IK, workspace median manipulability "
         f"{report.median_manipulability:.4g} ({n} samples, seed {seed})"),
        f"  {'point':<{width}}  {position_head:<29}  reachable  branches  manipulability  dexterity  margin [{lu}]",
    ]
    for r in rows:
        where = " ".join(f"{v:9.6g}" for v in r["position"])
        if r["reachable"]:
            lines.append(f"  {r['name']:<{width}}  {where}  {'yes':>9}  {r['branches']:8d}  {r['manipulability']:14.4g}"
                         f"  {r['dexterity_ratio']:9.2f}  {r['boundary_margin']:.4g}")
        else:
            lines.append(f"  {r['name']:<{width}}  {where}  {'NO':>9}  (no IK solution within the joint limits)")
    lines.append("all points reachable" if report.all_reachable else
                 f"{int(np.count_nonzero(~report.reachable))} point(s) NOT reachable: move them or the robot")
    emit(as_json, data, lines)


