"""Commands about one robot: ``robots``, ``fk``, ``ik``, ``workspace``, ``layout``."""

from __future__ import annotations

import click
import numpy as np

from pinarms import robots
from pinarms.robots.errors import InvalidInput
from pinarms.units import (
    angle_scale,
    joints_from_si,
    joints_to_si,
    length_scale,
    prismatic_mask,
)

from . import _common as common
from ._common import (
    NUMBERS,
    cli,
    emit,
    floats,
    fmt,
    json_option,
    jsonable,
    load_robot,
    new_session,
    save_session,
    scheduler_option,
    vectors_from_args,
)


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
    emit(as_json, {"robots": rows}, lines)


# --------------------------------------------------------------------------- fk
@cli.command("fk", context_settings=NUMBERS)
@click.argument("robot")
@click.argument("q", nargs=-1, type=float, required=True)
@click.option("--deg", is_flag=True, help="Revolute joint values in degrees (output angles too).")
@click.option("--mm", is_flag=True, help="Prismatic joint values and the output position in millimetres.")
@click.option("--frame", default="tcp", show_default=True, help="Frame whose pose is printed.")
@json_option
def fk_cmd(robot: str, q: tuple[float, ...], deg: bool, mm: bool, frame: str, as_json: bool) -> None:
    """Forward kinematics: pose of FRAME for joint values Q... (one per independent joint)."""
    import pinocchio as pin

    arm = load_robot(robot)
    values = vectors_from_args(q)
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
        f"position [{lu}]: {fmt(pos)}",
        f"roll pitch yaw [{au}]: {fmt(ang)}",
        "T (frame → base, SI):",
        *("  " + "  ".join(f"{v: .6f}" for v in row) for row in T),
    ]
    if not limits_ok:
        lines.append("warning: q is outside the joint limits: " + "; ".join(arm.limit_violations(q_si)))
    emit(as_json, data, lines)


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


@cli.command("ik", context_settings=NUMBERS)
@click.argument("robot")
@click.argument("pose", nargs=-1, type=float, required=True)
@click.option("--all", "all_solutions", is_flag=True, help="Every analytic solution within the limits.")
@click.option("--deg", is_flag=True, help="ROLL PITCH YAW, revolute joints (and --limit-tol) in degrees.")
@click.option("--mm", is_flag=True, help="X Y Z, prismatic joints (and --limit-tol) in millimetres.")
@click.option("--seed-q", default=None, help="Comma-separated start configuration for the numerical solver.")
@click.option("--limit-tol", "limit_tol", default=None, type=click.FloatRange(min=0.0),
              help="Accept solutions up to this far outside a joint's range (deg with --deg, else rad; "
                   "mm with --mm, else m, for prismatic joints); never clamped.")
@json_option
def ik_cmd(robot: str, pose: tuple[float, ...], all_solutions: bool, deg: bool, mm: bool,
           seed_q: str | None, limit_tol: float | None, as_json: bool) -> None:
    """Inverse kinematics for the tcp at X Y Z [ROLL PITCH YAW] (base frame).

    With three numbers only the position is asked (orientation free for the numerical
    solver; with --all, or for the note below, the orientation is taken as the base's).
    With --all every closed-form solution within the joint limits is listed. Closed-form
    solutions that miss a joint range by less than 1° (1 mm) are named with how far they
    miss; --limit-tol accepts them (a solution within the limits is always preferred).
    """
    from pinarms.robots.errors import UnreachableTarget
    from pinarms.robots.ik import near_limit_solutions

    arm = load_robot(robot)
    values = vectors_from_args(pose)
    T = _target_pose(values, deg, mm)
    position_only = values.size == 3
    prismatic = prismatic_mask(arm)
    user = np.where(prismatic, length_scale(mm), angle_scale(deg))  # SI per user unit, per joint
    kinds = ["mm" if (p and mm) else "m" if p else ("deg" if deg else "rad") for p in prismatic]
    # --limit-tol in user units, per joint kind: one SI tolerance (the smaller of the two readings)
    tol_si = 0.0 if limit_tol is None else float(np.min(limit_tol * user))
    near = []
    if arm.has_analytic_ik:
        near = near_limit_solutions(arm, T, within=max(float(np.min(np.where(prismatic, 1e-3, np.radians(1.0)))),
                                                      2.0 * tol_si))
    if all_solutions:
        if not arm.has_analytic_ik:
            raise InvalidInput(f"{arm.name} has no closed-form IK; drop --all to use the numerical solver")
        sols = np.atleast_2d(arm.ik_all(T, limit_tolerance=tol_si))
        if sols.size == 0:
            sols = np.zeros((0, arm.nq))
    else:
        q0 = None
        if seed_q is not None:
            start = floats(seed_q, "--seed-q")
            if start.size != arm.nq:
                raise InvalidInput(
                    f"--seed-q needs {arm.nq} values for {arm.name} ({', '.join(arm.joint_names)}), got {start.size}"
                )
            q0 = joints_to_si(arm, start, deg=deg, mm=mm)
        accepted = [s.q for s in near if s.worst <= tol_si]
        try:
            sols = np.atleast_2d(arm.ik(T, q0, position_only=position_only, limit_tolerance=tol_si))
        except UnreachableTarget:
            if not accepted:
                raise InvalidInput(_unreachable(arm, T, values, position_only, near, user, kinds, mm)) from None
            sols = np.atleast_2d(accepted[0])
        if position_only and accepted:  # asked for: the closed form (orientation as the base's) within --limit-tol
            sols = np.atleast_2d(accepted[0])
    rows = []
    for q in sols:
        T_q = arm.fk(q)
        outside = _outside(arm, q, user)
        rows.append(
            {
                "q": joints_from_si(arm, q, deg=deg, mm=mm),
                "position_error_m": float(np.linalg.norm(T_q[:3, 3] - T[:3, 3])),
                "outside_limits": outside,
            }
        )
    lu, au = ("mm" if mm else "m"), ("deg" if deg else "rad")
    data = {
        "robot": arm.name,
        "target": {"position": values[:3], "rpy": values[3:] if values.size == 6 else None},
        "units": {"position": lu, "angles": au, "joints": kinds},
        "joint_names": list(arm.joint_names),
        "limit_tolerance": limit_tol,
        "solutions": rows,
        "near_limit_solutions": [
            {"q": joints_from_si(arm, s.q, deg=deg, mm=mm), "outside_limits": _outside(arm, s.q, user)} for s in near
        ],
    }
    header = "  ".join(f"{n}[{u}]" for n, u in zip(arm.joint_names, kinds))
    lines = [f"{arm.name}: {len(rows)} solution(s)  ({header})"]
    for r in rows:
        beyond = "".join(f"; {j} {abs(e):.4g} {kinds[arm.joint_names.index(j)]} outside its range"
                         for j, e in r["outside_limits"].items())
        lines.append(f"  {fmt(r['q'])}   |Δp| = {r['position_error_m']:.1e} m{beyond}")
    if not rows:  # only with --all: the numerical solver raises UnreachableTarget instead
        reason = arm.ik_failure_reason(T)
        data["reason"] = reason
        lines.append(f"  none within the joint limits: {reason}")
    taken = [r["q"] for r in rows]
    for s, d in zip(near, data["near_limit_solutions"]):
        if any(np.allclose(d["q"], q, atol=1e-9) for q in taken):
            continue
        misses = ", ".join(f"{j} by {abs(e):.4g} {kinds[arm.joint_names.index(j)]} "
                           f"({'above' if e > 0 else 'below'} {_limit_text(arm, j, e, user)})"
                           for j, e in d["outside_limits"].items())
        need = max(abs(e) for e in d["outside_limits"].values())
        lines.append(f"  note: the closed-form solution ({fmt(d['q'])}) lies outside the joint ranges: {misses}; "
                     f"--limit-tol {float(np.format_float_positional(need * 1.01, precision=2, fractional=False))} "
                     "accepts it")
    emit(as_json, data, lines)


def _outside(arm, q: np.ndarray, user: np.ndarray) -> dict[str, float]:
    """Joints of ``q`` outside their range → signed excess in user units (revolute angles wrapped to the range)."""
    from pinarms.robots.ik import limit_excess

    _, excess = limit_excess(arm, q)
    return {n: float(e / u) for n, e, u in zip(arm.joint_names, excess, user) if abs(e) > 1e-9}


def _limit_text(arm, joint: str, excess: float, user: np.ndarray) -> str:
    j = arm.joint_names.index(joint)
    limit = arm.upper[j] if excess > 0 else arm.lower[j]
    return f"{limit / user[j]:.6g}"


def _unreachable(arm, T: np.ndarray, values: np.ndarray, position_only: bool, near: list, user: np.ndarray,
                 kinds: list[str], mm: bool) -> str:
    """Why no configuration reaches the target, in the units the user typed."""
    from pinarms.robots.ik import NumericalIK

    unit = "mm" if mm else "m"
    where = f"({', '.join(f'{v:g}' for v in values[:3])}) {unit}"
    head = f"robot '{arm.name}': no configuration within the joint limits reaches {where}"
    free = NumericalIK(arm).solve(T, position_only=position_only, tol=1e-9, max_restarts=20, seed=0, limits=False)
    if free.success or near:
        q = near[0].q if near else free.q
        misses = "; ".join(f"{j} {abs(e):.4g} {kinds[arm.joint_names.index(j)]} "
                           f"{'above' if e > 0 else 'below'} its range end {_limit_text(arm, j, e, user)}"
                           for j, e in _outside(arm, q, user).items())
        small = all(abs(e) * u <= (1e-3 if k in ("mm", "m") else np.radians(1.0))
                    for e, u, k in ((e, user[arm.joint_names.index(j)], kinds[arm.joint_names.index(j)])
                                    for j, e in _outside(arm, q, user).items()))
        return f"{head}: it is within reach but needs {misses}" + (" (--limit-tol accepts that much)" if small else "")
    scale = 1e3 if mm else 1.0
    return (f"{head}: it is out of reach; the closest tcp position found is "
            f"{free.position_error * scale:.4g} {unit} away")


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
    from pinarms.robots.reach.workspace_stream import stream_workspace

    with common.progress_bar("workspace tasks", None, as_json) as bar:
        res = stream_workspace(arm, n, seed=seed, frame=frame,
                               voxel_size=None if voxel_mm is None else voxel_mm * 1e-3,
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


