"""Commands about one robot's kinematics: ``robots``, ``pairs``, ``fk``, ``ik`` (where it reaches: :mod:`.workspace_commands`)."""

from __future__ import annotations

import click
import numpy as np

from pinarms import robots
from pinarms.errors import InvalidInput
from pinarms.units import (
    angle_scale,
    joints_from_si,
    joints_to_si,
    length_scale,
    prismatic_mask,
)

from pinarms.cli._common import (
    NUMBERS,
    cli,
    emit,
    floats,
    fmt,
    json_option,
    load_robot,
    skipped_pair_lines,
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


# --------------------------------------------------------------------------- pairs
@cli.command("pairs")
@click.argument("robot")
@json_option
def pairs_cmd(robot: str, as_json: bool) -> None:
    """The self-collision pairs of ROBOT (a name or a .urdf file): how many are checked, and why each other
    pair of links is skipped (same link, rigid, adjacent, coaxial, declared in the URDF)."""
    from collections import Counter

    arm = load_robot(robot)
    sc = robots.SelfCollision(arm)
    reasons = Counter(str(a.reason) for a in sc.allowed)
    data = {"robot": arm.name, "geometries": sc.n_geometries, "pairs_checked": sc.n_pairs,
            "checked": [list(p) for p in sc.pairs.tolist()], "pairs_allowed": dict(reasons),
            "allowed": [{"bodies": [a.body_a, a.body_b], "geometries": [a.geometry_a, a.geometry_b],
                         "reason": str(a.reason), "note": a.note} for a in sc.allowed]}
    lines = [f"robot {arm.name}: {sc.n_geometries} collision geometries",
             f"pairs checked: {sc.n_pairs}",
             "pairs allowed: " + ", ".join(f"{n} {r}" for r, n in sorted(reasons.items()))]
    lines.extend(skipped_pair_lines(sc.allowed, 1.0, "m"))
    emit(as_json, data, lines)


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
    from pinarms.errors import UnreachableTarget
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
    rows = _solution_rows(arm, sols, T, user, deg, mm)
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
    lines += _near_limit_notes(arm, rows, data["near_limit_solutions"], kinds, user)
    emit(as_json, data, lines)


def _solution_rows(arm, sols: np.ndarray, T: np.ndarray, user: np.ndarray, deg: bool, mm: bool) -> list[dict]:
    """One row per solution: ``q`` in the user's units, its tcp position error [m], the joints outside their range."""
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
    return rows


def _near_limit_notes(arm, rows: list[dict], near: list[dict], kinds: list[str], user: np.ndarray) -> list[str]:
    """A note per closed-form solution just outside the joint ranges (and not listed): which joints miss, by how
    much, and the --limit-tol that accepts it."""
    lines = []
    taken = [r["q"] for r in rows]
    for d in near:
        if any(np.allclose(d["q"], q, atol=1e-9) for q in taken):
            continue
        misses = ", ".join(f"{j} by {abs(e):.4g} {kinds[arm.joint_names.index(j)]} "
                           f"({'above' if e > 0 else 'below'} {_limit_text(arm, j, e, user)})"
                           for j, e in d["outside_limits"].items())
        need = max(abs(e) for e in d["outside_limits"].values())
        lines.append(f"  note: the closed-form solution ({fmt(d['q'])}) lies outside the joint ranges: {misses}; "
                     f"--limit-tol {float(np.format_float_positional(need * 1.01, precision=2, fractional=False))} "
                     "accepts it")
    return lines


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
