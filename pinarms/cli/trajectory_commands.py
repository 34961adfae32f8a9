"""Joint trajectories through via points: ``plan`` and ``optimize`` (via points from options, CSV or JSON:
:mod:`.via_points`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import click
import numpy as np

from pinarms.errors import InvalidInput
from pinarms.robots.robot import Robot
from pinarms.units import (
    angle_scale,
    prismatic_mask,
)

from pinarms.cli import _common as common
from pinarms.cli._common import (
    NUMBERS,
    cli,
    emit,
    floats,
    fmt,
    joint_scale_at,
    load_robot,
    new_session,
    save_session,
)
from pinarms.cli.option_groups import Flag, LoadFlags, OutputFlags, TimingFlags, flag, option_group
from pinarms.cli.via_points import TRAJECTORY_KINDS, via_input

OPTIMIZE_KINDS = ("3-5-3", "multi-quintic", "quintic-bspline")


@dataclass(frozen=True)
class ViaFlags:
    """The via points as typed: ``--via`` (comma-separated joint values, in order), knot ``--times`` [s],
    or a ``--file`` (.json or .csv) with both."""

    via: tuple[str, ...] = ()
    times: str | None = None
    file: str | None = None

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--via", multiple=True, help="One via point: comma-separated joint values (repeat, in order)."),
        flag("--times", default=None, help="Comma-separated knot times [s], one per via point."),
        flag("--file", "file", default=None, type=click.Path(exists=True, dir_okay=False),
             help="Via points (and times) from a .json or .csv file."),
    )

    def read(self) -> tuple[np.ndarray | None, np.ndarray, dict]:
        """``(times or None, positions (n, nq), extras of the file)`` (:func:`~pinarms.cli.via_points.via_input`)."""
        return via_input(self.via, self.times, self.file)


#: The limits of ``plan`` and ``optimize`` (user units: degrees with --deg).
_LIMIT_WORDS = {"vmax": {"help": "Velocity limit(s), one or per joint, comma-separated."},
                "amax": {"help": "Acceleration limit(s)."}, "jmax": {"help": "Jerk limit(s)."}}


def _build_trajectory(kind: str, times: np.ndarray, positions: np.ndarray, degree: int | None, degrees: str | None):
    from pinarms import planning

    if kind == "3-5-3":
        return planning.piecewise_polynomial(times, positions, degrees=(3, 5, 3))
    if kind == "piecewise":
        if degrees is None:
            raise click.UsageError("--kind piecewise needs --degrees, e.g. --degrees 4,3,4")
        values = floats(degrees, "--degrees")
        if np.any(values != np.round(values)) or np.any(values < 1):
            raise click.BadParameter(f"--degrees takes whole polynomial degrees >= 1, got {degrees!r}")
        degs = tuple(int(d) for d in values)
        return planning.piecewise_polynomial(times, positions, degrees=degs)
    if kind == "multi-quintic":
        return planning.multi_quintic(times, positions)
    if kind == "quintic-bspline":
        return planning.quintic_bspline(times, positions)
    if kind == "polynomial":
        if degree is None:
            raise click.UsageError("--kind polynomial needs --degree (3, 5 or 7)")
        return planning.polynomial(times, positions, degree)
    raise click.UsageError(f"unknown kind {kind!r}; use one of {', '.join(TRAJECTORY_KINDS)}")


def _joint_scale(robot: Robot | None, deg: bool, n_joints: int) -> float | np.ndarray:
    """SI per user unit of each via-point column (and of its limits).

    Without a robot every joint is taken as revolute: radians per degree with ``--deg``,
    else 1. With a robot its prismatic joints stay in metres (scale 1) whatever ``--deg``
    says, and the number of columns must be its number of joints.
    """
    if robot is None:
        return angle_scale(deg)
    if robot.nq != n_joints:
        raise InvalidInput(
            f"{robot.name} has {robot.nq} joints ({', '.join(robot.joint_names)}) but the via points have "
            f"{n_joints} value(s) each"
        )
    return np.where(prismatic_mask(robot), 1.0, angle_scale(deg))


def _unit_label(robot: Robot | None, deg: bool) -> str:
    """Unit of the via-point values: ``deg``, ``deg|m`` (robot with prismatic joints) or ``rad|m``."""
    if not deg:
        return "rad|m"
    return "deg|m" if robot is not None and bool(np.any(prismatic_mask(robot))) else "deg"


def _peaks_lines(peaks: Any, scale: float | np.ndarray, unit: str) -> list[str]:
    return [
        f"peak |velocity|     [{unit}/s]:   {fmt(np.asarray(peaks.velocity) / scale)}",
        f"peak |acceleration| [{unit}/s²]:  {fmt(np.asarray(peaks.acceleration) / scale)}",
        f"peak |jerk|         [{unit}/s³]:  {fmt(np.asarray(peaks.jerk) / scale)}",
    ]


def _peaks_dict(peaks: Any, scale: float | np.ndarray) -> dict:
    return {
        "velocity": np.asarray(peaks.velocity) / scale,
        "acceleration": np.asarray(peaks.acceleration) / scale,
        "jerk": np.asarray(peaks.jerk) / scale,
    }


def _limits_from_options(timing: TimingFlags, robot: Robot | None, scale: float | np.ndarray):
    """Velocity/acceleration/jerk limits (SI) from options, else the robot's velocity limits.

    ``--amax``/``--jmax`` without a velocity limit are a usage error, not silently ignored.
    """
    v, a, j = timing.limits(scale)
    if v is None and robot is not None:
        v = robot.velocity_limit
        if not np.all(v > 0):
            raise InvalidInput(f"{robot.name}'s URDF gives no velocity limit for every joint; pass --vmax")
    if v is None and (a is not None or j is not None):
        raise click.UsageError("--amax/--jmax need a velocity limit too: give --vmax (or --robot)")
    return v, a, j


# --------------------------------------------------------------------------- plan
@cli.command("plan", context_settings=NUMBERS)
@option_group(TimingFlags, "timing", only=("kind", "vmax", "amax", "jmax"),
              kind={"type": click.Choice(TRAJECTORY_KINDS), "default": "3-5-3"}, **_LIMIT_WORDS)
@option_group(ViaFlags, "vias")
@click.option("--degree", type=int, default=None, help="Degree for --kind polynomial.")
@click.option("--degrees", default=None, help="Per-segment degrees for --kind piecewise, e.g. 4,3,4.")
@click.option("--deg", is_flag=True,
              help="Joint values and limits in degrees (with --robot: its revolute joints; prismatic stay in m).")
@click.option("--robot", default=None, help="Take velocity limits from this robot (and store it in the session).")
@option_group(OutputFlags, "output", only=("session_path", "as_json"),
              session_path={"help": "Save the trajectory into a session file."})
def plan_cmd(timing: TimingFlags, vias: ViaFlags, degree: int | None, degrees: str | None, deg: bool,
             robot: str | None, output: OutputFlags) -> None:
    """Plan a joint trajectory through via points; print its exact peaks and the limit check.

    Example (seed 000, joint 1): pinarms plan --kind 3-5-3 --deg --times 0,2,4,6
    --via 55.5 --via 69.7 --via 106.5 --via 124.5 --vmax 55
    """
    from pinarms import planning

    kind, session_path, as_json = timing.kind, output.session_path, output.as_json
    if session_path and not robot:
        raise click.UsageError("--session needs --robot: a session stores the trajectory with its robot")
    t, positions, extra = vias.read()
    if t is None:
        raise click.UsageError("give knot times with --times (or a 't' column / 'times' key in the file)")
    if extra.get("kind") and kind == "3-5-3" and extra["kind"] in TRAJECTORY_KINDS:
        kind = extra["kind"]
    degree = degree if degree is not None else extra.get("degree")
    arm = load_robot(robot) if robot else None
    scale = _joint_scale(arm, deg, positions.shape[1])
    traj = _build_trajectory(kind, t, positions * scale, degree, degrees)
    peaks = traj.peaks()
    unit = _unit_label(arm, deg)
    v, a, j = _limits_from_options(timing, arm, scale)
    report = None
    if v is not None:
        report = traj.check(planning.JointLimits(v, a, j))
    data = {
        "kind": kind,
        "n_joints": traj.n_joints,
        "duration_s": traj.duration,
        "knot_times_s": traj.knot_times,
        "units": unit,
        "peaks": _peaks_dict(peaks, scale),
        "limits_ok": None if report is None else bool(report.ok),
        "violations": [] if report is None else [
            {"joint": int(vi[0]), "time_s": float(vi[1]), "kind": str(vi[2]),
             "value": float(vi[3]) / joint_scale_at(scale, int(vi[0])), "limit": float(vi[4]) / joint_scale_at(scale, int(vi[0]))}
            for vi in report.violations
        ],
    }
    lines = [
        f"{kind} trajectory: {traj.n_joints} joint(s), {positions.shape[0]} via points, duration {traj.duration:.6g} s",
        f"knot times [s]: {fmt(traj.knot_times)}",
        *_peaks_lines(peaks, scale, unit),
    ]
    if report is not None:
        lines.append("limits: ok" if report.ok else f"limits: {len(report.violations)} violation(s)")
        lines += [
            f"  joint {d['joint']} {d['kind']} {d['value']:.6g} > {d['limit']:.6g} at t = {d['time_s']:.4g} s"
            for d in data["violations"][:10]
        ]
    if session_path:
        session = new_session(arm, f"{kind} trajectory")
        session.add_trajectory(kind, traj)
        save_session(session, session_path, data, lines)
    emit(as_json, data, lines)


# --------------------------------------------------------------------------- optimize
@cli.command("optimize", context_settings=NUMBERS)
@option_group(TimingFlags, "timing", kind={"type": click.Choice(OPTIMIZE_KINDS), "default": "3-5-3"},
              method={"type": click.Choice(["ga", "exact"]), "default": "ga"},
              seed={"help": "Random seed of the GA."},
              **{**_LIMIT_WORDS, "vmax": {"help": "Velocity limit(s), one or per joint."}})
@option_group(ViaFlags, "vias", only=("via", "file"), file={"help": "Via points from a .json or .csv file."})
@click.option("--deg", is_flag=True,
              help="Joint values and limits in degrees (with --robot: its revolute joints; prismatic stay in m).")
@click.option("--robot", default=None, help="Take velocity limits from this robot.")
@click.option("--generations", default=None, type=click.IntRange(min=1), help="Maximum GA generations.")
@option_group(LoadFlags, "load", payload={"help": "Mass at the tcp, e.g. 3kg or 800g (needs --robot): also limits joint "
                                                  "torques (--torque-max, default the URDF's efforts)."},
              torque={"help": "Also limit joint torques to the URDF's efforts (needs --robot)."},
              torque_max={"help": "Joint torque limit(s) [N·m, or N for prismatic joints] (needs --robot)."})
@option_group(OutputFlags, "output", only=("session_path", "as_json"),
              session_path={"help": "Save the optimised trajectory (and GA history) into a session file."})
def optimize_cmd(timing: TimingFlags, vias: ViaFlags, deg: bool, robot: str | None, generations: int | None,
                 load: LoadFlags, output: OutputFlags) -> None:
    """Shortest segment times through via points under velocity/acceleration/jerk limits.

    With --payload, --torque or --torque-max the joint torques of --robot (Pinocchio's RNEA,
    payload included) are limited too.

    Example (seed 000): pinarms optimize --kind 3-5-3 --deg --via 55.5 --via 69.7
    --via 106.5 --via 124.5 --vmax 55
    """
    from pinarms import optim

    kind, method, seed = timing.kind, timing.method, timing.seed
    session_path, as_json = output.session_path, output.as_json
    if session_path and not robot:
        raise click.UsageError("--session needs --robot: a session stores the trajectory with its robot")
    _, positions, _ = vias.read()
    arm = load_robot(robot) if robot else None
    scale = _joint_scale(arm, deg, positions.shape[1])
    unit = _unit_label(arm, deg)
    v, a, j = _limits_from_options(timing, arm, scale)
    if v is None:
        raise click.UsageError("give a velocity limit with --vmax (or --robot)")
    kwargs: dict[str, Any] = {}
    callback = None
    if generations is not None and method == "ga":
        kwargs["max_generations"] = generations
    if load.asked:
        if arm is None:
            raise click.UsageError("--payload, --torque and --torque-max need --robot (its inverse dynamics give the torques)")
        kwargs.update(robot=arm, payload=load.kg, torque_limits=load.torque_limits(arm.nq))
    budget = generations or optim.GASettings.seed002().max_generations  # minimize_time's default settings
    bar = common.progress_bar("GA generations", budget, as_json or method != "ga")
    if bar.enabled:
        callback = lambda _state: bar.advance()  # noqa: E731
    request = optim.TimingRequest(positions * scale, kind, v, a, j, method=method, seed=seed, **kwargs)
    try:
        result = optim.minimize_time(request, callback=callback)
    finally:
        bar.close()
    data = {
        "kind": kind,
        "method": result.method,
        "durations_s": result.durations,
        "total_s": result.total,
        "peaks": _peaks_dict(result.peaks, scale),
        "units": unit,
        "generations": None if result.history is None else len(getattr(result.history, "best", [])),
        "wall_time_s": result.wall_time,
    }
    lines = [
        f"{kind}, method {result.method}: total {result.total:.6g} s",
        f"segment durations [s]: {fmt(result.durations)}",
        *_peaks_lines(result.peaks, scale, unit),
    ]
    carrying = arm
    if result.torque_peaks is not None:
        carrying = arm if kwargs.get("payload") is None else arm.with_payload(kwargs["payload"])
        data["torque_peaks"] = result.torque_peaks.as_dict()
        data["torque_limit"] = result.torque_limit
        data["payload_kg"] = kwargs.get("payload")
        lines.append("torque / limit: " + ", ".join(
            f"{n} {r:.3f}" for n, r in zip(arm.joint_names, result.torque_ratios)))
    if session_path:
        session = new_session(carrying, f"time-optimal {kind}")
        session.add_trajectory(f"{kind} ({result.method})", result.trajectory)
        if result.history is not None:
            session.add_history(f"{kind} GA", result.history)
        save_session(session, session_path, data, lines)
    emit(as_json, data, lines)


