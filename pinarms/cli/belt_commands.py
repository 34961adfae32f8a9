"""Items on a moving belt: ``belt run`` (simulate a line), ``belt arms`` (fewest arms for a flow),
``belt size`` (arms, places and belt speed by the GA). Lines of the line study
(:mod:`pinarms.studies.line`): ``--preset scara`` (seed 000's SCARAs, enoki bunches) or
``--preset gantry`` (seed 002's gantry, flowers)."""

from __future__ import annotations

from dataclasses import replace

import click

from pinarms.errors import InvalidInput

from pinarms.cli._common import cli, emit, json_option, scheduler_option

PRESETS = ("scara", "gantry")


def _spec(preset: str, arms: int, rate: float, speed: float | None, paper_limit: bool, rule: str, seeds: int,
          duration: float, arrivals: str | None):
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
    if preset == "scara":
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
    click.option("--speed", type=float, default=None, help="Belt speed [m/s] (default 0.2 scara, 0.3 gantry)."),
    click.option("--paper-limit", is_flag=True, help="Seed 000's 55 deg/s limit on the SCARA's joint 1."),
    click.option("--rule", type=click.Choice(["first", "nearest", "shortest", "bands", "split", "lookahead"]),
                 default="first", show_default=True, help="Assignment rule."),
    click.option("--seeds", type=int, default=5, show_default=True, help="Seeds (Monte Carlo runs)."),
    click.option("--duration", type=float, default=600.0, show_default=True, help="Simulated time per seed [s]."),
]


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
             plot_path, window, trays, scheduler, as_json) -> None:
    """Simulate a line and print picks/min, miss rate, utilisation."""
    from pinarms.optim.line import run_line
    from pinarms.studies.line import maps_for

    spec = _spec(preset, arms, rate, speed, paper_limit, rule, seeds, duration, arrivals)
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
        maps = maps_for(spec)
    res = run_line(spec, maps=maps, scheduler=scheduler)
    if session_path or html_path or plot_path:
        from pinarms.viz.line_views import save_line_views

        save_line_views(spec, res, session=session_path, html=html_path, schedule=plot_path, duration=window)
    emit(as_json, res.as_dict(), res.summary(f"belt run: {preset}, {arms} arm(s), rule {rule}").splitlines())


@belt.command("arms")
@_with(common)
@click.option("--max-arms", type=int, default=20, show_default=True)
@json_option
def belt_arms(preset, rate, speed, paper_limit, rule, seeds, duration, max_arms, as_json) -> None:
    """Fewest SCARAs (preset scara) whose miss rate is <= 1 % at the flow."""
    from pinarms.optim.line import run_line
    from pinarms.studies.line import maps_for

    if preset != "scara":
        raise InvalidInput("belt arms adds SCARAs along the belt: use --preset scara")
    from pinarms.optim.caps import count_setting
    from pinarms.optim.line.api import MAX_LINE_ARMS

    count_setting(max_arms, "--max-arms", 1, MAX_LINE_ARMS)
    for n in range(1, max_arms + 1):
        spec = _spec(preset, n, rate, speed, paper_limit, rule, seeds, duration, None)
        res = run_line(spec, maps=maps_for(spec))
        if res.status == "ok":
            break
    data = {"arms_needed": n if res.status == "ok" else None, **res.as_dict()}
    lines = res.summary(f"belt arms: {rate:g} items/min at <= 1 % miss -> "
                        f"{n if res.status == 'ok' else f'more than {max_arms}'} arm(s)").splitlines()
    emit(as_json, data, lines)


@belt.command("size")
@_with(common)
@click.option("--max-miss", type=float, default=0.01, show_default=True, help="Miss rate asked for (fraction).")
@click.option("--generations", type=int, default=6, show_default=True)
@click.option("--population", type=int, default=10, show_default=True)
@scheduler_option
@json_option
def belt_size(preset, rate, speed, paper_limit, rule, seeds, duration, max_miss, generations, population, scheduler,
              as_json) -> None:
    """Fewest SCARAs, their places along the belt and the belt speed (the project's GA)."""
    from pinarms.optim.line import Rule
    from pinarms.optim.line.sizing import SizingProblem, size_line
    from pinarms.studies.line import ENOKI, maps_for

    if preset != "scara":
        raise InvalidInput("belt size places SCARAs along the belt: use --preset scara")
    speeds = [0.2] if speed is None else [speed]
    maps = {v: maps_for(_spec(preset, 1, rate, v, paper_limit, rule, 1, duration, None))["scara 1"][0] for v in speeds}
    problem = SizingProblem(maps, rate, max_miss, item=ENOKI, rule=Rule(rule), seeds=tuple(range(seeds)),
                            duration=duration)
    r = size_line(problem, population=population, generations=generations, scheduler=scheduler,
                  progress=None if as_json else click.echo)
    lines = [f"belt size: {rate:g} items/min at <= {100 * max_miss:g} % miss",
             f"  status            {r.status}",
             f"  arms              {r.arms}",
             "  places along belt " + "  ".join(f"{u:.3f}" for u in r.positions) + " m",
             f"  belt speed        {r.speed:.3f} m/s",
             f"  miss rate         {100 * r.miss_rate:.2f} %",
             f"  picks             {r.picks_per_minute:.1f} /min",
             f"  simulations       {r.evaluations}"]
    emit(as_json, r.__dict__, lines)
