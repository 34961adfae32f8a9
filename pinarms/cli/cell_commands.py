"""Cells of several arms and fixtures: ``cell show``, ``cell check``, ``cell cycle``."""

from __future__ import annotations

import sys
import time
from collections import Counter
from typing import TYPE_CHECKING, Any

import click
import numpy as np

from pinarms.errors import InvalidInput

from pinarms.cli._common import (NUMBERS, PinarmsGroup, cli, emit, floats, json_option, package_map, save_session, show_progress,
                      skipped_pair_lines)
from pinarms.cli.motion_commands import hold_option

if TYPE_CHECKING:
    from pinarms.robots.cell import Cell

_ARG_HELP = "A xacro:arg value of CELL (repeatable), e.g. --arg belt_top=0.85."
_PKG_HELP = "A folder for $(find NAME) and package://NAME/ in CELL (repeatable)."


def load_cell_option(cell: str, args: tuple[str, ...], packages: tuple[str, ...]) -> Cell:
    """The cell of a ``CELL`` argument with its ``--xacro-arg`` and ``--package`` options (InvalidInput for a file that
    is not UTF-8 text)."""
    from pinarms.robots.cell import load_cell
    from pinarms.robots.xacro_expand import parse_xacro_args

    pkgs = package_map(packages)
    try:
        return load_cell(cell, packages=pkgs or None, xacro_args=parse_xacro_args(args))
    except UnicodeDecodeError as exc:
        raise InvalidInput(f"cell file {cell!r} is not UTF-8 text (byte {exc.start}: {exc.reason}): save it as "
                           "UTF-8") from None


def _shape_text(shape: Any, k: float, lu: str) -> str:
    if shape.kind == "mesh":
        return f"mesh {shape.mesh} (scale {' x '.join(f'{v:g}' for v in shape.size)})"
    return f"{shape.kind} {' x '.join(f'{v * k:.4g}' for v in shape.size)} {lu}"


def _arm_keys_text(cell: Any, arm: Any) -> list[str]:
    """An arm's tool point, frozen joints, hold pose and named states, one line each (docs/cells.md)."""
    placement = next((p for p in cell.arm_placements if p.name == arm.name), None)
    held = placement.hold if placement is not None else None
    why = f"state {held}" if isinstance(held, str) else ("neutral" if held is None else "given")
    out = [f"    tcp: {arm.tcp_choice}"]
    if arm.frozen:
        out.append("    frozen: " + ", ".join(f"{j} = {v:g}" for j, v in arm.frozen.items()))
    out.append(f"    hold: ({', '.join(f'{v:.4g}' for v in arm.hold)}) rad/m ({why})")
    if arm.states:
        out.append("    states: " + ", ".join(arm.states))
    return out


def _cell_options(fn):
    fn = click.option("--package", "packages", multiple=True, metavar="NAME=FOLDER", help=_PKG_HELP)(fn)
    fn = click.option("--arg", "xacro_args", multiple=True, metavar="NAME=VALUE", help=_ARG_HELP)(fn)
    return click.argument("cell")(fn)


@cli.group("cell", cls=PinarmsGroup)
def cell_group() -> None:
    """Cells: several arms at their bases and fixtures, checked for collisions (docs/cells.md).

    CELL is a built-in cell (mushroom_line, aubo_food_station) or a .xacro/.urdf file; a
    xacro file is expanded behind a wall (its own folder and the --package folders only).
    """


# --------------------------------------------------------------------------- show
@cell_group.command("show")
@_cell_options
@click.option("--mm", is_flag=True, help="Lengths in millimetres.")
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Save the cell into a session file (pinarms view opens it).")
@click.option("--html", "html_path", default=None, type=click.Path(dir_okay=False),
              help="Write the cell as a standalone HTML page.")
@json_option
def cell_show_cmd(cell, xacro_args, packages, mm, session_path, html_path, as_json) -> None:
    """The arms, fixtures and collision pairs of CELL."""
    c = load_cell_option(cell, xacro_args, packages)
    k, lu = (1000.0, "mm") if mm else (1.0, "m")
    arms = [{"name": a.name, "model": a.model, "prefix": a.prefix, "joints": list(a.robot.joint_names),
             "q_slice": [a.q_slice.start, a.q_slice.stop], "base_to_world": a.base_to_world,
             "tcp_frame": a.robot.tcp_frame, "tcp": a.tcp_choice, "frozen": dict(a.frozen),
             "hold": [float(v) for v in a.hold], "states": {n: [float(v) for v in q] for n, q in a.states.items()},
             "delta": next((d.delta.name for d in c.deltas if d.name == a.name), None)}
            for a in c.arms]
    fixtures = [{"name": f.name, "shapes": [{"kind": s.kind, "size": list(s.size), "mesh": s.mesh,
                                             "position_m": s.shape_to_world[:3, 3]} for s in f.shapes]}
                for f in c.fixtures]
    kinds = Counter(p.kind for p in c.pairs + c.delta_pairs)
    allowed = c.allowed + c.delta_allowed
    reasons = Counter(a.reason for a in allowed)
    delta_of = {d.name: d.delta.name for d in c.deltas}
    data = {"cell": c.name, "source": c.source, "args": c.args, "nq": c.nq, "joint_names": list(c.joint_names),
            "arms": arms, "fixtures": fixtures, "pairs_checked": dict(kinds), "pairs_allowed": dict(reasons),
            "allowed": [{"bodies": [a.body_a, a.body_b], "geometries": [a.geometry_a, a.geometry_b],
                         "reason": str(a.reason), "distance_bound_m": a.distance_bound, "note": a.note}
                        for a in allowed]}
    args_text = "; args " + ", ".join(f"{a}={v}" for a, v in c.args.items()) if c.args else ""
    lines = [f"cell {c.name} ({c.source}){args_text}", f"{len(c.arms)} arm(s), {c.nq} joints in the cell vector:"]
    for a in c.arms:
        p = a.base_to_world[:3, 3] * k
        kind = f"delta {delta_of[a.name]} (bodies from the closed form)" if a.name in delta_of else a.model or "arm"
        lines.append(f"  {a.name}: {kind}, joints {a.q_slice.start}-{a.q_slice.stop - 1} "
                     f"({', '.join(a.robot.joint_names)}), base at ({p[0]:.4g}, {p[1]:.4g}, {p[2]:.4g}) {lu}")
        lines += _arm_keys_text(c, a)
    lines.append(f"{len(c.fixtures)} fixture(s):")
    for f in c.fixtures:
        lines.append(f"  {f.name}: {', '.join(_shape_text(s, k, lu) for s in f.shapes)}")
    lines.append("pairs checked: " + ", ".join(f"{n} {kind}" for kind, n in sorted(kinds.items())))
    lines.append("pairs allowed: " + ", ".join(f"{n} {r}" for r, n in sorted(reasons.items())))
    lines.extend(skipped_pair_lines(allowed, k, lu))
    if session_path or html_path:
        from pinarms import viz

        session = viz.Session(title=f"cell {c.name}")
        session.add_cell(c)
        if session_path:
            save_session(session, session_path, data, lines)
        if html_path:
            viz.export_html(session, html_path)
            data["html"] = html_path
            lines.append(f"page written: {html_path}")
    emit(as_json, data, lines)


# --------------------------------------------------------------------------- check
@cell_group.command("check", context_settings=NUMBERS)
@_cell_options
@click.option("--q", "q_values", multiple=True, help="A cell joint vector, comma-separated [rad or m] (repeatable).")
@click.option("--random", "n_random", default=0, type=int, help="Also check N random configurations (seeded).")
@click.option("--seed", default=0, show_default=True, type=int)
@click.option("--margin", default=0.0, show_default=True, type=float, help="Pairs closer than this touch [m].")
@json_option
def cell_check_cmd(cell, xacro_args, packages, q_values, n_random, seed, margin, as_json) -> None:
    """Collisions and clearance of CELL at given (--q) or random (--random N) configurations."""
    c = load_cell_option(cell, xacro_args, packages)
    if not q_values and n_random <= 0:
        raise click.UsageError("give configurations with --q or a count with --random N")
    data: dict[str, Any] = {"cell": c.name, "joint_names": list(c.joint_names), "margin_m": margin}
    lines: list[str] = []
    if q_values:
        Q = np.array([floats(v, "--q") for v in q_values])
        if Q.shape[1] != c.nq:
            raise InvalidInput(f"--q needs {c.nq} values ({', '.join(c.joint_names)}), got {Q.shape[1]}")
        hits = c.collisions(Q, margin=margin)
        cl = c.clearance(Q)
        rows = []
        for i in range(Q.shape[0]):
            pair = cl.pair_of(i)
            rows.append({"q": Q[i], "colliding": bool(hits.colliding[i]), "touching": hits.bodies_at(i),
                         "clearance_m": float(cl.distance[i]), "closest": [pair.body_a, pair.body_b]})
            state = "TOUCHES " + "; ".join(f"{a} – {b}" for a, b in hits.bodies_at(i)) if hits.colliding[i] else "free"
            lines.append(f"q{i + 1}: {state}; clearance {cl.distance[i] * 1e3:.1f} mm ({pair})")
        data["configurations"] = rows
    if n_random > 0:
        Q = c.random_q(n_random, seed=seed)
        out = np.empty(n_random, dtype=bool)
        chunk = 2000
        t0 = time.perf_counter()
        bar = click.progressbar(length=n_random, label="checking", file=sys.stderr) if show_progress(as_json) else None
        if bar is not None:
            bar.__enter__()
        try:
            for s in range(0, n_random, chunk):
                out[s:s + chunk] = c.in_collision(Q[s:s + chunk], margin=margin)
                if bar is not None:
                    bar.update(min(chunk, n_random - s))
        finally:
            if bar is not None:
                bar.__exit__(None, None, None)
        seconds = time.perf_counter() - t0
        sample = np.flatnonzero(out)[:500]
        counts = Counter(p for i in range(sample.size)  # a pair of links once per configuration, however many shapes
                         for p in dict.fromkeys(c.collisions(Q[sample[i]], margin=margin).bodies_at()))
        top = counts.most_common(5)
        data["random"] = {"n": n_random, "seed": seed, "colliding": int(out.sum()), "share": float(out.mean()),
                          "configurations_per_s": n_random / seconds,
                          "most_frequent": [{"bodies": list(p), "count": n} for p, n in top]}
        lines.append(f"{n_random} random configurations (seed {seed}): {out.sum()} in collision ({out.mean():.1%}), "
                     f"{n_random / seconds:,.0f} configurations/s")
        for p, n in top:
            lines.append(f"  {p[0]} – {p[1]}: {n} of the first {sample.size} colliding")
    emit(as_json, data, lines)


# --------------------------------------------------------------------------- cycle
def _closest_arms(check: Any, k: float, lu: str) -> str:
    """Where two arms come closest (a check of the arm–arm pairs): the true distance, its pair and time, the proof."""
    pair = check.min_clearance_pair
    where = "" if pair is None else f"{pair.body_a} ↔ {pair.body_b} "
    return (f"the arms come closest at {check.min_clearance / k:.4g} {lu} ({where}at t = {check.min_clearance_time:.3f} s;"
            f" proven never closer than {check.lower_bound / k:.4g} {lu})")


@cell_group.command("cycle", context_settings=NUMBERS)
@_cell_options
@click.option("--task", "tasks", nargs=7, multiple=True, required=True, metavar="ARM PX PY PZ QX QY QZ",
              help="An arm's pick P and place Q (world frame); repeat for each arm.")
@click.option("--lift", default=None, type=float, help="Starting lift [default 0.05 m, 50 mm].")
@click.option("--dwell", default=0.2, show_default=True, type=float, help="Gripper time at pick and place [s].")
@click.option("--clearance", default=None, type=float,
              help="Distance kept from fixtures and other arms [default 0.02 m, 20 mm].")
@click.option("--margin", default=None, type=float,
              help="Resolution of the continuous checks [default 0.005 m, 5 mm].")
@click.option("--hold", "holds", multiple=True, metavar="ARM=Q1,Q2,...|ARM=STATE",
              help="Where an arm without a --task stays (repeatable): joint values (rad and m; m as mm with --mm) or a "
                   "named state of the cell description (default: the description's hold, else neutral).")
@click.option("--offsets", "n_offsets", default=24, show_default=True, type=int,
              help="Time offsets scanned per arm (two or more arms).")
@click.option("--mm", is_flag=True, help="Points, lift, clearance and margin in millimetres.")
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Save the cell with all arms' cycles (animated together) into a session file.")
@click.option("--plot-clearance", "plot_clearance", default=None, type=click.Path(dir_okay=False),
              help="Plot the clearance over time (.png or .svg).")
@click.option("--plot-schedule", "plot_schedule", default=None, type=click.Path(dir_okay=False),
              help="Plot the arms' busy intervals in the shared zone (.png or .svg; two or more arms).")
@json_option
def cell_cycle_cmd(cell, xacro_args, packages, tasks, lift, dwell, clearance, margin, holds, n_offsets, mm, session_path,
                   plot_clearance, plot_schedule, as_json) -> None:
    """Collision-aware pick-and-place cycles of CELL's arms and, for two or more arms, their schedule.

    Each arm's cycle keeps --clearance from the fixtures and the other arms (re-planned
    with a higher lift or via points until it does); two or more arms are given time
    offsets so that they never collide (every offset checked continuously).

    Example: pinarms cell cycle mushroom_line --task left -50 -30 840 220 680 840
    --task right 50 30 840 220 -680 840 --mm
    """
    from pinarms import optim
    from pinarms.optim import caps
    from pinarms.optim.cycle import CellSettings, CycleRequest
    from pinarms.robots.cell import ArmMotion

    k = 1e-3 if mm else 1.0
    lu = "mm" if mm else "m"
    lift = 0.05 / k if lift is None else lift  # all lengths in the user's unit until multiplied by k
    clearance = 0.02 / k if clearance is None else clearance
    margin = 0.005 / k if margin is None else margin
    # the settings first: a slip in them is an error at once, before the cell loads or a cycle is planned
    if len(tasks) >= 2:
        caps.count_setting(n_offsets, "--offsets", 2, caps.MAX_OFFSETS)
    caps.number_setting(dwell, "--dwell", 0.0, caps.MAX_DWELL, unit="s")
    caps.number_setting(clearance * k, "--clearance", 0.0, caps.MAX_CLEARANCE, unit="m")
    caps.number_setting(margin * k, "--margin", caps.MIN_MARGIN, unit="m")
    caps.number_setting(lift * k, "--lift", 0.0, open_low=True, unit="m")
    c = load_cell_option(cell, xacro_args, packages)
    hold = hold_option(c, holds, tuple(t[0] for t in tasks), False, mm, "it has a --task")
    cycles = {}
    data: dict[str, Any] = {"cell": c.name, "clearance_m": clearance * k, "arms": {}}
    lines: list[str] = [f"cell {c.name}: cycles keeping {clearance:g} {lu} from fixtures and other arms"]
    for task in tasks:
        name = task[0]
        arm = c.arm(name)
        try:
            values = np.array([float(v) for v in task[1:]]) * k
        except ValueError:
            raise click.BadParameter(f"--task {name}: the six coordinates must be numbers, got {task[1:]}") from None
        spec = optim.PickPlace(arm.to_base(values[:3]), arm.to_base(values[3:]), lift=lift * k, dwell=dwell)
        res = optim.plan_cycle(CycleRequest(arm.robot, spec, cell=CellSettings(c, clearance=clearance * k,
                                                                               margin=margin * k, hold=hold)))
        cycles[name] = res
        rep = res.cell_report
        data["arms"][name] = {"cycle": res.as_dict(), "cycle_time_s": res.cycle_time,
                              "picks_per_minute": res.picks_per_minute}
        vias = f", {len(rep.via)} via point(s)" if rep.via else ""
        lines.append(f"  {name}: cycle {res.cycle_time:.3f} s ({res.picks_per_minute:.2f} picks/min), lift "
                     f"{rep.lift / k:.4g} {lu}{vias}; +{rep.extra_time:.3f} s against {rep.cycle_time_without_cell:.3f} s "
                     f"without the cell; closest {rep.min_clearance / k:.4g} {lu} ({rep.min_clearance_pair})")
    motions = [ArmMotion(n, r.trajectory) for n, r in cycles.items()]
    check = None
    if len(cycles) >= 2:
        total = max(1, n_offsets * (len(cycles) - 1))
        bar = click.progressbar(length=total, label="scanning offsets", file=sys.stderr) if show_progress(as_json) else None
        if bar is not None:
            bar.__enter__()
        try:
            progress = (lambda done, _total: bar.update(1)) if bar is not None else None
            schedule = optim.schedule_line(c, cycles, margin=max(margin * k, 0.005), n_offsets=n_offsets,
                                           progress=progress, hold=hold)
        finally:
            if bar is not None:
                bar.__exit__(None, None, None)
        data["schedule"] = schedule.as_dict()
        lines.append(f"line: period {schedule.period:.3f} s, offsets "
                     + ", ".join(f"{n} {v:.3f} s" for n, v in schedule.offsets.items())
                     + f"; {schedule.picks_per_minute:.2f} picks/min against "
                     + ", ".join(f"{v:.2f}" for v in schedule.single_arm_picks_per_minute.values())
                     + " for one arm alone")
        lines.append(f"  {int(schedule.clear.sum())} of {schedule.clear.size} offsets clear; "
                     + _closest_arms(schedule.arm_check, k, lu))
        motions = [ArmMotion(n, cycles[n].trajectory, schedule.offsets[n], schedule.period) for n in schedule.arms]
        check = schedule.arm_check
        if plot_schedule:
            from pinarms.viz import plots

            plots.plot_schedule(plot_schedule, schedule)
            data["schedule_plot"] = plot_schedule
            lines.append(f"schedule plot written: {plot_schedule}")
    elif plot_schedule:
        raise click.UsageError("--plot-schedule needs two or more --task")
    if plot_clearance:
        from pinarms.viz import plots

        if check is None:
            check = c.with_pairs("external").check_motion(motions, margin=margin * k, clearance=clearance * k, curve=True,
                                                          hold=hold)
        plots.plot_clearance(plot_clearance, check)
        data["clearance_plot"] = plot_clearance
        lines.append(f"clearance plot written: {plot_clearance}")
    if session_path:
        from pinarms import viz

        session = viz.Session(title=f"cell {c.name}: cycles")
        session.add_cell(c, motions=motions, name="cycles", hold=hold)
        save_session(session, session_path, data, lines)
    emit(as_json, data, lines)
