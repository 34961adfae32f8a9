"""Where to bolt the arm: ``layout-search``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import click
import numpy as np

from pinarms.errors import InvalidInput

from pinarms.cli._common import (
    NUMBERS,
    cli,
    emit,
    load_robot,
    progress_bar,
    save_session,
    scheduler_option,
)
from pinarms.cli.option_groups import JSON_FLAG, Flag, OutputFlags, TimingFlags, UnitFlags, flag, option_group


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


@dataclass(frozen=True)
class PlacementAxes:
    """The base placements tried: x, y, z [user lengths] and yaw [rad, or ° with --deg] each ``V`` (fixed),
    ``LO:HI:STEP`` (a grid) or, with ``n_random``, ``LO:HI`` (bounds of seeded uniform draws)."""

    x_range: str = "0"
    y_range: str = "0"
    z_range: str = "0"
    yaw_range: str = "0"
    n_random: int | None = None
    deg: bool = False

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--x", "x_range", default="0", show_default=True, help="Base x: V, LO:HI:STEP (or LO:HI with --random)."),
        flag("--y", "y_range", default="0", show_default=True, help="Base y: V, LO:HI:STEP (or LO:HI with --random)."),
        flag("--z", "z_range", default="0", show_default=True, help="Base z: V, LO:HI:STEP (or LO:HI with --random)."),
        flag("--yaw", "yaw_range", default="0", show_default=True,
             help="Base yaw about the vertical [rad, or ° with --deg]: V, LO:HI:STEP (or LO:HI)."),
        flag("--random", "n_random", default=None, type=int,
             help="Draw this many placements uniformly within LO:HI bounds instead of a grid (seeded)."),
        flag("--deg", is_flag=True, help="Base yaw in degrees."),
    )

    def candidates(self, k: float, seed: int) -> np.ndarray:
        """The placements (x, y, z, yaw) in SI, lengths typed times ``k`` [m per unit]."""
        from pinarms import optim

        ky = np.pi / 180.0 if self.deg else 1.0
        random = self.n_random is not None
        axes = {name: _range(text, f"--{name}", scale, random)
                for name, text, scale in (("x", self.x_range, k), ("y", self.y_range, k), ("z", self.z_range, k),
                                          ("yaw", self.yaw_range, ky))}
        if random:
            return optim.random_candidates(self.n_random, seed=seed, **axes)
        return optim.grid_candidates(**axes)


@dataclass(frozen=True)
class LayoutTask:
    """The picks and places (line frame, user lengths; every pick pairs with every place), the lift
    (``None``: 0.05 m) and the gripper's dwell [s]."""

    pick: tuple[tuple[float, float, float], ...]
    place: tuple[tuple[float, float, float], ...]
    lift: float | None = None
    dwell: float = 0.2

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--pick", nargs=3, type=float, multiple=True, required=True,
             help="X Y Z of a pick point in the line frame (repeat for several)."),
        flag("--place", nargs=3, type=float, multiple=True, required=True,
             help="X Y Z of a place point in the line frame (repeat; every pick pairs with every place)."),
        flag("--lift", default=None, type=float, help="Vertical approach/retreat height [default 0.05 m, 50 mm]."),
        flag("--dwell", default=0.2, show_default=True, type=float, help="Gripper time at pick and at place [s]."),
    )


@dataclass(frozen=True)
class SearchFlags:
    """How the placements are ranked: refinement of the best, seed, chunking, edge margin and the bound."""

    refine: int = 2
    refine_evaluations: int = 30
    seed: int = 0
    chunk_size: int = 4
    min_margin: float = 0.0
    bound: bool = False

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--refine", default=2, show_default=True, type=int,
             help="Improve the best N placements continuously (Nelder-Mead over the varied coordinates)."),
        flag("--refine-evaluations", default=30, show_default=True, type=int, help="Cycles each refinement may plan."),
        flag("--seed", default=0, show_default=True, type=int, help="Seed of random placements, workspace and optimiser."),
        flag("--chunk-size", default=4, show_default=True, type=int, help="Placements per task."),
        flag("--min-margin", default=0.0, show_default=True, type=float,
             help="Rule out placements whose picks or places are closer than this to the workspace edge "
                  "[m, or mm with --mm]."),
        flag("--bound", is_flag=True,
             help="Plan placements in increasing order of a proven lower bound of their cycle time and skip those "
                  "that cannot reach the --refine best (reported 'outranked', without a cycle time): the same best "
                  "placement, fewer cycles planned."),
    )


@dataclass(frozen=True)
class InCellFlags:
    """A search inside a cell (``cell_name``): the clearance kept and the fixtures carried with the arm."""

    cell_name: str | None = None
    clearance: float = 0.02
    carry: tuple[str, ...] = ()

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--cell", "cell_name", default=None,
             help="Search inside a cell (built-in name or .xacro/.urdf file): ROBOT is then the arm's name in it, "
                  "the line frame is the cell's world and every cycle keeps --clearance from its fixtures."),
        flag("--clearance", default=0.02, show_default=True, type=float,
             help="With --cell: distance the cycle keeps from fixtures and other arms [m, or mm with --mm]."),
        flag("--carry", multiple=True, help="With --cell: a fixture that moves with the arm (its stand); repeat."),
    )

    def __post_init__(self) -> None:
        if self.carry and not self.cell_name:
            raise InvalidInput("--carry names fixtures of a cell: give --cell too")


@dataclass(frozen=True)
class LayoutOutput(OutputFlags):
    """The ranked table's rows (``top``) besides the plot, the session and JSON."""

    top: int = 10

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--top", default=10, show_default=True, type=int, help="Rows of the ranked table."),
        flag("--plot", "plot_path", default=None, type=click.Path(dir_okay=False),
             help="Write the picks/min map over the (x, y) placements (.png or .svg)."),
        flag("--session", "session_path", default=None, type=click.Path(dir_okay=False),
             help="Save the arm at the best placement, its cycle and the candidates into a session file."),
        JSON_FLAG,
    )


@cli.command("layout-search", context_settings=NUMBERS)
@click.argument("robot")
@option_group(LayoutTask, "task")
@option_group(PlacementAxes, "axes")
@option_group(UnitFlags, "units", only=("mm",), mm={"help": "Points, base positions and lift in millimetres."})
@option_group(TimingFlags, "timing", only=("kind", "vmax", "amax", "jmax"),
              vmax={"help": "Joint speed limit(s) [rad/s or m/s] (default: the URDF's)."})
@option_group(SearchFlags, "search")
@option_group(InCellFlags, "in_cell")
@option_group(LayoutOutput, "output")
@scheduler_option
def layout_search_cmd(robot: str, task: LayoutTask, axes: PlacementAxes, units: UnitFlags, timing: TimingFlags,
                      search: SearchFlags, in_cell: InCellFlags, output: LayoutOutput, scheduler: str | None) -> None:
    """Where to put ROBOT for the most picks per minute: rank base placements by their cycle.

    Every placement (x, y, z, yaw of the base in the line frame) is screened by IK (which
    point is out of reach or needs a joint outside its limits), then the time-optimal
    pick-and-place cycle of every (pick, place) pair is planned (optim.plan_cycle); the best
    placements are refined continuously. --scheduler runs the cycles on Dask.

    Example: pinarms layout-search aubo_i3 --pick 400 -300 50 --place 400 300 50 --mm
    --x -200:400:100 --y -300:300:100 --refine 1
    """
    from pinarms import optim

    k = units.length
    as_json = output.as_json
    cell_fields = {}
    if in_cell.cell_name:
        from pinarms.robots.cell import load_cell

        cell = load_cell(in_cell.cell_name)
        arm = cell.arm(robot).robot
        cell_fields = {"arm": robot, "clearance": in_cell.clearance * k, "carry": tuple(in_cell.carry)}
    else:
        cell, arm = None, load_robot(robot)
    candidates = axes.candidates(k, search.seed)
    picks, places = np.array(task.pick) * k, np.array(task.place) * k
    vmax, amax, jmax = timing.limits(np.ones(arm.nq))
    request = optim.LayoutRequest(
        cell if cell is not None else arm, picks, places, candidates,
        lift=0.05 if task.lift is None else task.lift * k, dwell=task.dwell, kind=timing.kind,
        vmax=vmax, amax=amax, jmax=jmax, refine=search.refine, refine_evaluations=search.refine_evaluations,
        seed=search.seed, chunk_size=search.chunk_size, min_margin=search.min_margin * k, bound=search.bound,
        **cell_fields,
    )
    with progress_bar(f"{arm.name}: placements", len(candidates), as_json) as bar:
        res = optim.search_layout(request, scheduler=scheduler, progress=bar if bar.enabled else None)
    data = res.as_dict()
    from pinarms.execution import describe_scheduler

    data["ran_on"] = describe_scheduler(scheduler)
    data["units"] = {"lengths": "m", "yaw": "rad", "times": "s"}
    lines = res.table(top=output.top).splitlines() + [f"ran on: {describe_scheduler(scheduler)}"]
    if output.plot_path:
        from pinarms import viz

        viz.plot_layout_search(output.plot_path, res)
        data["plot"] = output.plot_path
        lines.append(f"plot written: {output.plot_path}")
    if output.session_path:
        from pinarms import viz

        if res.status is optim.LayoutStatus.NO_PLACEMENT:
            raise InvalidInput("no placement runs the cycle: there is no best placement to save in a session")
        session = viz.layout_search_session(res, arm, cell=cell, carry=tuple(in_cell.carry))
        save_session(session, output.session_path, data, lines)
    emit(as_json, data, lines)
