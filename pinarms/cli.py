"""The ``pinarms`` command line.

Every command prints a short human-readable report, or with ``--json`` one JSON document
on stdout. Units are SI (m, rad, s) unless ``--deg`` / ``--mm`` ask for degrees and
millimetres at the edge (:mod:`pinarms.units` converts). A user mistake (unknown robot,
malformed numbers, unreachable target, infeasible limits, missing file) ends with one line
``Error: ...`` on stderr and a non-zero exit status, never a Python traceback.

Exit status: 0 success, 1 a pinarms error (bad value, unreachable, infeasible, ...),
2 a command-line usage error (unknown option, missing argument).
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import sys
from pathlib import Path
from typing import Any, Callable, Iterable

import click
import numpy as np

from pinarms import robots
from pinarms.robots.errors import InvalidInput, PinarmsError
from pinarms.robots.robot import Robot

from .units import angle_scale, joints_from_si, joints_to_si, length_scale, prismatic_mask

__all__ = ["cli", "main"]

# numbers may be negative: "-0.5" must reach the command as a value, not as an option
_NUMBERS = {"ignore_unknown_options": True}
TRAJECTORY_KINDS = ("3-5-3", "multi-quintic", "quintic-bspline", "polynomial", "piecewise")
OPTIMIZE_KINDS = ("3-5-3", "multi-quintic", "quintic-bspline")


# --------------------------------------------------------------------------- plumbing
def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


class _Group(click.Group):
    """A click group that turns pinarms errors into one-line messages (exit status 1)."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except PinarmsError as exc:
            raise click.ClickException(_one_line(exc)) from None
        except FileNotFoundError as exc:
            raise click.ClickException(f"file not found: {exc.filename or _one_line(exc)}") from None
        except OSError as exc:
            where = f"{exc.filename}: " if exc.filename else ""
            raise click.ClickException(f"{where}{exc.strerror or _one_line(exc)}") from None


def jsonable(obj: Any) -> Any:
    """Plain JSON types for numpy arrays/scalars, dataclasses, paths and dict-like results."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, Path):
        return str(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    for method in ("as_dict", "to_dict"):
        if callable(getattr(obj, method, None)):
            return jsonable(getattr(obj, method)())
    if hasattr(obj, "_asdict"):
        return jsonable(obj._asdict())
    return obj if isinstance(obj, (str, int, type(None))) else str(obj)


def _emit(as_json: bool, data: dict, lines: Iterable[str]) -> None:
    if as_json:
        click.echo(json.dumps(jsonable(data), indent=2))
    else:
        for line in lines:
            click.echo(line)


def _fmt(values: Any, digits: int = 6) -> str:
    arr = np.atleast_1d(np.asarray(values, dtype=float))
    return "  ".join(f"{v:.{digits}g}" for v in arr)


def _show_progress(as_json: bool) -> bool:
    """Progress bars only for a person at a terminal, never in machine-readable output."""
    return (not as_json) and sys.stderr.isatty()


def _load_robot(name: str) -> Robot:
    """A registry name, or the path of any ``.urdf`` file."""
    if name.lower().endswith(".urdf"):
        return robots.from_urdf(name)
    return robots.load(name)


def _floats(text: str, what: str) -> np.ndarray:
    """``"1, 2,3"`` → array; a clear usage error otherwise."""
    parts = [p for p in text.replace(";", ",").split(",") if p.strip()]
    try:
        values = np.array([float(p) for p in parts], dtype=float)
    except ValueError:
        raise click.BadParameter(f"{what} must be comma-separated numbers, got {text!r}") from None
    if values.size == 0:
        raise click.BadParameter(f"{what} is empty")
    if not np.all(np.isfinite(values)):
        raise click.BadParameter(f"{what} holds a non-finite value: {text!r}")
    return values


def _limit(text: str | None, what: str, scale: float | np.ndarray) -> np.ndarray | float | None:
    """A limit option in user units → SI: one value for every joint, or one per joint."""
    if text is None:
        return None
    values = _floats(text, what)
    per_joint = np.asarray(scale, dtype=float)
    if per_joint.ndim and values.size not in (1, per_joint.size):
        raise InvalidInput(f"{what} takes one value or one per joint ({per_joint.size}), got {values.size}")
    values = values * per_joint
    return float(values[0]) if values.size == 1 else values


def _vectors_from_args(values: tuple[float, ...]) -> np.ndarray:
    return np.asarray(values, dtype=float)


def _at(scale: float | np.ndarray, joint: int) -> float:
    """The scale of one joint (a scalar scale applies to every joint)."""
    arr = np.asarray(scale, dtype=float)
    return float(arr[joint]) if arr.ndim else float(arr)


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="pinarms", prog_name="pinarms")
def cli() -> None:
    """pinarms: model, plan and time-optimise food/agricultural handling arms (on Pinocchio).

    Units are SI (m, rad, s); --deg and --mm convert at the command line.
    Every command takes --json for machine-readable output.
    """


def main() -> None:
    """Console-script entry point (``pinarms``)."""
    cli(prog_name="pinarms")


json_option = click.option("--json", "as_json", is_flag=True, help="Print one JSON document instead of text.")


# --------------------------------------------------------------------------- robots
@cli.command("robots")
@json_option
def robots_cmd(as_json: bool) -> None:
    """List the robots `pinarms` knows (built-in arms and example-robot-data arms) with their DoF."""
    from pinarms.robots.registry import info

    rows = []
    for name in robots.names():
        entry = info(name)
        robot = robots.load(name)
        rows.append(
            {
                "name": name,
                "dof": robot.nq,
                "source": entry.source,
                "description": entry.description,
                "joints": list(robot.joint_names),
            }
        )
    width = max(len(r["name"]) for r in rows)
    lines = [f"{'name':<{width}}  dof  source              description"]
    lines += [f"{r['name']:<{width}}  {r['dof']:>3}  {r['source']:<18}  {r['description']}" for r in rows]
    _emit(as_json, {"robots": rows}, lines)


# --------------------------------------------------------------------------- fk
@cli.command("fk", context_settings=_NUMBERS)
@click.argument("robot")
@click.argument("q", nargs=-1, type=float, required=True)
@click.option("--deg", is_flag=True, help="Revolute joint values in degrees (output angles too).")
@click.option("--mm", is_flag=True, help="Prismatic joint values and the output position in millimetres.")
@click.option("--frame", default="tcp", show_default=True, help="Frame whose pose is printed.")
@json_option
def fk_cmd(robot: str, q: tuple[float, ...], deg: bool, mm: bool, frame: str, as_json: bool) -> None:
    """Forward kinematics: pose of FRAME for joint values Q... (one per independent joint)."""
    import pinocchio as pin

    arm = _load_robot(robot)
    values = _vectors_from_args(q)
    if values.size != arm.nq:
        raise InvalidInput(
            f"{arm.name} has {arm.nq} joints ({', '.join(arm.joint_names)}); got {values.size} value(s) for Q"
        )
    q_si = joints_to_si(arm, values, deg=deg, mm=mm)
    T = arm.fk(q_si, frame=frame)
    rpy = pin.rpy.matrixToRpy(T[:3, :3])
    pos = T[:3, 3] / length_scale(mm)
    ang = rpy / angle_scale(deg)
    lu, au = ("mm" if mm else "m"), ("deg" if deg else "rad")
    limits_ok = bool(arm.within_limits(q_si))
    data = {
        "robot": arm.name,
        "frame": frame,
        "q": values,
        "q_si": q_si,
        "position": pos,
        "rpy": ang,
        "units": {"position": lu, "angles": au},
        "T": T,
        "within_limits": limits_ok,
    }
    lines = [
        f"{arm.name}  frame {frame}",
        f"position [{lu}]: {_fmt(pos)}",
        f"roll pitch yaw [{au}]: {_fmt(ang)}",
        "T (frame → base, SI):",
        *("  " + "  ".join(f"{v: .6f}" for v in row) for row in T),
    ]
    if not limits_ok:
        lines.append("warning: q is outside the joint limits: " + "; ".join(arm.limit_violations(q_si)))
    _emit(as_json, data, lines)


# --------------------------------------------------------------------------- ik
def _target_pose(pose: np.ndarray, deg: bool, mm: bool) -> np.ndarray:
    import pinocchio as pin

    if pose.size not in (3, 6):
        raise InvalidInput(f"give X Y Z or X Y Z ROLL PITCH YAW (3 or 6 numbers), got {pose.size}")
    T = np.eye(4)
    T[:3, 3] = pose[:3] * length_scale(mm)
    if pose.size == 6:
        T[:3, :3] = pin.rpy.rpyToMatrix(*(pose[3:] * angle_scale(deg)))
    return T


@cli.command("ik", context_settings=_NUMBERS)
@click.argument("robot")
@click.argument("pose", nargs=-1, type=float, required=True)
@click.option("--all", "all_solutions", is_flag=True, help="Every analytic solution within the limits.")
@click.option("--deg", is_flag=True, help="ROLL PITCH YAW and revolute joint output in degrees.")
@click.option("--mm", is_flag=True, help="X Y Z and prismatic joint output in millimetres.")
@click.option("--seed-q", default=None, help="Comma-separated start configuration for the numerical solver.")
@json_option
def ik_cmd(robot: str, pose: tuple[float, ...], all_solutions: bool, deg: bool, mm: bool,
           seed_q: str | None, as_json: bool) -> None:
    """Inverse kinematics for the tcp at X Y Z [ROLL PITCH YAW] (base frame).

    With three numbers only the position is asked (orientation free for the numerical
    solver; with --all the orientation is taken as the base's). With --all every
    closed-form solution within the joint limits is listed.
    """
    arm = _load_robot(robot)
    values = _vectors_from_args(pose)
    T = _target_pose(values, deg, mm)
    position_only = values.size == 3
    if all_solutions:
        if not arm.has_analytic_ik:
            raise InvalidInput(f"{arm.name} has no closed-form IK; drop --all to use the numerical solver")
        sols = np.atleast_2d(arm.ik_all(T))
        if sols.size == 0:
            sols = np.zeros((0, arm.nq))
    else:
        q0 = None
        if seed_q is not None:
            start = _floats(seed_q, "--seed-q")
            if start.size != arm.nq:
                raise InvalidInput(
                    f"--seed-q needs {arm.nq} values for {arm.name} ({', '.join(arm.joint_names)}), got {start.size}"
                )
            q0 = joints_to_si(arm, start, deg=deg, mm=mm)
        sols = np.atleast_2d(arm.ik(T, q0, position_only=position_only))
    rows = []
    for q in sols:
        T_q = arm.fk(q)
        rows.append(
            {
                "q": joints_from_si(arm, q, deg=deg, mm=mm),
                "position_error_m": float(np.linalg.norm(T_q[:3, 3] - T[:3, 3])),
            }
        )
    lu, au = ("mm" if mm else "m"), ("deg" if deg else "rad")
    kinds = ["mm" if (p and mm) else "m" if p else au for p in prismatic_mask(arm)]
    data = {
        "robot": arm.name,
        "target": {"position": values[:3], "rpy": values[3:] if values.size == 6 else None},
        "units": {"position": lu, "angles": au, "joints": kinds},
        "joint_names": list(arm.joint_names),
        "solutions": rows,
    }
    header = "  ".join(f"{n}[{u}]" for n, u in zip(arm.joint_names, kinds))
    lines = [f"{arm.name}: {len(rows)} solution(s)  ({header})"]
    lines += [f"  {_fmt(r['q'])}   |Δp| = {r['position_error_m']:.1e} m" for r in rows]
    if not rows:  # only with --all: the numerical solver raises UnreachableTarget instead
        reason = arm.ik_failure_reason(T)
        data["reason"] = reason
        lines.append(f"  none within the joint limits: {reason}")
    _emit(as_json, data, lines)


# --------------------------------------------------------------------------- workspace
@cli.command("workspace")
@click.argument("robot")
@click.option("-n", "n", default=20000, show_default=True, type=click.IntRange(min=1), help="Samples.")
@click.option("--seed", default=0, show_default=True, type=int, help="Random seed.")
@click.option("--frame", default="tcp", show_default=True)
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Also save the cloud into a session file.")
@json_option
def workspace_cmd(robot: str, n: int, seed: int, frame: str, session_path: str | None, as_json: bool) -> None:
    """Monte Carlo workspace of ROBOT: extent, sphere fit, manipulability, recommended table region.

    The region is robots.placement.recommend_region's radial band on the working side of
    the base plane (distances in the JSON in metres).
    """
    arm = _load_robot(robot)
    from pinarms.robots.placement import recommend_region
    from pinarms.robots.workspace import sample_workspace

    ws = sample_workspace(arm, n=n, seed=seed, frame=frame)
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
        session = _new_session(arm, f"workspace of {arm.name}")
        session.add_workspace("workspace", ws)
        _save_session(session, session_path, data, lines)
    _emit(as_json, data, lines)


# --------------------------------------------------------------------------- layout
@cli.command("layout", context_settings=_NUMBERS)
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
    arm = _load_robot(robot)
    from pinarms.robots.workspace import sample_workspace

    values = _vectors_from_args(xyz)
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
    _emit(as_json, data, lines)


# --------------------------------------------------------------------------- via points
def read_via_file(path: str) -> dict[str, Any]:
    """Via points from a JSON or CSV file.

    JSON: ``{"times": [...], "positions": [[...], ...], "kind": ..., "degree": ...}``
    (``times``/``kind`` optional). CSV: a header row; a column named ``t`` or ``time``
    holds knot times, every other column is one joint; one row per via point.
    """
    file = Path(path)
    text = file.read_text(encoding="utf-8")
    if file.suffix.lower() == ".json":
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InvalidInput(f"{path}: not valid JSON ({exc.msg}, line {exc.lineno})") from None
        if not isinstance(doc, dict) or "positions" not in doc:
            raise InvalidInput(f"{path}: expected an object with 'positions' (and optional 'times', 'kind')")
        return _checked_via_doc(doc, path)
    rows = list(csv.reader(io.StringIO(text)))
    rows = [r for r in rows if any(c.strip() for c in r)]
    if len(rows) < 3:
        raise InvalidInput(f"{path}: a CSV needs a header row and at least two via points")
    header = [h.strip().lower() for h in rows[0]]
    try:
        table = np.array([[float(c) for c in r] for r in rows[1:]], dtype=float)
    except ValueError:
        raise InvalidInput(f"{path}: every CSV cell after the header must be a number") from None
    if table.ndim != 2 or table.shape[1] != len(header):
        raise InvalidInput(f"{path}: every CSV row must have {len(header)} cells like the header")
    doc: dict[str, Any] = {}
    time_cols = [i for i, h in enumerate(header) if h in ("t", "time", "time_s", "t_s")]
    if time_cols:
        doc["times"] = table[:, time_cols[0]]
    joints = [i for i in range(len(header)) if i not in time_cols]
    doc["positions"] = table[:, joints]
    doc["joint_names"] = [rows[0][i].strip() for i in joints]
    return doc


def _checked_via_doc(doc: dict[str, Any], path: str) -> dict[str, Any]:
    """A JSON via-point document with numeric arrays and a known kind, or InvalidInput."""
    out = dict(doc)
    for key, ndim in (("positions", 2), ("times", 1)):
        if out.get(key) is None:
            continue
        try:
            arr = np.asarray(out[key], dtype=float)
        except (TypeError, ValueError):
            raise InvalidInput(f"{path}: '{key}' must be {'rows of ' if ndim == 2 else 'a list of '}numbers "
                               f"(one {'row' if ndim == 2 else 'value'} per via point)") from None
        if key == "positions" and arr.ndim == 1:
            arr = arr[:, None]
        if arr.ndim != ndim:
            raise InvalidInput(f"{path}: '{key}' must be a {ndim}-D list of numbers, got shape {arr.shape}")
        out[key] = arr
    kind = out.get("kind")
    if kind is not None and kind not in TRAJECTORY_KINDS:
        raise InvalidInput(f"{path}: unknown 'kind' {kind!r}; use one of {', '.join(TRAJECTORY_KINDS)}")
    degree = out.get("degree")
    if degree is not None and (isinstance(degree, bool) or not isinstance(degree, int)):
        raise InvalidInput(f"{path}: 'degree' must be a whole number (3, 5 or 7), got {degree!r}")
    return out


def _via_input(via: tuple[str, ...], times: str | None, file: str | None) -> tuple[np.ndarray | None, np.ndarray, dict]:
    """(times or None, positions (m+1, n_joints), extra file options)."""
    if file and via:
        raise click.UsageError("give via points either with --via or with --file, not both")
    extra: dict = {}
    if file:
        doc = read_via_file(file)
        positions = np.asarray(doc["positions"], dtype=float)
        t = None if doc.get("times") is None else np.asarray(doc["times"], dtype=float)
        extra = {k: v for k, v in doc.items() if k not in ("positions", "times")}
    elif via:
        points = [_floats(v, "--via") for v in via]
        if len({p.size for p in points}) != 1:
            raise InvalidInput(f"every --via must have the same number of joint values, got sizes {[p.size for p in points]}")
        positions = np.vstack(points)
        t = None
    else:
        raise click.UsageError("give via points with --via (repeat it, one point each) or --file")
    if times is not None:
        t = _floats(times, "--times")
    if positions.ndim == 1:
        positions = positions[:, None]
    if positions.shape[0] < 2:
        raise InvalidInput(f"need at least two via points, got {positions.shape[0]}")
    return t, positions, extra


def _new_session(robot: Robot | str | None, title: str):
    """A :class:`viz.Session` for ``robot`` (built-in name or any URDF)."""
    from pinarms import viz

    return viz.Session(robot=robot, title=title)


def _save_session(session: Any, path: str, data: dict, lines: list[str]) -> None:
    """Write ``session`` to ``path`` and report it in the command's JSON ``data`` and text ``lines``."""
    session.save(path)
    data["session"] = path
    lines.append(f"session written: {path}")


def _build_trajectory(kind: str, times: np.ndarray, positions: np.ndarray, degree: int | None, degrees: str | None):
    from pinarms import planning

    if kind == "3-5-3":
        return planning.piecewise_polynomial(times, positions, degrees=(3, 5, 3))
    if kind == "piecewise":
        if degrees is None:
            raise click.UsageError("--kind piecewise needs --degrees, e.g. --degrees 4,3,4")
        values = _floats(degrees, "--degrees")
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
        f"peak |velocity|     [{unit}/s]:   {_fmt(np.asarray(peaks.velocity) / scale)}",
        f"peak |acceleration| [{unit}/s²]:  {_fmt(np.asarray(peaks.acceleration) / scale)}",
        f"peak |jerk|         [{unit}/s³]:  {_fmt(np.asarray(peaks.jerk) / scale)}",
    ]


def _peaks_dict(peaks: Any, scale: float | np.ndarray) -> dict:
    return {
        "velocity": np.asarray(peaks.velocity) / scale,
        "acceleration": np.asarray(peaks.acceleration) / scale,
        "jerk": np.asarray(peaks.jerk) / scale,
    }


def _limits_from_options(vmax, amax, jmax, robot: Robot | None, scale: float | np.ndarray):
    """Velocity/acceleration/jerk limits (SI) from options, else the robot's velocity limits.

    ``--amax``/``--jmax`` without a velocity limit are a usage error, not silently ignored.
    """
    v = _limit(vmax, "--vmax", scale)
    a = _limit(amax, "--amax", scale)
    j = _limit(jmax, "--jmax", scale)
    if v is None and robot is not None:
        v = robot.velocity_limit
        if not np.all(v > 0):
            raise InvalidInput(f"{robot.name}'s URDF gives no velocity limit for every joint; pass --vmax")
    if v is None and (a is not None or j is not None):
        raise click.UsageError("--amax/--jmax need a velocity limit too: give --vmax (or --robot)")
    return v, a, j


# --------------------------------------------------------------------------- plan
@cli.command("plan", context_settings=_NUMBERS)
@click.option("--kind", type=click.Choice(TRAJECTORY_KINDS), default="3-5-3", show_default=True)
@click.option("--via", multiple=True, help="One via point: comma-separated joint values (repeat, in order).")
@click.option("--times", default=None, help="Comma-separated knot times [s], one per via point.")
@click.option("--file", "file", default=None, type=click.Path(exists=True, dir_okay=False),
              help="Via points (and times) from a .json or .csv file.")
@click.option("--degree", type=int, default=None, help="Degree for --kind polynomial.")
@click.option("--degrees", default=None, help="Per-segment degrees for --kind piecewise, e.g. 4,3,4.")
@click.option("--deg", is_flag=True,
              help="Joint values and limits in degrees (with --robot: its revolute joints; prismatic stay in m).")
@click.option("--robot", default=None, help="Take velocity limits from this robot (and store it in the session).")
@click.option("--vmax", default=None, help="Velocity limit(s), one or per joint, comma-separated.")
@click.option("--amax", default=None, help="Acceleration limit(s).")
@click.option("--jmax", default=None, help="Jerk limit(s).")
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Save the trajectory into a session file.")
@json_option
def plan_cmd(kind, via, times, file, degree, degrees, deg, robot, vmax, amax, jmax, session_path, as_json) -> None:
    """Plan a joint trajectory through via points; print its exact peaks and the limit check.

    Example (seed 000, joint 1): pinarms plan --kind 3-5-3 --deg --times 0,2,4,6
    --via 55.5 --via 69.7 --via 106.5 --via 124.5 --vmax 55
    """
    from pinarms import planning

    if session_path and not robot:
        raise click.UsageError("--session needs --robot: a session stores the trajectory with its robot")
    t, positions, extra = _via_input(via, times, file)
    if t is None:
        raise click.UsageError("give knot times with --times (or a 't' column / 'times' key in the file)")
    if extra.get("kind") and kind == "3-5-3" and extra["kind"] in TRAJECTORY_KINDS:
        kind = extra["kind"]
    degree = degree if degree is not None else extra.get("degree")
    arm = _load_robot(robot) if robot else None
    scale = _joint_scale(arm, deg, positions.shape[1])
    traj = _build_trajectory(kind, t, positions * scale, degree, degrees)
    peaks = traj.peaks()
    unit = _unit_label(arm, deg)
    v, a, j = _limits_from_options(vmax, amax, jmax, arm, scale)
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
             "value": float(vi[3]) / _at(scale, int(vi[0])), "limit": float(vi[4]) / _at(scale, int(vi[0]))}
            for vi in report.violations
        ],
    }
    lines = [
        f"{kind} trajectory: {traj.n_joints} joint(s), {positions.shape[0]} via points, duration {traj.duration:.6g} s",
        f"knot times [s]: {_fmt(traj.knot_times)}",
        *_peaks_lines(peaks, scale, unit),
    ]
    if report is not None:
        lines.append("limits: ok" if report.ok else f"limits: {len(report.violations)} violation(s)")
        lines += [
            f"  joint {d['joint']} {d['kind']} {d['value']:.6g} > {d['limit']:.6g} at t = {d['time_s']:.4g} s"
            for d in data["violations"][:10]
        ]
    if session_path:
        session = _new_session(arm, f"{kind} trajectory")
        session.add_trajectory(kind, traj)
        _save_session(session, session_path, data, lines)
    _emit(as_json, data, lines)


# --------------------------------------------------------------------------- optimize
@cli.command("optimize", context_settings=_NUMBERS)
@click.option("--kind", type=click.Choice(OPTIMIZE_KINDS), default="3-5-3", show_default=True)
@click.option("--via", multiple=True, help="One via point: comma-separated joint values (repeat, in order).")
@click.option("--file", "file", default=None, type=click.Path(exists=True, dir_okay=False),
              help="Via points from a .json or .csv file.")
@click.option("--deg", is_flag=True,
              help="Joint values and limits in degrees (with --robot: its revolute joints; prismatic stay in m).")
@click.option("--robot", default=None, help="Take velocity limits from this robot.")
@click.option("--vmax", default=None, help="Velocity limit(s), one or per joint.")
@click.option("--amax", default=None, help="Acceleration limit(s).")
@click.option("--jmax", default=None, help="Jerk limit(s).")
@click.option("--method", type=click.Choice(["ga", "exact"]), default="ga", show_default=True)
@click.option("--seed", default=0, show_default=True, type=int, help="Random seed of the GA.")
@click.option("--generations", default=None, type=click.IntRange(min=1), help="Maximum GA generations.")
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Save the optimised trajectory (and GA history) into a session file.")
@json_option
def optimize_cmd(kind, via, file, deg, robot, vmax, amax, jmax, method, seed, generations, session_path, as_json) -> None:
    """Shortest segment times through via points under velocity/acceleration/jerk limits.

    Example (seed 000): pinarms optimize --kind 3-5-3 --deg --via 55.5 --via 69.7
    --via 106.5 --via 124.5 --vmax 55
    """
    from pinarms import optim

    if session_path and not robot:
        raise click.UsageError("--session needs --robot: a session stores the trajectory with its robot")
    _, positions, _ = _via_input(via, None, file)
    arm = _load_robot(robot) if robot else None
    scale = _joint_scale(arm, deg, positions.shape[1])
    unit = _unit_label(arm, deg)
    v, a, j = _limits_from_options(vmax, amax, jmax, arm, scale)
    if v is None:
        raise click.UsageError("give a velocity limit with --vmax (or --robot)")
    kwargs: dict[str, Any] = {}
    if generations is not None and method == "ga":
        kwargs["max_generations"] = generations
    progress = _show_progress(as_json) and method == "ga"
    if progress:
        budget = generations or optim.GASettings.seed002().max_generations  # minimize_time's default settings
        bar = click.progressbar(length=budget, label="GA generations", file=sys.stderr)
        bar.__enter__()

        def tick(_state: Any) -> None:
            bar.update(1)

        kwargs["callback"] = tick
    try:
        result = optim.minimize_time(positions * scale, kind, v, a, j, method=method, seed=seed, **kwargs)
    finally:
        if progress:
            bar.__exit__(None, None, None)
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
        f"segment durations [s]: {_fmt(result.durations)}",
        *_peaks_lines(result.peaks, scale, unit),
    ]
    if session_path:
        session = _new_session(arm, f"time-optimal {kind}")
        session.add_trajectory(f"{kind} ({result.method})", result.trajectory)
        if result.history is not None:
            session.add_history(f"{kind} GA", result.history)
        _save_session(session, session_path, data, lines)
    _emit(as_json, data, lines)


# --------------------------------------------------------------------------- cycle
@cli.command("cycle", context_settings=_NUMBERS)
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
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Save the cycle (trajectory, via points, pick and place) into a session file.")
@json_option
def cycle_cmd(robot, pick, place, via, lift, dwell, mm, kind, vmax, amax, jmax, method, seed, session_path,
              as_json) -> None:
    """Time-optimal pick-and-place cycle of ROBOT: pick, lift, transfer, lower, place, and back.

    Prints the time of each move, the cycle time, picks per minute and how far the tcp
    leaves the straight vertical approach/retreat lines (optim.plan_cycle; the tool points
    down on 6+ joint arms). Limits are SI per joint; --mm converts only lengths.

    Example: pinarms cycle aubo_i3 --pick 350 200 150 --place -100 400 100 --mm
    """
    from pinarms import optim

    arm = _load_robot(robot)
    scale = length_scale(mm)
    lu = "mm" if mm else "m"
    lift_m = 0.05 if lift is None else lift * scale
    spec = optim.PickPlace(np.array(pick) * scale, np.array(place) * scale, lift=lift_m, dwell=dwell,
                           via=[np.array(v) * scale for v in via])
    res = optim.plan_cycle(arm, spec, kind=kind, vmax=_limit(vmax, "--vmax", np.ones(arm.nq)),
                           amax=_limit(amax, "--amax", np.ones(arm.nq)), jmax=_limit(jmax, "--jmax", np.ones(arm.nq)),
                           method=method, seed=seed)
    data = res.as_dict()
    data["units"] = {"lengths": "m", "times": "s", "limits": "rad or m per s^k", "given_points": lu}
    dev = res.line_deviation / scale
    lines = [
        (f"{arm.name}: pick-and-place cycle, {kind} ({method}), lift {lift_m / scale:g} {lu}, "
         f"dwell {dwell:g} s at pick and place"),
        f"  move to place: {res.move_times[0]:.4f} s  (segments {_fmt(res.moves[0].durations, 4)} s)",
        f"  move to pick:  {res.move_times[1]:.4f} s  (segments {_fmt(res.moves[1].durations, 4)} s)",
        f"cycle time {res.cycle_time:.4f} s, {res.picks_per_minute:.2f} picks per minute",
        "peak / limit: " + ", ".join(f"{k} {v.max():.4f}" for k, v in res.limit_ratios.items()),
        f"tcp off the vertical lines [{lu}]: "
        + ", ".join(f"{name} {d:.4g}" for name, d in zip(optim.cycle.LINE_NAMES, dev)),
        "IK: one branch for every waypoint" if res.one_branch else
        f"IK: branches {res.branches.tolist()} (the joint limits force a switch, or the arm is solved numerically)",
    ]
    if session_path:
        session = _new_session(arm, f"pick-and-place cycle of {arm.name}")
        session.add_trajectory("cycle", res.trajectory)
        session.add_points("cycle_via_points", res.waypoints[:, :3, 3], kind="via")
        place_m = res.waypoints[res.names.index("place"), :3, 3]
        session.add_points("pick_place", np.stack([res.waypoints[0, :3, 3], place_m]), kind="target")
        _save_session(session, session_path, data, lines)
    _emit(as_json, data, lines)


# --------------------------------------------------------------------------- sessions
@cli.command("view")
@click.argument("session", type=click.Path(exists=True, dir_okay=False))
@click.option("--port", default=None, type=click.IntRange(1, 65535), help="HTTP port (default: a free one).")
@click.option("--open", "open_browser", is_flag=True, help="Open the page in the default web browser.")
@click.option("--no-wait", is_flag=True, help="Show, print the address and stop at once (for scripts/tests).")
@json_option
def view_cmd(session: str, port: int | None, open_browser: bool, no_wait: bool, as_json: bool) -> None:
    """Open a saved SESSION in the MeshCat viewer (local server on 127.0.0.1; Ctrl+C stops it)."""
    from pinarms import viz

    loaded = viz.load_session(session)
    viewer = viz.show(loaded, port=port, open_browser=open_browser, wait=False)
    try:
        _emit(as_json, {"session": session, "url": viewer.url, "title": loaded.title},
              [f"{loaded.title or session}: viewer at {viewer.url}"] + ([] if no_wait else ["press Ctrl+C to stop"]))
        if not no_wait:
            sys.stdout.flush()
            viewer.wait()
    finally:
        viewer.close()


@cli.command("export-html")
@click.argument("session", type=click.Path(exists=True))
@click.argument("out", type=click.Path(dir_okay=False))
@json_option
def export_html_cmd(session: str, out: str, as_json: bool) -> None:
    """Write SESSION as one self-contained HTML page OUT (opens offline in any browser)."""
    from pinarms import viz

    loaded = viz.load_session(session)
    path = viz.export_html(loaded, out)
    path = Path(path) if path else Path(out)
    size = path.stat().st_size
    _emit(as_json, {"session": session, "html": str(path), "bytes": size}, [f"wrote {path} ({size / 1e6:.2f} MB)"])


# --------------------------------------------------------------------------- urdf
@cli.group("urdf", cls=_Group)
def urdf_group() -> None:
    """Build the built-in URDFs from their xacro sources, or export a URDF for other tools."""


@urdf_group.command("build")
@click.option("--check", is_flag=True, help="Only check: exit 1 and list the URDFs that differ from their xacro.")
@click.option("--out", "out_dir", default=None, type=click.Path(file_okay=False),
              help="Write into this folder instead of the urdf/ package.")
@json_option
def urdf_build_cmd(check: bool, out_dir: str | None, as_json: bool) -> None:
    """Regenerate urdf/*.urdf from robots/xacro/*.urdf.xacro."""
    from pinarms.robots import urdf_build

    if check:
        stale = urdf_build.stale(out_dir)
        _emit(as_json, {"stale": stale}, [f"stale: {name}" for name in stale] or ["all URDFs are up to date"])
        if stale:
            raise SystemExit(1)
        return
    written = urdf_build.build_all(out_dir)
    _emit(as_json, {"written": [str(p) for p in written]}, [f"wrote {p}" for p in written])


@urdf_group.command("export")
@click.argument("robot")
@click.argument("out_dir", type=click.Path(file_okay=True))
@click.option("--overwrite", is_flag=True, help="Replace a non-empty folder.")
@json_option
def urdf_export_cmd(robot: str, out_dir: str, overwrite: bool, as_json: bool) -> None:
    """Write ROBOT as a self-contained folder (URDF with relative mesh paths + meshes) into OUT_DIR."""
    from .export import export_urdf

    result = export_urdf(_load_robot(robot), out_dir, overwrite=overwrite)
    _emit(
        as_json,
        {"folder": result.folder, "urdf": result.urdf, "meshes": list(result.meshes)},
        [f"wrote {result.urdf} and {len(result.meshes)} mesh file(s)"],
    )


# --------------------------------------------------------------------------- demo
@cli.command("demo")
@click.option("--quick", is_flag=True, help="Smaller samples and GA runs: under a minute.")
@click.option("--out", "out_dir", default="demo-output", show_default=True, type=click.Path(file_okay=False))
@click.option("--only", multiple=True, type=click.Choice(["000", "001", "002", "004"]), help="Run only these studies.")
@click.option("--readme", "readme", default=None, type=click.Path(exists=True, dir_okay=False),
              help="Also write the table into this markdown file, between its table markers (full run only).")
@json_option
def demo_cmd(quick: bool, out_dir: str, only: tuple[str, ...], readme: str | None, as_json: bool) -> None:
    """Redo the four papers' studies, print the paper-vs-pinarms table and write sessions, HTML and plots."""
    from .demo import run_demo
    from .report import splice_table

    if readme and (quick or only):
        raise click.UsageError("--readme takes the table of the full run: drop --quick and --only")
    if readme:
        splice_table(Path(readme).read_text(encoding="utf-8"), [])  # markers checked before the long run
    progress: Callable[[str], None] | None = None
    if _show_progress(as_json):
        progress = lambda label: click.echo(f"· {label}", err=True)  # noqa: E731
    result = run_demo(out_dir, quick=quick, only=only or None, progress=progress)
    lines = [result.table_text(), "", *(f"wrote {p}" for p in result.files)]
    data = result.as_dict()
    if readme:
        doc = Path(readme)
        doc.write_text(splice_table(doc.read_text(encoding="utf-8"), result.rows), encoding="utf-8")
        data["readme"] = readme
        lines.append(f"table written into {readme}")
    _emit(as_json, data, lines)


if __name__ == "__main__":  # pragma: no cover
    main()
