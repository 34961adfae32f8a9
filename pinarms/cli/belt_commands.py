"""Items on a moving belt: ``belt run`` (simulate a line), ``belt arms`` (fewest arms for a flow),
``belt size`` (arms, places and belt speed by the GA). Lines of the line study
(:mod:`pinarms.studies.line`): ``--preset scara`` (seed 000's SCARAs, enoki bunches) or
``--preset gantry`` (seed 002's gantry, flowers); or copies of the user's own arm,
``--robot URDF`` (:mod:`~.belt_robot`, :func:`pinarms.studies.arm_line.arm_line`), whose task
maps are built (a progress line on stderr while a step takes over 2 s)."""

from __future__ import annotations

from dataclasses import replace

import click
import numpy as np

from pinarms.errors import InvalidInput

from pinarms.cli._common import cli, emit, json_option, progress_bar, scheduler_option
from pinarms.cli.belt_robot import box_value, grid_value, load_belt_robot, robot_options

PRESETS = ("scara", "gantry")


def _spec(preset: str, arms: int, rate: float, speed: float | None, paper_limit: bool, rule: str, seeds: int,
          duration: float, arrivals: str | None, robot: dict | None = None):
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
        from pinarms.studies.delta_line import delta_line

        if paper_limit:
            raise InvalidInput("--paper-limit is seed 000's SCARA limit: drop it with --robot")
        from pinarms.studies.line import ENOKI

        spec = delta_line(arms, rate, item=ENOKI, name=robot["delta"], rule=rule, map_grid=robot["map_grid"], **kw, **({} if speed is None else {"speed": speed}))
    elif robot is not None:
        from pinarms.studies.arm_line import arm_line

        if paper_limit:
            raise InvalidInput("--paper-limit is seed 000's SCARA limit: drop it with --robot")
        spec = arm_line(robot["robot"], arms, rate, rule=rule, base_offset=robot["base_offset"],
                        base_height=robot["base_height"], box=robot["box"], spacing=robot["spacing"], descend=robot["descend"], map_grid=robot["map_grid"], **kw,
                        **({} if speed is None else {"speed": speed}))
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


common = [
    click.option("--preset", type=click.Choice(PRESETS), default="scara", show_default=True,
                 help="scara: seed 000's SCARAs and enoki bunches; gantry: seed 002's gantry and flowers."),
    click.option("--rate", type=float, default=60.0, show_default=True, help="Items per minute (Poisson)."),
    click.option("--speed", type=float, default=None,
                 help="Belt speed [m/s] (default 0.2 scara, 0.3 gantry, 0.1 --robot)."),
    click.option("--paper-limit", is_flag=True, help="Seed 000's 55 deg/s limit on the SCARA's joint 1."),
    click.option("--rule", type=click.Choice(["first", "nearest", "shortest", "bands", "split", "lookahead"]),
                 default="first", show_default=True, help="Assignment rule."),
    click.option("--seeds", type=int, default=5, show_default=True, help="Seeds (Monte Carlo runs)."),
    click.option("--duration", type=float, default=600.0, show_default=True, help="Simulated time per seed [s]."),
    *robot_options,
]


def _robot(kw: dict) -> dict | None:
    """The ``--robot`` options (:mod:`~.belt_robot`) popped from a command's ``kw``: None without ``--robot``."""
    keys = ("robot_urdf", "packages", "tcp", "tcp_offset", "tool_axis", "base_offset", "base_height", "box", "spacing",
            "descend", "map_grid")
    opts = {k: kw.pop(k) for k in keys}
    if opts["robot_urdf"] is None:
        given = [f"--{k.replace('_', '-')}" for k in ("packages", "tcp", "tcp_offset") if opts[k]]
        if given or opts["tool_axis"] != "z":
            flag = (given or ["--tool-axis"])[0].replace("--packages", "--package")
            raise InvalidInput(f"{flag} describes the arm of --robot URDF: give --robot, or drop {flag}")
        return None
    from pinarms.robots.delta import delta_names

    if opts["robot_urdf"] in delta_names():  # a shipped delta, above the belt (pinarms.studies.delta_line)
        given = [f"--{k.replace('_', '-')}" for k in ("packages", "tcp", "tcp_offset") if opts[k]]
        if given or opts["tool_axis"] != "z":
            flag = (given or ["--tool-axis"])[0].replace("--packages", "--package")
            raise InvalidInput(f"{flag} describes a URDF arm; --robot {opts['robot_urdf']} is a shipped delta: drop {flag}")
        return {"delta": opts["robot_urdf"], "map_grid": grid_value(opts["map_grid"])}
    robot = load_belt_robot(opts["robot_urdf"], opts["packages"], opts["tcp"], opts["tcp_offset"], opts["tool_axis"])
    return {"robot": robot, "base_offset": opts["base_offset"], "base_height": opts["base_height"],
            "box": box_value(opts["box"]), "spacing": opts["spacing"], "descend": opts["descend"],
            "map_grid": grid_value(opts["map_grid"])}


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


def _with(options):
    def wrap(f):
        for o in reversed(options):
            f = o(f)
        return f
    return wrap


@cli.group("belt")
def belt() -> None:
    """Items on a moving belt: several arms picking on the fly (docs/line.md)."""


@belt.command("run")
@_with(common)
@click.option("--arms", type=int, default=3, show_default=True, help="Arms along the belt.")
@click.option("--arrivals", type=click.Path(exists=True, dir_okay=False), default=None,
              help="CSV arrivals file (time,across,type[,yaw]) instead of the Poisson stream.")
@click.option("--session", "session_path", type=click.Path(dir_okay=False), default=None,
              help="Also save the first seed's first --window seconds as a session (.pinarms; pinarms view).")
@click.option("--html", "html_path", type=click.Path(dir_okay=False), default=None,
              help="Also write that window as a standalone page (.html).")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False), default=None,
              help="Also plot who picked what when (.png or .svg; 3 x --window seconds).")
@click.option("--window", type=float, default=20.0, show_default=True, help="Seconds animated in --session/--html.")
@click.option("--trays", default=None, help="Place in trays on a second belt through the boxes: PITCH,SPEED,SLOTS "
              "(m, m/s, items per tray; tray maps built, minutes).")
@scheduler_option
@json_option
def belt_run(preset, rate, speed, paper_limit, rule, seeds, duration, arms, arrivals, session_path, html_path,
             plot_path, window, trays, scheduler, as_json, **kw) -> None:
    """Simulate a line and print picks/min, miss rate, utilisation (a preset's arms, or --robot URDF)."""
    from pinarms.optim.line import run_line
    from pinarms.studies.line import maps_for

    robot = _robot(kw)
    spec = _spec(preset, arms, rate, speed, paper_limit, rule, seeds, duration, arrivals, robot)
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

        save_line_views(spec, res, session=session_path, html=html_path, schedule=plot_path, duration=window)
    what = preset if robot is None else f"{robot['delta'] if 'delta' in robot else robot['robot'].name} (--robot)"
    emit(as_json, res.as_dict(), res.summary(f"belt run: {what}, {arms} arm(s), rule {rule}").splitlines())


@belt.command("arms")
@_with(common)
@click.option("--max-arms", type=int, default=20, show_default=True)
@json_option
def belt_arms(preset, rate, speed, paper_limit, rule, seeds, duration, max_arms, as_json, **kw) -> None:
    """Fewest SCARAs (preset scara), or arms of --robot URDF, whose miss rate is <= 1 % at the flow."""
    from pinarms.optim.line import LineStatus, run_line

    robot = _robot(kw)
    if preset != "scara" and robot is None:
        raise InvalidInput("belt arms adds SCARAs along the belt: use --preset scara (or --robot URDF)")
    from pinarms.optim.caps import count_setting
    from pinarms.optim.line.api import MAX_LINE_ARMS

    count_setting(max_arms, "--max-arms", 1, MAX_LINE_ARMS)
    one = None  # --robot: the first arm's maps, shared by every arm (same shape, shifted along the belt)
    for n in range(1, max_arms + 1):
        spec = _spec(preset, n, rate, speed, paper_limit, rule, seeds, duration, None, robot)
        if robot is None:
            maps = _maps(spec, None, as_json)
        else:
            one = one or _maps(spec, robot, as_json)[spec.stations[0].name]
            maps = {st.name: one for st in spec.stations}
        res = run_line(spec, maps=maps)
        if res.status is LineStatus.OK:
            break
    data = {"arms_needed": n if res.status is LineStatus.OK else None, **res.as_dict()}
    lines = res.summary(f"belt arms: {rate:g} items/min at <= 1 % miss -> "
                        f"{n if res.status is LineStatus.OK else f'more than {max_arms}'} arm(s)").splitlines()
    emit(as_json, data, lines)


@belt.command("size")
@_with(common)
@click.option("--max-miss", type=float, default=0.01, show_default=True, help="Miss rate asked for (fraction).")
@click.option("--generations", type=int, default=6, show_default=True)
@click.option("--population", type=int, default=10, show_default=True)
@scheduler_option
@json_option
def belt_size(preset, rate, speed, paper_limit, rule, seeds, duration, max_miss, generations, population, scheduler,
              as_json, **kw) -> None:
    """Fewest SCARAs (or arms of --robot URDF), their places along the belt and the belt speed (the project's GA)."""
    from pinarms.optim.line import Rule
    from pinarms.optim.line.sizing import SizingProblem, size_line
    from pinarms.studies.line import ENOKI

    robot = _robot(kw)
    if preset != "scara" and robot is None:
        raise InvalidInput("belt size places SCARAs along the belt: use --preset scara (or --robot URDF)")
    speeds = [0.2 if robot is None or "delta" in robot else 0.1] if speed is None else [speed]
    maps, item, extra = {}, ENOKI, {}
    for v in speeds:
        spec = _spec(preset, 1, rate, v, paper_limit, rule, 1, duration, None, robot)
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
