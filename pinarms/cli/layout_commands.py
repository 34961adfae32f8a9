"""Where to bolt the arm: ``layout-search``."""

from __future__ import annotations

import click
import numpy as np

from pinarms.errors import InvalidInput

from pinarms.cli._common import (
    NUMBERS,
    cli,
    emit,
    json_option,
    load_robot,
    progress_bar,
    save_session,
    scheduler_option,
    si_limit,
)


def _range(text: str, what: str, scale: float, random: bool):
    """``"V"`` (fixed), ``"LO:HI:STEP"`` (grid) or ``"LO:HI"`` (random bounds), scaled to SI."""
    parts = text.split(":")
    try:
        values = [float(p) * scale for p in parts]
    except ValueError:
        raise click.BadParameter(f"{what} must be V, LO:HI:STEP or LO:HI (numbers), got {text!r}") from None
    if len(values) == 1:
        return values[0]
    if random and len(values) == 2:
        return tuple(values)
    if not random and len(values) == 3:
        return tuple(values)
    form = "LO:HI (with --random)" if random else "LO:HI:STEP"
    raise click.BadParameter(f"{what} must be one value V or {form}, got {text!r}")


@cli.command("layout-search", context_settings=NUMBERS)
@click.argument("robot")
@click.option("--pick", nargs=3, type=float, multiple=True, required=True,
              help="X Y Z of a pick point in the line frame (repeat for several).")
@click.option("--place", nargs=3, type=float, multiple=True, required=True,
              help="X Y Z of a place point in the line frame (repeat; every pick pairs with every place).")
@click.option("--x", "x_range", default="0", show_default=True, help="Base x: V, LO:HI:STEP (or LO:HI with --random).")
@click.option("--y", "y_range", default="0", show_default=True, help="Base y: V, LO:HI:STEP (or LO:HI with --random).")
@click.option("--z", "z_range", default="0", show_default=True, help="Base z: V, LO:HI:STEP (or LO:HI with --random).")
@click.option("--yaw", "yaw_range", default="0", show_default=True,
              help="Base yaw about the vertical [rad, or ° with --deg]: V, LO:HI:STEP (or LO:HI).")
@click.option("--random", "n_random", default=None, type=int,
              help="Draw this many placements uniformly within LO:HI bounds instead of a grid (seeded).")
@click.option("--mm", is_flag=True, help="Points, base positions and lift in millimetres.")
@click.option("--deg", is_flag=True, help="Base yaw in degrees.")
@click.option("--lift", default=None, type=float, help="Vertical approach/retreat height [default 0.05 m, 50 mm].")
@click.option("--dwell", default=0.2, show_default=True, type=float, help="Gripper time at pick and at place [s].")
@click.option("--kind", type=click.Choice(["multi-quintic", "quintic-bspline", "3-5-3"]), default="multi-quintic",
              show_default=True)
@click.option("--vmax", default=None, help="Joint speed limit(s) [rad/s or m/s] (default: the URDF's).")
@click.option("--amax", default=None, help="Acceleration limit(s) [rad/s² or m/s²].")
@click.option("--jmax", default=None, help="Jerk limit(s) [rad/s³ or m/s³].")
@click.option("--refine", default=2, show_default=True, type=int,
              help="Improve the best N placements continuously (Nelder-Mead over the varied coordinates).")
@click.option("--refine-evaluations", default=30, show_default=True, type=int,
              help="Cycles each refinement may plan.")
@click.option("--seed", default=0, show_default=True, type=int, help="Seed of random placements, workspace and optimiser.")
@click.option("--chunk-size", default=4, show_default=True, type=int, help="Placements per task.")
@click.option("--top", default=10, show_default=True, type=int, help="Rows of the ranked table.")
@click.option("--min-margin", default=0.0, show_default=True, type=float,
              help="Rule out placements whose picks or places are closer than this to the workspace edge "
                   "[m, or mm with --mm].")
@click.option("--cell", "cell_name", default=None,
              help="Search inside a cell (built-in name or .xacro/.urdf file): ROBOT is then the arm's name in it, "
                   "the line frame is the cell's world and every cycle keeps --clearance from its fixtures.")
@click.option("--clearance", default=0.02, show_default=True, type=float,
              help="With --cell: distance the cycle keeps from fixtures and other arms [m, or mm with --mm].")
@click.option("--carry", multiple=True, help="With --cell: a fixture that moves with the arm (its stand); repeat.")
@click.option("--bound", is_flag=True,
              help="Plan placements in increasing order of a proven lower bound of their cycle time and skip those "
                   "that cannot reach the --refine best (reported 'outranked', without a cycle time): the same best "
                   "placement, fewer cycles planned.")
@click.option("--plot", "plot_path", default=None, type=click.Path(dir_okay=False),
              help="Write the picks/min map over the (x, y) placements (.png or .svg).")
@click.option("--session", "session_path", default=None, type=click.Path(dir_okay=False),
              help="Save the arm at the best placement, its cycle and the candidates into a session file.")
@scheduler_option
@json_option
def layout_search_cmd(robot, pick, place, x_range, y_range, z_range, yaw_range, n_random, mm, deg, lift, dwell, kind,
                      vmax, amax, jmax, refine, refine_evaluations, seed, chunk_size, top, min_margin, cell_name, clearance, carry,
                      bound, plot_path, session_path, scheduler, as_json) -> None:
    """Where to put ROBOT for the most picks per minute: rank base placements by their cycle.

    Every placement (x, y, z, yaw of the base in the line frame) is screened by IK (which
    point is out of reach or needs a joint outside its limits), then the time-optimal
    pick-and-place cycle of every (pick, place) pair is planned (optim.plan_cycle); the best
    placements are refined continuously. --scheduler runs the cycles on Dask.

    Example: pinarms layout-search aubo_i3 --pick 400 -300 50 --place 400 300 50 --mm
    --x -200:400:100 --y -300:300:100 --refine 1
    """
    from pinarms import optim

    k = 1e-3 if mm else 1.0
    in_cell = {}
    if cell_name:
        from pinarms.robots.cell import load_cell

        cell = load_cell(cell_name)
        arm = cell.arm(robot).robot
        in_cell = {"arm": robot, "clearance": clearance * k, "carry": tuple(carry)}
    else:
        if carry:
            raise InvalidInput("--carry names fixtures of a cell: give --cell too")
        cell, arm = None, load_robot(robot)
    ky = np.pi / 180.0 if deg else 1.0
    random = n_random is not None
    axes = {name: _range(text, f"--{name}", scale, random)
            for name, text, scale in (("x", x_range, k), ("y", y_range, k), ("z", z_range, k), ("yaw", yaw_range, ky))}
    if random:
        candidates = optim.random_candidates(n_random, seed=seed, **axes)
    else:
        candidates = optim.grid_candidates(**axes)
    picks, places = np.array(pick) * k, np.array(place) * k
    ones = np.ones(arm.nq)
    request = optim.LayoutRequest(
        cell if cell is not None else arm, picks, places, candidates,
        lift=0.05 if lift is None else lift * k, dwell=dwell, kind=kind,
        vmax=si_limit(vmax, "--vmax", ones), amax=si_limit(amax, "--amax", ones),
        jmax=si_limit(jmax, "--jmax", ones), refine=refine, refine_evaluations=refine_evaluations, seed=seed,
        chunk_size=chunk_size, min_margin=min_margin * k, bound=bound, **in_cell,
    )
    with progress_bar(f"{arm.name}: placements", len(candidates), as_json) as bar:
        res = optim.search_layout(request, scheduler=scheduler, progress=bar if bar.enabled else None)
    data = res.as_dict()
    from pinarms.execution import describe_scheduler

    data["ran_on"] = describe_scheduler(scheduler)
    data["units"] = {"lengths": "m", "yaw": "rad", "times": "s"}
    lines = res.table(top=top).splitlines() + [f"ran on: {describe_scheduler(scheduler)}"]
    if plot_path:
        from pinarms import viz

        viz.plot_layout_search(plot_path, res)
        data["plot"] = plot_path
        lines.append(f"plot written: {plot_path}")
    if session_path:
        from pinarms import viz

        if res.status is optim.LayoutStatus.NO_PLACEMENT:
            raise InvalidInput("no placement runs the cycle: there is no best placement to save in a session")
        save_session(viz.layout_search_session(res, arm, cell=cell, carry=tuple(carry)), session_path, data, lines)
    emit(as_json, data, lines)
