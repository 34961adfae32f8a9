"""Straight tool lines: ``line`` (a Cartesian path through tcp poses, its joint image and its timing)."""

from __future__ import annotations

from typing import Any

import click
import numpy as np

from pinarms.errors import InvalidInput
from pinarms.units import joints_from_si, joints_to_si, length_scale

from pinarms.cli.pose_options import PoseCommand, parse_pose
from pinarms.cli._common import (NUMBERS, cli, emit, floats, fmt, json_option, load_robot, new_session, save_session,
                      si_limit)

@cli.command("line", cls=PoseCommand, context_settings=NUMBERS)
@click.argument("robot")
@click.option("--from", "start", required=True, help="X Y Z [ROLL PITCH YAW] of the start pose (tcp in the base frame).")
@click.option("--to", "goal", required=True, help="X Y Z [ROLL PITCH YAW] of the end pose.")
@click.option("--via", multiple=True, help="X Y Z [ROLL PITCH YAW] of a pose on the way (repeat, in order).")
@click.option("--blend", default=0.0, show_default=True, type=float,
              help="Corner radius at the vias [m, or mm with --mm]; 0: stop at every corner.")
@click.option("--stop", "stop_at_vias", is_flag=True, help="Stop at every via (no blend).")
@click.option("--vtool", default=None, type=float, help="tcp speed limit [m/s, or mm/s with --mm], e.g. 0.5 carrying food.")
@click.option("--atool", default=None, type=float, help="tcp acceleration limit [m/s², or mm/s² with --mm].")
@click.option("--vmax", default=None, help="Joint speed limit(s) [rad/s or m/s], one or per joint (default: the URDF's).")
@click.option("--amax", default=None, help="Joint acceleration limit(s): time-optimal (TOPP-RA); without: a quintic time law.")
@click.option("--jmax", default=None, help="Joint jerk limit(s) (with --amax): a smoothed time-optimal result.")
@click.option("--tolerance", default=None, type=float, help="Largest tcp deviation from the lines [default 0.1 mm].")
@click.option("--weight", default=0.1, show_default=True, type=float, help="Arc-length weight of rotations [m/rad].")
@click.option("--q-start", "q_start", default=None, help="Comma-separated joint values picking the IK branch.")
@click.option("--deg", is_flag=True, help="ROLL PITCH YAW, --q-start and joint output in degrees.")
@click.option("--mm", is_flag=True, help="Positions, --blend, --tolerance, --vtool, --atool and deviations in millimetres.")
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Save the timed line (trajectory, poses) into a session file.")
@json_option
def line_cmd(robot: str, start: str, goal: str, via: tuple[str, ...], blend: float, stop_at_vias: bool,
             vtool: float | None, atool: float | None, vmax: str | None, amax: str | None, jmax: str | None,
             tolerance: float | None, weight: float, q_start: str | None, deg: bool, mm: bool,
             session_path: str | None, as_json: bool) -> None:
    """Straight tcp lines from --from through the --via poses to --to, on one IK branch, timed.

    The tcp moves on straight lines (orientation by SLERP), with circular blends of radius
    --blend at the vias; the joint path keeps it within --tolerance of the lines (checked by
    FK). Timing: time-optimal along the path (TOPP-RA) under --vmax/--amax (and --vtool,
    --atool; --jmax smooths it), or without --amax the fastest rest-to-rest quintic time law.
    Poses without ROLL PITCH YAW keep the tool's default orientation (pointing down on
    six-axis arms).

    Example: pinarms line aubo_i3 --from 350 200 0 --to 350 200 300 --mm --amax 7 --vtool 500
    """
    from pinarms import planning
    from pinarms.robots.reach.layout import default_orientation

    arm = load_robot(robot)
    lu = length_scale(mm)
    R = default_orientation(arm)
    poses = np.stack([parse_pose(start, "--from", mm, deg, R), *(parse_pose(v, "--via", mm, deg, R) for v in via),
                      parse_pose(goal, "--to", mm, deg, R)])
    q0 = _q_start(arm, q_start, deg, mm)
    tol = 1e-4 if tolerance is None else tolerance * lu
    stops = range(1, poses.shape[0] - 1) if stop_at_vias else ()
    path = planning.cartesian_path(arm, poses, blend=blend * lu, weight=weight, stops=stops, tolerance=tol,
                                   q_start=q0)
    timing, law = _timed(arm, path, vmax, amax, jmax, None if vtool is None else vtool * lu,
                         None if atool is None else atool * lu)
    data, lines = _line_report(arm, poses, path, timing, law, tol, mm, deg)
    if session_path:
        session = new_session(arm, f"{arm.name}: straight tcp lines")
        session.add_trajectory("line", timing.trajectory, hz=200.0)
        session.add_points("poses", poses[:, :3, 3], kind="via")
        save_session(session, session_path, data, lines)
    emit(as_json, data, lines)


def _q_start(arm: Any, q_start: str | None, deg: bool, mm: bool) -> np.ndarray | None:
    """``--q-start`` in SI units (None: not given); InvalidInput naming the flag for a wrong count."""
    if q_start is None:
        return None
    values = floats(q_start, "--q-start")
    if values.size != arm.nq:
        raise InvalidInput(f"--q-start needs {arm.nq} values for {arm.name} ({', '.join(arm.joint_names)}), "
                           f"got {values.size}")
    return joints_to_si(arm, values, deg=deg, mm=mm)


def _timed(arm: Any, path: Any, vmax: str | None, amax: str | None, jmax: str | None, vtool: float | None,
           atool: float | None) -> tuple[Any, str]:
    """The timing of ``path`` under the limits of the flags (tool limits in SI units) and its law in words:
    time-optimal with ``--amax``, else the fastest rest-to-rest quintic time law."""
    from pinarms import optim, planning

    v = si_limit(vmax, "--vmax", 1.0)
    v = np.asarray(arm.velocity_limit, dtype=float) if v is None else v
    a = si_limit(amax, "--amax", 1.0)
    j = si_limit(jmax, "--jmax", 1.0)
    if j is not None and a is None:
        raise InvalidInput("--jmax smooths the time-optimal profile: give --amax too")
    constraints: list[Any] = [planning.JointVelocityConstraint(v)]
    if a is not None:
        constraints.append(planning.JointAccelerationConstraint(a))
    if vtool is not None:
        constraints.append(planning.ToolSpeedConstraint(vtool))
    if atool is not None:
        constraints.append(planning.ToolAccelerationConstraint(atool))
    if a is None:
        return optim.time_scaled(path, constraints, shape="quintic"), "quintic time law"
    law = "time-optimal (TOPP-RA)" + (" smoothed for the jerk limit" if j is not None else "")
    return optim.time_optimal(path, constraints, jerk=j), law


def _line_report(arm: Any, poses: np.ndarray, path: Any, timing: Any, law: str, tol: float, mm: bool,
                 deg: bool) -> tuple[dict[str, Any], list[str]]:
    """What ``pinarms line`` reports: the JSON data and the text lines."""
    lu = length_scale(mm)
    traj = timing.trajectory
    s = np.linspace(0.0, path.length, 10 * (path.breaks.size - 1) + 1)
    dev, rot = path.deviation(s)
    t = np.linspace(0.0, timing.duration, 1001)
    speed, ang = timing.tool_speed(t)
    peaks = traj.peaks()
    data: dict[str, Any] = {
        "robot": arm.name,
        "units": {"length": "mm" if mm else "m", "angle": "deg" if deg else "rad"},
        "poses_m": poses[:, :3, 3],
        "path_length_m": path.length,
        "weight_m_per_rad": path.tool_path.weight,
        "stops_m": path.stops,
        "blend_radii_m": path.tool_path.radii,
        "knots": int(path.breaks.size),
        "tolerance_m": tol,
        "max_deviation_m": float(dev.max()),
        "max_rotation_deviation_rad": float(rot.max()),
        "branch": path.branch,
        "q_start": joints_from_si(arm, path.q_knots[0], deg=deg, mm=mm),
        "q_end": joints_from_si(arm, path.q_knots[-1], deg=deg, mm=mm),
        "time_law": law,
        "duration_s": timing.duration,
        "dilation": timing.dilation,
        "smoothing_s": timing.smoothing,
        "max_tool_speed_m_s": float(speed.max()),
        "peak_ratios": timing.ratios,
        "joint_peaks": peaks.as_dict(),
    }
    u = "mm" if mm else "m"
    lines = [
        f"{arm.name}: {poses.shape[0] - 1} line(s), {path.length / lu:.6g} {u} of weighted arc length "
        f"({path.tool_path.kinds.count('blend')} blends, {path.stops.size} stops), IK branch {path.branch}",
        f"  joint path: {path.breaks.size} knots, tcp within {dev.max() / lu:.3g} {u} of the lines "
        f"(tolerance {tol / lu:g} {u}; FK at 10x the knots), orientation within {rot.max():.2g} rad",
        f"  {law}: {timing.duration:.6g} s" + (f" (slowed by {timing.dilation:.6g} to the limits)"
                                               if timing.dilation > 1.0 + 1e-9 else ""),
        f"  largest tcp speed {speed.max() / lu:.6g} {u}/s; limit use: "
        + ", ".join(f"{k} {100 * r:.1f} %" for k, r in timing.ratios.items()),
        f"  joint peak |v| [rad/s or m/s]: {fmt(peaks.velocity, 4)}",
    ]
    return data, lines
