"""Items on a moving belt: ``belt run`` (simulate a line), ``belt arms`` (fewest arms for a flow),
``belt size`` (arms, places and belt speed by the GA). Lines of the line study
(:mod:`pinarms.studies.line`): ``--preset scara`` (seed 000's SCARAs, enoki bunches) or
``--preset gantry`` (seed 002's gantry, flowers); or copies of the user's own arm,
``--robot URDF`` (:mod:`~.belt_robot`, :func:`pinarms.studies.arm_line.arm_line`), whose task
maps are built (a progress line on stderr while a step takes over 2 s)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

import click
import numpy as np

from pinarms.errors import InvalidInput

from pinarms.cli._common import cli, emit, json_option, progress_bar, scheduler_option
from pinarms.cli.belt_robot import BeltRobotFlags
from pinarms.cli.option_groups import Flag, flag, option_group

PRESETS = ("scara", "gantry")


@dataclass(frozen=True)
class BeltFlow:
    """The line simulated: the ``preset``'s arms, the flow (``rate`` items/min), the belt ``speed`` [m/s]
    (``None``: the preset's), seed 000's joint-1 limit (``paper_limit``), the assignment ``rule``, the Monte
    Carlo ``seeds`` and the simulated ``duration`` [s] per seed."""

    preset: str = "scara"
    rate: float = 60.0
    speed: float | None = None
    paper_limit: bool = False
    rule: str = "first"
    seeds: int = 5
    duration: float = 600.0

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--preset", type=click.Choice(PRESETS), default="scara", show_default=True,
             help="scara: seed 000's SCARAs and enoki bunches; gantry: seed 002's gantry and flowers."),
        flag("--rate", type=float, default=60.0, show_default=True, help="Items per minute (Poisson)."),
        flag("--speed", type=float, default=None, help="Belt speed [m/s] (default 0.2 scara, 0.3 gantry, 0.1 --robot)."),
        flag("--paper-limit", is_flag=True, help="Seed 000's 55 deg/s limit on the SCARA's joint 1."),
        flag("--rule", type=click.Choice(["first", "nearest", "shortest", "bands", "split", "lookahead"]),
             default="first", show_default=True, help="Assignment rule."),
        flag("--seeds", type=int, default=5, show_default=True, help="Seeds (Monte Carlo runs)."),
        flag("--duration", type=float, default=600.0, show_default=True, help="Simulated time per seed [s]."),
    )


@dataclass(frozen=True)
class BeltViews:
    """The views of a run: a session file, a standalone page, a schedule plot and the seconds animated."""

    session_path: str | None = None
    html_path: str | None = None
    plot_path: str | None = None
    window: float = 20.0

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--session", "session_path", type=click.Path(dir_okay=False), default=None,
             help="Also save the first seed's first --window seconds as a session (.pinarms; pinarms view)."),
        flag("--html", "html_path", type=click.Path(dir_okay=False), default=None,
             help="Also write that window as a standalone page (.html)."),
        flag("--plot", "plot_path", type=click.Path(dir_okay=False), default=None,
             help="Also plot who picked what when (.png or .svg; 3 x --window seconds)."),
        flag("--window", type=float, default=20.0, show_default=True, help="Seconds animated in --session/--html."),
    )


def _spec(flow: BeltFlow, arms: int, arrivals: str | None, robot: dict | None = None):
    preset, rate, speed, paper_limit = flow.preset, flow.rate, flow.speed, flow.paper_limit
    rule, seeds, duration = flow.rule, flow.seeds, flow.duration
    from pinarms.optim.line import Stream
    from pinarms.studies.line import gantry_line, scara_line

    from pinarms.optim.caps import count_setting
    from pinarms.optim.line.api import MAX_LINE_ARMS, MAX_LINE_SEEDS
    from pinarms.optim.line.items import MAX_ITEMS

    count_setting(seeds, "--seeds", 1, MAX_LINE_SEEDS)  # before any station or map is made
    count_setting(arms, "--arms", 1, MAX_LINE_ARMS)
    expected = rate / 60.0 * duration
    if not arrivals and not expected <= MAX_ITEMS:
        raise InvalidInput(f"--rate {rate:g} items/min over --duration {duration:g} s is {expected:.3g} items; a stream "
                           f"holds at most {MAX_ITEMS}: lower --rate or --duration")
    kw = {"seeds": tuple(range(seeds)), "duration": duration}
    if robot is not None and "delta" in robot:
        from pinarms.studies.delta_line import DeltaLineRequest, delta_line

        if paper_limit:
            raise InvalidInput("--paper-limit is seed 000's SCARA limit: drop it with --robot")
        from pinarms.studies.line import ENOKI

        spec = delta_line(DeltaLineRequest(arms, rate, item=ENOKI, name=robot["delta"], rule=rule, map_grid=robot["map_grid"],
                                           **kw, **({} if speed is None else {"speed": speed})))
    elif robot is not None:
        from pinarms.studies.arm_line import ArmLineRequest, arm_line

        if paper_limit:
            raise InvalidInput("--paper-limit is seed 000's SCARA limit: drop it with --robot")
        spec = arm_line(ArmLineRequest(robot["robot"], arms, rate, rule=rule, base_offset=robot["base_offset"],
                                       base_height=robot["base_height"], box=robot["box"], spacing=robot["spacing"],
                                       descend=robot["descend"], map_grid=robot["map_grid"], **kw,
                                       **({} if speed is None else {"speed": speed})))
    elif preset == "scara":
        spec = scara_line(arms, rate, rule=rule, paper_limit=paper_limit, **kw, **({} if speed is None else {"speed": speed}))
    else:
        if arms != 1:
            raise InvalidInput("the gantry preset has one arm: drop --arms")
        spec = gantry_line(rate, **kw, **({} if speed is None else {"speed": speed}))
        spec = replace(spec, rule=replace(spec.rule, name=rule))
    if arrivals:
        spec = replace(spec, stream=Stream("file", rate / 60.0, duration, path=arrivals, types=spec.stream.types), seeds=(0,))
    return spec


def _maps(spec, robot: dict | None, as_json: bool, scheduler=None) -> dict:
    """The line's task maps: the package's for a preset (:func:`pinarms.studies.line.maps_for`), built for
    ``--robot`` with a progress line (:func:`_progress`)."""
    from pinarms.optim.line.api import build_maps
    from pinarms.studies.line import maps_for

    if robot is None:
        return maps_for(spec)
    if "delta" in robot:
        from pinarms.optim.line.errors import BeltOutOfReach
        from pinarms.studies.delta_line import delta_maps

        with _progress(as_json) as step:
            try:
                return delta_maps(spec, progress=lambda done, total: step(done, total, f"task map of {robot['delta']}"))
            except BeltOutOfReach as exc:
                raise InvalidInput(f"--speed: {' '.join(str(exc).split())}") from None
    from pinarms.optim.line.errors import BeltOutOfReach
    from pinarms.errors import UnreachableTarget

    with _progress(as_json) as step:
        try:
            maps = build_maps(spec, scheduler=scheduler, progress=step)
        except BeltOutOfReach as exc:
            raise InvalidInput(f"--base-offset: {' '.join(str(exc).split())}") from None
        except UnreachableTarget as exc:
            raise InvalidInput(f"--box: {' '.join(str(exc).split())} (--box DX,DY,DZ from the arm's base)") from None
    for name, ms in maps.items():
        m = ms[0]
        du, w = 0.5 * (m.du[1:] + m.du[:-1]), 0.5 * (m.w[1:] + m.w[:-1])
        if not np.isfinite(m.times(du[:, None], w[None, :])[0]).any():
            raise InvalidInput(f"--robot: {name} picks nowhere on the belt (no cell of its {m.du.size} x {m.w.size} map "
                               "is feasible at all four nodes): bring it closer (--base-offset), lengthen --descend, "
                               "slow the belt (--speed) or refine the map (--map-grid)")
    return maps


class _progress:
    """A ``progress(done, total, note)`` for the line's long calls: one progress line on stderr, drawn
    once a step has taken over 2 s (:class:`pinarms.progress.ProgressBar` ``after``)."""

    def __init__(self, as_json: bool) -> None:
        self.as_json, self.bar, self.note = as_json, None, None

    def __call__(self, done: int, total: int | None = None, note: str = "") -> None:
        if note != self.note:
            if self.bar is not None:
                self.bar.close()
            self.bar, self.note = progress_bar(note, total, self.as_json), note
            self.bar.after = 2.0
        self.bar(done, total)

    def __enter__(self) -> "_progress":
        return self

    def __exit__(self, *exc) -> None:
        if self.bar is not None:
            self.bar.close()


@cli.group("belt")
def belt() -> None:
    """Items on a moving belt: several arms picking on the fly (docs/line.md)."""


@belt.command("run")
@option_group(BeltFlow, "flow")
@option_group(BeltRobotFlags, "arm")
@click.option("--arms", type=int, default=3, show_default=True, help="Arms along the belt.")
@click.option("--arrivals", type=click.Path(exists=True, dir_okay=False), default=None,
              help="CSV arrivals file (time,across,type[,yaw]) instead of the Poisson stream.")
@option_group(BeltViews, "views")
@click.option("--trays", default=None, help="Place in trays on a second belt through the boxes: PITCH,SPEED,SLOTS "
              "(m, m/s, items per tray; tray maps built, minutes).")
@click.option("--map-error", "map_error_n", type=int, default=0, show_default=True, metavar="N",
              help="--robot: also measure the first arm's task map against exact planning at N seeded random "
                   "picks at random item yaw (mean, p95, max; goal p95 <= 1 %); 0: not measured.")
@scheduler_option
@json_option
def belt_run(flow: BeltFlow, arm: BeltRobotFlags, arms: int, arrivals: str | None, views: BeltViews,
             trays: str | None, map_error_n: int, scheduler: str | None, as_json: bool) -> None:
    """Simulate a line and print picks/min, miss rate, utilisation (a preset's arms, or --robot URDF)."""
    from pinarms.optim.line import run_line
    from pinarms.studies.line import maps_for

    from pinarms.optim.caps import count_setting

    count_setting(map_error_n, "--map-error", 0, MAX_MAP_ERROR_PICKS)
    robot = arm.resolve()
    if map_error_n and (robot is None or "delta" in robot):
        raise InvalidInput("--map-error measures the task map of --robot URDF: give --robot, or drop --map-error")
    session_path, html_path, plot_path = views.session_path, views.html_path, views.plot_path
    spec = _spec(flow, arms, arrivals, robot)
    if trays and robot is not None:
        raise InvalidInput("--trays with --robot: the tray line takes a preset's arms only; drop --trays")
    if trays:
        from pinarms.optim.line.trays import parse_trays, trays_beside

        if session_path or html_path or plot_path:
            raise InvalidInput("--trays with --session, --html or --plot: the views do not show trays yet; drop them")
        tb = trays_beside(spec.belt, spec.stations[0].place.position, *parse_trays(trays))
        spec = replace(spec, trays=tb)
    if trays:  # the tray maps take the approach times from the box maps (finer, refined)
        from pinarms.optim.line.api import build_maps

        maps = build_maps(spec, scheduler=scheduler, approach_maps=maps_for(spec))
    else:
        maps = _maps(spec, robot, as_json, scheduler)
    with _progress(as_json) as step:
        res = run_line(spec, maps=maps, scheduler=scheduler, progress=step)
    if session_path or html_path or plot_path:
        from pinarms.viz.line_views import save_line_views

        save_line_views(spec, res, session=session_path, html=html_path, schedule=plot_path, duration=views.window)
    what = flow.preset if robot is None else f"{robot['delta'] if 'delta' in robot else robot['robot'].name} (--robot)"
    data, lines = res.as_dict(), res.summary(f"belt run: {what}, {arms} arm(s), rule {flow.rule}").splitlines()
    if map_error_n:
        data["map_error"], more = _map_error(spec, maps, map_error_n, as_json)
        lines += more
    emit(as_json, data, lines)


#: Largest ``--map-error N`` (each pick is planned exactly: about a second each on a 6-axis arm).
MAX_MAP_ERROR_PICKS = 1000


def _map_error(spec, maps: dict, n: int, as_json: bool) -> tuple[dict, list[str]]:
    """The first station's map (first item type) against exact planning at ``n`` seeded random picks at random
    yaw (:func:`pinarms.optim.line.map_error`): ``(JSON figures, text lines)``."""
    from pinarms.optim.line import map_error
    from pinarms.optim.line.task_map_error import MAP_ERROR_TARGET

    st, item = spec.stations[0], spec.stream.types[0]
    m = maps[st.name][0]
    with _progress(as_json) as step:
        step(0, None, f"map error: {n} exact picks")
        err = map_error(m, st, spec.belt, spec.tracking, n=n, item_height=item.size[2], seed=0)
    verdict = "met" if err.p95 <= MAP_ERROR_TARGET else "NOT met"
    yaw = "with a yaw coordinate" if m.yaw is not None else "without a yaw coordinate"
    data = {"points": int(err.relative.size), "mean": err.mean, "p95": err.p95, "max": err.max,
            "target_p95": MAP_ERROR_TARGET, "seconds": err.planning_seconds, "yaw_axis": m.yaw is not None,
            "by_yaw": [dict(zip(("low_rad", "high_rad", "points", "mean", "p95", "max"), row)) for row in err.by_yaw()]}
    lines = [f"  map error        {err.relative.size} exact picks at random yaw (seed 0), map {m.du.size} x {m.w.size} "
             f"{yaw}: mean {100 * err.mean:.2f} %, p95 {100 * err.p95:.2f} %, max {100 * err.max:.2f} % "
             f"(goal p95 <= {100 * MAP_ERROR_TARGET:g} %: {verdict}; {err.planning_seconds:.1f} s)",
             *err.table().splitlines()]
    return data, lines


@belt.command("arms")
@option_group(BeltFlow, "flow")
@option_group(BeltRobotFlags, "arm")
@click.option("--max-arms", type=int, default=20, show_default=True)
@json_option
def belt_arms(flow: BeltFlow, arm: BeltRobotFlags, max_arms: int, as_json: bool) -> None:
    """Fewest SCARAs (preset scara), or arms of --robot URDF, whose miss rate is <= 1 % at the flow."""
    from pinarms.optim.line import LineStatus, run_line

    robot = arm.resolve()
    if flow.preset != "scara" and robot is None:
        raise InvalidInput("belt arms adds SCARAs along the belt: use --preset scara (or --robot URDF)")
    from pinarms.optim.caps import count_setting
    from pinarms.optim.line.api import MAX_LINE_ARMS

    count_setting(max_arms, "--max-arms", 1, MAX_LINE_ARMS)
    one = None  # --robot: the first arm's maps, shared by every arm (same shape, shifted along the belt)
    for n in range(1, max_arms + 1):
        spec = _spec(flow, n, None, robot)
        if robot is None:
            maps = _maps(spec, None, as_json)
        else:
            one = one or _maps(spec, robot, as_json)[spec.stations[0].name]
            maps = {st.name: one for st in spec.stations}
        res = run_line(spec, maps=maps)
        if res.status is LineStatus.OK:
            break
    data = {"arms_needed": n if res.status is LineStatus.OK else None, **res.as_dict()}
    lines = res.summary(f"belt arms: {flow.rate:g} items/min at <= 1 % miss -> "
                        f"{n if res.status is LineStatus.OK else f'more than {max_arms}'} arm(s)").splitlines()
    emit(as_json, data, lines)


@belt.command("size")
@option_group(BeltFlow, "flow")
@option_group(BeltRobotFlags, "arm")
@click.option("--max-miss", type=float, default=0.01, show_default=True, help="Miss rate asked for (fraction).")
@click.option("--generations", type=int, default=6, show_default=True)
@click.option("--population", type=int, default=10, show_default=True)
@scheduler_option
@json_option
def belt_size(flow: BeltFlow, arm: BeltRobotFlags, max_miss: float, generations: int, population: int,
              scheduler: str | None, as_json: bool) -> None:
    """Fewest SCARAs (or arms of --robot URDF), their places along the belt and the belt speed (the project's GA)."""
    from pinarms.optim.line import Rule
    from pinarms.optim.line.sizing import SizingProblem, size_line
    from pinarms.studies.line import ENOKI

    from pinarms.optim.caps import MAX_GENERATIONS, MAX_POPULATION, count_setting

    count_setting(population, "--population", 4, MAX_POPULATION)  # the GA's range, named by the flag, before
    count_setting(generations, "--generations", 1, MAX_GENERATIONS)  # any map is built
    robot = arm.resolve()
    preset, rate, speed, rule, seeds, duration = flow.preset, flow.rate, flow.speed, flow.rule, flow.seeds, flow.duration
    if preset != "scara" and robot is None:
        raise InvalidInput("belt size places SCARAs along the belt: use --preset scara (or --robot URDF)")
    speeds = [0.2 if robot is None or "delta" in robot else 0.1] if speed is None else [speed]
    maps, item, extra = {}, ENOKI, {}
    for v in speeds:
        spec = _spec(replace(flow, speed=v, seeds=1), 1, None, robot)
        maps[v] = _maps(spec, robot, as_json, scheduler)[spec.stations[0].name][0]
    if robot is not None:
        st = spec.stations[0]
        u0, rest = spec.belt.to_belt(st.base_to_world[:3, 3]), spec.belt.to_belt(st.place.position)
        item = spec.stream.types[0]
        from pinarms.studies.delta_line import DELTA_SPACING

        gap = DELTA_SPACING if "delta" in robot else robot["spacing"]
        extra = {"rest": (float(rest[0] - u0[0]), float(rest[1])), "first_u": float(u0[0]),
                 "min_gap": gap, "max_gap": 1.5 * gap}
    problem = SizingProblem(maps, rate, max_miss, item=item, rule=Rule(rule), seeds=tuple(range(seeds)),
                            duration=duration, population=population, generations=generations, **extra)
    r = size_line(problem, scheduler=scheduler, progress=None if as_json else click.echo)
    lines = [f"belt size: {rate:g} items/min at <= {100 * max_miss:g} % miss",
             f"  status            {r.status}",
             f"  arms              {r.arms}",
             "  places along belt " + "  ".join(f"{u:.3f}" for u in r.positions) + " m",
             f"  belt speed        {r.speed:.3f} m/s",
             f"  miss rate         {100 * r.miss_rate:.2f} %",
             f"  picks             {r.picks_per_minute:.1f} /min",
             f"  simulations       {r.evaluations}"]
    if r.status_reason:
        lines.insert(2, f"  why               {r.status_reason}")
    emit(as_json, {**r.__dict__, "status": r.status.value}, lines)
