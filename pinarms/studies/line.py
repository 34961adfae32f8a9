"""The line study: enoki bunches on seed 000's belt, flowers on seed 002's gantry.

- **Seed 000.** Enoki bunches (0.15 kg, 0.12 × 0.06 × 0.04 m) arrive at random (Poisson) on a
  0.3 m belt at 0.2 m/s; SCARAs of seed 000 stand on one side, 0.9 m apart (their windows do
  not overlap), each with its box beside it. How many arms for a given flow at ≤ 1 % miss
  (mean over seeds) — with the paper's 55 °/s limit on joint 1 and with the model's own limits.
- **Seed 002.** The flower gantry straddles a belt (0.3 m/s) and packs into a box beside it;
  the paper reports about 60 grasps per minute on hardware. The study gives the gantry's
  picks per minute on a belt at 60 flowers/min (regular and random) and the largest flow it
  takes at ≤ 1 % miss.

Task-time maps are built once and kept as package data (``data/*.npz``, named by a digest
of everything they depend on); :func:`maps_for` rebuilds a missing one, and the study checks
each against exact planning at a few random picks.
"""

from __future__ import annotations

import hashlib
from dataclasses import replace
from pathlib import Path
from typing import Any, Callable

import numpy as np

from pinarms import robots
from pinarms.optim.line import (Belt, ItemType, LineSpec, MapRequest, PlaceBox, Rule, Station, Stream, TaskMap,
                                TrackingSpec, base_pose, build_task_map, map_error, run_line)
from pinarms.optim.line.api import build_maps, station_shape_key
from pinarms.optim.line.tracking import PLAN_VERSION

__all__ = ["ENOKI", "FLOWER", "PAPER_J1_DEG_S", "scara_line", "gantry_line", "maps_for", "arms_needed",
           "max_flow", "DATA"]

ENOKI = ItemType("enoki bunch", 0.15, (0.12, 0.06, 0.04))
FLOWER = ItemType("flower", 0.05, (0.25, 0.08, 0.05))
#: Seed 000's joint-1 speed limit [°/s] (the paper's GA constraint).
PAPER_J1_DEG_S = 55.0
#: Where the study's task maps are kept.
DATA = Path(__file__).with_name("data")
SCARA_SPACING = 0.9


def scara_line(n_arms: int, rate: float, *, speed: float = 0.2, paper_limit: bool = False, rule: str = "first",
               seeds: tuple[int, ...] = (0, 1, 2, 3, 4), duration: float = 600.0) -> LineSpec:
    """Seed 000's line: ``n_arms`` SCARAs on one side of the belt, ``rate`` bunches/min (module doc)."""
    robot = robots.load("scara_mushroom")
    vmax = np.array(robot.velocity_limit, dtype=float)
    if paper_limit:
        vmax[0] = np.radians(PAPER_J1_DEG_S)
    stations = tuple(
        Station(f"scara {k + 1}", robot, base_pose(0.6 + SCARA_SPACING * k, 0.30, 0.78),
                PlaceBox((0.6 + SCARA_SPACING * k - 0.2, 0.45, 0.93), f"box {k + 1}"),
                vmax=vmax, amax=10.0 * np.array(robot.velocity_limit))
        for k in range(n_arms))
    belt = Belt((0.0, 0.0, 0.80), speed=speed, width=0.3, length=0.6 + SCARA_SPACING * n_arms + 0.5)
    return LineSpec(belt, stations, Stream("poisson", rate / 60.0, duration, types=(ENOKI,)), TrackingSpec(), Rule(rule),
                    seeds, 0.01, (24, 7))


def gantry_line(rate: float, *, kind: str = "poisson", speed: float = 0.3, seeds: tuple[int, ...] = (0, 1, 2, 3, 4),
                duration: float = 600.0) -> LineSpec:
    """Seed 002's gantry over a belt along its x axis, its box beside the belt (module doc)."""
    robot = robots.load("gantry_flower")
    belt = Belt((-0.5, 0.2, 0.70), speed=speed, width=0.3, length=2.5)
    station = Station("gantry", robot, base_pose(0.0, 0.0, 0.65), PlaceBox((0.6, 0.5, 0.90), "box"))
    return LineSpec(belt, (station,), Stream(kind, rate / 60.0, duration, types=(FLOWER,)), TrackingSpec(), Rule("first"),
                    seeds, 0.01, (24, 5))


def _digest(spec: LineSpec, station: Station, kind: ItemType) -> str:
    key = (station_shape_key(station, spec.belt), spec.belt.speed, kind.mass, kind.size, spec.tracking, spec.map_grid,
           spec.belt.width, PLAN_VERSION)
    return hashlib.sha256(repr(key).encode()).hexdigest()[:16]


def maps_for(spec: LineSpec, *, build: bool = True, save: bool = False, progress: Callable[[str], None] | None = None) -> dict:
    """Task maps of every station of ``spec`` from :data:`DATA` (built when missing and ``build``).
    A spec with a cell gets maps built against the cell's fixtures (:func:`pinarms.optim.line.build_maps`;
    not stored: they hold for that cell only)."""
    if spec.cell is not None:
        if not build:
            raise FileNotFoundError("maps against a cell's fixtures are built, never stored: pass build=True")
        return build_maps(spec)
    out, cache = {}, {}
    for st in spec.stations:
        maps = []
        for kind in spec.stream.types:
            name = f"{st.robot.name}_{_digest(spec, st, kind)}.npz"
            if name not in cache:
                path = DATA / name
                if path.exists():
                    cache[name] = TaskMap.load(path)
                elif build:
                    if progress:
                        progress(f"building the task map {name}")
                    one = len(spec.stream.types) == 1  # refined grids differ between types
                    rq = MapRequest(st, spec.belt, spec.tracking, mass=kind.mass, item_height=kind.size[2],
                                    nu=spec.map_grid[0], nw=spec.map_grid[1], refine=2 if one else 0)
                    cache[name] = build_task_map(rq).task_map
                    if save:
                        DATA.mkdir(exist_ok=True)
                        cache[name].save(path)
                else:
                    raise FileNotFoundError(path)
            maps.append(cache[name])
        out[st.name] = tuple(maps)
    return out


def arms_needed(rate: float, *, paper_limit: bool, max_arms: int = 20, start: int = 1,
                **kw: Any) -> tuple[int | None, Any]:
    """Fewest SCARAs (from ``start`` up) whose mean miss rate is ≤ 1 % at ``rate`` bunches/min
    (and that line's result)."""
    n, last, _ = _arms_history(rate, paper_limit=paper_limit, max_arms=max_arms, start=start, **kw)
    return n, last


def _arms_history(rate: float, *, paper_limit: bool, max_arms: int = 20, start: int = 1,
                  **kw: Any) -> tuple[int | None, Any, Any]:
    """:func:`arms_needed` and the curve (:class:`pinarms.optim.line.LineCurve`) of the lines tried."""
    from pinarms.optim.line import LineCurve, LineStatus

    last, tried = None, []
    found = None
    for n in range(max(1, start), max_arms + 1):
        spec = scara_line(n, rate, paper_limit=paper_limit, **kw)
        last = run_line(spec, maps=maps_for(spec))
        f = last.figures
        tried.append((n, f.picks_per_minute, f.miss_rate, *f.miss_rate_ci, f.arrivals_per_minute))
        if last.status is LineStatus.OK:
            found = n
            break
    a = np.array(tried, dtype=float)
    return found, last, LineCurve("arms", a[:, 0], *a[:, 1:].T)


def max_flow(make_spec: Callable[[float], LineSpec], lo: float, hi: float, *, target: float = 0.01, steps: int = 8) -> float:
    """Largest flow [items/min] in [lo, hi] with mean miss rate ≤ ``target`` (bisection)."""
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        spec = make_spec(mid)
        r = run_line(spec, maps=maps_for(spec))
        lo, hi = (mid, hi) if r.figures.miss_rate <= target else (lo, mid)
    return lo


def study(rate: float = 60.0, *, seeds: tuple[int, ...] = (0, 1, 2, 3, 4), duration: float = 600.0,
          check_points: int = 2) -> dict[str, Any]:
    """The study's figures (module doc), with each map's error against exact planning."""
    out: dict[str, Any] = {"rate_per_min": rate}
    objects: dict[str, Any] = {}
    for label, paper in (("model limits", False), ("paper 55 deg/s joint 1", True)):
        one = scara_line(1, rate, paper_limit=paper, seeds=seeds, duration=duration)
        m = maps_for(one)["scara 1"][0]
        err = map_error(m, one.stations[0], one.belt, one.tracking, n=check_points, item_height=ENOKI.size[2])
        single = run_line(replace(one, stream=Stream("regular", 2.0, 120.0, types=(ENOKI,)), seeds=(0,)),
                          maps={"scara 1": (m,)})
        # no fewer arms than the flow over one saturated arm's rate
        start = max(1, int(np.ceil(rate / single.figures.picks_per_minute)) - 1)
        n, res, curve = _arms_history(rate, paper_limit=paper, seeds=seeds, duration=duration, start=start)
        objects[label] = (res, curve)
        f = res.figures
        out[label] = {"arms": n, "picks_per_min": f.picks_per_minute, "miss_rate": f.miss_rate,
                      "miss_rate_ci": f.miss_rate_ci, "utilisation": f.utilisation, "belt_speed_m_s": res.belt_speed,
                      "one_arm_saturated_picks_per_min": single.figures.picks_per_minute,
                      "map_error_max": err.max}
    g_spec = gantry_line(60.0, kind="regular", seeds=(0,), duration=duration)
    gm = maps_for(g_spec)
    g_reg = run_line(g_spec, maps=gm)
    g_poi = run_line(gantry_line(60.0, seeds=seeds, duration=duration), maps=gm)
    g_sat = run_line(gantry_line(240.0, kind="regular", seeds=(0,), duration=120.0), maps=gm)
    err = map_error(gm["gantry"][0], g_spec.stations[0], g_spec.belt, g_spec.tracking, n=check_points,
                    item_height=FLOWER.size[2])
    out["gantry"] = {"regular_60": g_reg.figures.as_dict(), "poisson_60": g_poi.figures.as_dict(),
                     "saturated_picks_per_min": g_sat.figures.picks_per_minute,
                     "max_flow_1pct_regular": max_flow(lambda r: gantry_line(r, kind="regular", seeds=(0,),
                                                                           duration=duration), 5.0, 60.0),
                     "belt_speed_m_s": g_spec.belt.speed, "map_error_max": err.max}
    out["_objects"] = objects  # the runs and curves behind the figures (for plots; not JSON)
    return out


if __name__ == "__main__":  # regenerate the package's maps: python -m pinarms.studies.line
    for spec in (scara_line(1, 60.0), scara_line(1, 60.0, paper_limit=True), gantry_line(60.0)):
        maps_for(spec, save=True, progress=print)


def demo_study(quick: bool = False) -> Any:
    """The demo's line study (:func:`pinarms.demo.run_demo`, key ``"line"``): the figures a line
    engineer quotes, as rows of the paper-vs-pinarms table."""
    from pinarms.studies.study import Study
    from pinarms.report import Row

    seeds = (0, 1, 2) if quick else (0, 1, 2, 3, 4)
    out = study(60.0, seeds=seeds, duration=600.0)
    out.pop("_objects")  # the runs and curves behind the figures (not JSON); the views re-run what they show
    rows = []
    for label in ("model limits", "paper 55 deg/s joint 1"):
        d = out[label]
        note = (f"Poisson 60 bunches/min, belt {d['belt_speed_m_s']} m/s, rule first-in-window: "
                f"{d['picks_per_min']:.1f} picks/min, miss {100 * d['miss_rate']:.2f} % "
                f"(95 % CI {100 * d['miss_rate_ci'][0]:.2f}-{100 * d['miss_rate_ci'][1]:.2f} %, {len(seeds)} seeds); "
                f"map error vs exact planning {100 * d['map_error_max']:.2f} %")
        rows.append(Row("000", f"SCARAs for 60 bunches/min at <= 1 % miss ({label})", None, d["arms"], "arms", None,
                        note))
        rows.append(Row("000", f"one SCARA saturated on the belt ({label})", None,
                        d["one_arm_saturated_picks_per_min"], "picks/min", None, "conveyor tracking, box beside the arm"))
    from pinarms.studies.delta_line import delta_rows

    rows += delta_rows(out["model limits"], 60.0, item=ENOKI, seeds=seeds, duration=600.0)  # SCARA or delta (docs/line.md)
    g = out["gantry"]
    rows.append(Row("002", "gantry fed by a belt: picks/min saturated", 60.0, g["saturated_picks_per_min"], "picks/min",
                    None, f"belt {g['belt_speed_m_s']} m/s, tracking pick, the model's limits (1 m/s per axis); "
                          "the paper's 60/min is on hardware, path not printed"))
    rows.append(Row("002", "gantry: largest regular flow at <= 1 % miss", 60.0, round(g["max_flow_1pct_regular"], 1),
                    "items/min", None, f"at 60/min Poisson: {g['poisson_60']['picks_per_minute']:.1f} picks/min, "
                                       f"miss {100 * g['poisson_60']['miss_rate']:.1f} %"))

    session, plots = line_views(out["model limits"]["arms"] or 1, 60.0, seeds=seeds[:3], duration=300.0)
    return Study("line", "the line: enoki bunches on seed 000's belt, seed 002's gantry fed by a belt", rows, session,
                 plots)


def line_views(n_arms: int, rate: float = 60.0, *, seeds: tuple[int, ...] = (0, 1, 2), duration: float = 300.0,
               window: float = 20.0) -> tuple[Any, dict]:
    """(session, {plot name: writer(path)}) of ``n_arms`` SCARAs at ``rate`` bunches/min: seed 000's line as a
    session (belt, items, SCARAs picking), its schedule and its sizing curves (throughput and miss rate against
    flow and number of arms, 95 % band over the seeds). The demo writes them as ``sessions/line.pinarms``,
    ``html/line.html``, ``plots/line_schedule.png`` and ``plots/line_sizing.png``.

    Belt speed is not swept here: the package's task maps hold seed 000's belt at 0.2 m/s only
    (:func:`pinarms.viz.line_plots.line_curve` sweeps it where maps for other speeds exist or may be built).
    """
    from pinarms import viz
    from pinarms.optim.line import run_line
    from pinarms.viz.line_plots import line_curve, plot_line_schedule, plot_line_sizing

    n = max(1, int(n_arms))
    spec = scara_line(n, rate, seeds=seeds, duration=duration)
    result = run_line(spec, maps=maps_for(spec))
    f = result.figures
    session = viz.Session(title=f"seed 000 line: {n} SCARA(s), {rate:g} enoki bunches/min, "
                                f"belt {spec.belt.speed:g} m/s ({f.picks_per_minute:.1f} picks/min, miss {100 * f.miss_rate:.1f} %)")
    session.add_line(spec, result, duration=window)

    def sizing(path: Any) -> Any:
        flows = line_curve(lambda r: scara_line(n, r, seeds=seeds, duration=duration),
                           [rate * k for k in (0.5, 0.75, 1.0, 1.25, 1.5)], maps=maps_for)
        arms = line_curve(lambda k: scara_line(int(k), rate, seeds=seeds, duration=duration),
                          list(range(max(1, n - 2), n + 3)), maps=maps_for)
        return plot_line_sizing(path, {f"flow [bunches/min] ({n} arms)": flows, f"arms ({rate:g} bunches/min)": arms},
                                title=f"seed 000 line, belt {spec.belt.speed:g} m/s, rule {spec.rule.name}, "
                                      f"{len(seeds)} seeds × {duration:g} s")

    plots = {"schedule": lambda path: plot_line_schedule(path, result, window=(0.0, 60.0)), "sizing": sizing}
    return session, plots
