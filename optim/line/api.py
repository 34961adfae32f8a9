"""One line description in, one result out: :func:`run_line`.

A :class:`LineSpec` holds the belt, the stations (arms with their boxes), the item stream,
how arms pick (:class:`TrackingSpec`), the assignment rule, the seeds and the miss rate
asked for. :func:`run_line` builds each station's task-time maps (once per distinct station
shape: stations that differ only by their place along the belt share them), simulates every
seed on the execution layer (serial by default, a Dask cluster by address; same results
either way) and returns a :class:`LineResult` with a status and the figures.

Statuses and exceptions (:mod:`pinarms.optim.status`): a malformed :class:`LineSpec` raises when it is
built; a line that runs but misses more items than ``target_miss_rate`` is a result with
``status`` :attr:`LineStatus.MISSES_ABOVE_TARGET` and a ``status_reason``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from pinarms.optim.types import Scheduler

from pinarms.optim.caps import count_setting
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.numbers import finite_number
from pinarms.optim.line.items import MAX_ITEMS, ItemType, Items, poisson_items, read_arrivals, regular_items
from pinarms.optim.line.report import LineFigures, summarise
from pinarms.optim.line.rules import AssignmentRule, Rule
from pinarms.optim.line.simulate import SimArm, SimResult, simulate
from pinarms.optim.line.station import Station
from pinarms.optim.line.map_request import YAW_MODES, MapRequest
from pinarms.optim.line.task_map_build import build_task_map
from pinarms.optim.line.task_maps import TaskMap
from pinarms.optim.line.tracking import TrackingSpec, can_yaw
from pinarms.optim.line.trays import TrayBelt
from pinarms.optim.line.windows import PickWindow, window_of, windows_overlap
from pinarms.optim.status import Status
from pinarms.errors import InvalidInput

__all__ = ["Stream", "LineSpec", "LineResult", "run_line", "build_maps", "map_warnings", "sim_arms", "LineStatus",
           "LineCurve", "line_curve", "MAX_LINE_ARMS", "MAX_LINE_SEEDS", "station_shape_key"]

STREAM_KINDS = ("poisson", "regular", "file")
#: Most arms (stations) along one line, and most seeds (Monte Carlo runs) of one line result.
MAX_LINE_ARMS = 64
MAX_LINE_SEEDS = 10_000


class LineStatus(Status):
    """How a line did against its target miss rate (the value is the word printed)."""

    #: the miss rate's mean over the seeds is within ``LineSpec.target_miss_rate``
    OK = "ok"
    #: it is not (``LineResult.status_reason`` gives both figures)
    MISSES_ABOVE_TARGET = "misses above target"


@dataclass(frozen=True)
class Stream:
    """The items: ``kind`` ``"poisson"`` (``rate_per_s`` items/s at random, as
    :func:`~.items.poisson_items` takes it), ``"regular"`` (one every 1/``rate_per_s`` s) or
    ``"file"`` (``path`` of an arrivals file); ``duration`` [s] simulated; ``types`` of items (one
    :class:`ItemType` by default). Items per minute only at the edges (``pinarms belt --rate``)."""

    kind: str = "poisson"
    rate_per_s: float = 1.0
    duration: float = 600.0
    path: str | None = None
    types: tuple[ItemType, ...] = (ItemType("item"),)

    def __post_init__(self) -> None:
        if self.kind not in STREAM_KINDS:
            raise InvalidInput(f"stream kind must be one of {STREAM_KINDS}, got {self.kind!r}")
        if self.kind == "file" and not self.path:
            raise InvalidInput("a 'file' stream needs the path of its arrivals file")
        rate = finite_number(self.rate_per_s, "stream rate_per_s [items/s]", positive=True)
        duration = finite_number(self.duration, "stream duration [s]", positive=True)
        expected = rate * duration
        if self.kind != "file" and not expected <= MAX_ITEMS:
            raise InvalidInput(f"a stream of {rate:g} items/s over {duration:g} s is {expected:.3g} items; a stream "
                               f"holds at most {MAX_ITEMS} items: lower the rate or the duration")
        object.__setattr__(self, "types", tuple(self.types))

    def items(self, belt: Belt, seed: int) -> Items:
        if self.kind == "poisson":
            return poisson_items(belt, self.rate_per_s, self.duration, types=self.types, seed=seed)
        if self.kind == "regular":
            return regular_items(belt, 1.0 / self.rate_per_s, self.duration, types=self.types, seed=seed)
        return read_arrivals(Path(self.path), belt, self.types)


@dataclass(frozen=True, eq=False)
class LineSpec:
    """A line (module doc). ``target_miss_rate``: the miss rate asked for (fraction);
    ``map_grid``: (nu, nw) of the task maps; ``cell``: a :class:`pinarms.robots.cell.Cell` whose arms
    are the stations (same names and bases) — then neighbours whose windows overlap start a pick
    only when the cell's continuous check proves it keeps ``clearance`` [m] from the neighbour's
    (:mod:`~.neighbours`; the seeds then run in this process), and every map node whose planned pick
    comes closer than ``clearance`` to the cell's fixtures is infeasible (:mod:`~.fixtures`; the maps
    are then built per station, its place along the belt mattering)."""

    belt: Belt
    stations: tuple[Station, ...]
    stream: Stream = Stream()
    tracking: TrackingSpec = TrackingSpec()
    rule: Rule | AssignmentRule = Rule()
    seeds: tuple[int, ...] = (0, 1, 2, 3, 4)
    target_miss_rate: float = 0.01
    map_grid: tuple[int, int] = (24, 7)
    cell: Any = None
    clearance: float = 0.01
    trays: Any = None  #: None (every arm places in its box), a TrayBelt for every arm, or {station name: TrayBelt}
    tray_grid: tuple[int, int, int] = (10, 5, 8)  #: (nu, nw, nv) of the tray maps (docs/line.md: why 5 across)
    map_yaw: str = "auto"  #: the task maps' yaw coordinate (:data:`~.task_map_build.YAW_MODES`)

    def __post_init__(self) -> None:
        if not isinstance(self.belt, Belt):
            raise InvalidInput("belt must be a Belt")
        st = tuple(self.stations)
        count_setting(len(st), "the number of stations", 1, MAX_LINE_ARMS)
        count_setting(len(tuple(self.seeds)), "the number of seeds", 1, MAX_LINE_SEEDS)
        if not st or not all(isinstance(s, Station) for s in st):
            raise InvalidInput("stations must be a non-empty sequence of Station")
        names = [s.name for s in st]
        if len(set(names)) != len(names):
            raise InvalidInput(f"station names must be unique, got {names}")
        object.__setattr__(self, "stations", st)
        if not self.seeds:
            raise InvalidInput("seeds must hold at least one seed")
        object.__setattr__(self, "seeds", tuple(int(s) for s in self.seeds))
        rate = finite_number(self.target_miss_rate, "target miss rate")
        if not 0.0 <= rate < 1.0:
            raise InvalidInput(f"target miss rate must be in [0, 1), got {self.target_miss_rate!r}")
        if isinstance(self.rule, str):
            object.__setattr__(self, "rule", Rule(self.rule))
        elif not isinstance(self.rule, (Rule, AssignmentRule)):
            raise InvalidInput(f"rule must be a rule name, a Rule or an AssignmentRule, got {type(self.rule).__name__}")
        object.__setattr__(self, "trays", _tray_option(self.trays, names))
        if self.trays and len(self.stream.types) != 1:
            raise InvalidInput("trays: one item type only (the tray maps have no item-type coordinate)")
        if self.map_yaw not in YAW_MODES:
            raise InvalidInput(f"map_yaw must be one of {YAW_MODES}, got {self.map_yaw!r}")

    def trays_of(self, station: str) -> TrayBelt | None:
        """The TrayBelt arm ``station`` places in (None: its box)."""
        return (self.trays or {}).get(station)


def _tray_option(trays: Any, names: list) -> dict | None:
    if trays is None:
        return None
    if isinstance(trays, TrayBelt):
        return {n: trays for n in names}
    if not isinstance(trays, dict) or not all(isinstance(v, TrayBelt) or v is None for v in trays.values()):
        raise InvalidInput("trays must be None, a TrayBelt or a dict {station name: TrayBelt or None}")
    unknown = sorted(set(trays) - set(names))
    if unknown:
        raise InvalidInput(f"trays name stations that are not in the line: {unknown} (stations: {names})")
    return {n: t for n, t in trays.items() if t is not None} or None


@dataclass(frozen=True, eq=False)
class LineResult:
    """The line's answer: ``status`` (:class:`LineStatus`), ``status_reason`` (why, when not
    ``OK``; ``""`` otherwise), ``figures`` (:class:`LineFigures`),
    ``windows`` (each arm's :class:`PickWindow`), ``overlapping`` (neighbour pairs whose
    windows overlap), ``runs`` (one :class:`SimResult` per seed), ``maps`` (per station);
    ``fixture_infeasible``: per station, its maps' nodes closer than the clearance to the cell's
    fixtures (empty without a cell); ``map_warnings``: why a station's task times may be off (a map
    that ignores a yaw dependence it has, or never measured it: :meth:`TaskMap.warnings`), empty
    when none."""

    status: LineStatus
    figures: LineFigures
    windows: tuple[PickWindow, ...]
    overlapping: tuple[tuple[str, str], ...]
    runs: tuple[SimResult, ...] = field(repr=False)
    maps: dict = field(repr=False, default_factory=dict)
    belt_speed: float = 0.0
    fixture_infeasible: dict = field(default_factory=dict)
    status_reason: str = ""
    map_warnings: tuple[str, ...] = ()

    def summary(self, title: str = "line") -> str:
        """The figures as text, one per line (what ``pinarms belt run`` prints): status, arms, belt
        speed, arrivals and picks per minute, miss rate with its 95 % interval, utilisation per arm,
        item wait (and the tray figures when the line places in trays)."""
        f = self.figures
        lo, hi = f.miss_rate_ci
        lines = [
            title,
            f"  status            {self.status}",
            f"  arms              {len(f.arms)}",
            f"  belt speed        {self.belt_speed:.3f} m/s",
            f"  arrivals          {f.arrivals_per_minute:.1f} /min",
            f"  picks             {f.picks_per_minute:.1f} /min",
            f"  miss rate         {100 * f.miss_rate:.2f} %  (95 % CI {100 * lo:.2f} - {100 * hi:.2f} %, {f.seeds} seeds)",
            "  utilisation       " + ", ".join(f"{a}: {100 * u:.0f} %" for a, u in zip(f.arms, f.utilisation)),
            f"  item wait         mean {f.wait_mean_s:.2f} s, p95 {f.wait_p95_s:.2f} s",
        ]
        if f.tray_fill_rate is not None:
            lines.append(f"  tray fill         {100 * f.tray_fill_rate:.1f} %, {f.trays_unfilled:.1f} trays left with a "
                         f"free slot per run, {100 * f.unplaced_rate:.2f} % of items missed for want of a slot")
        lines += [f"  warning           {w}" for w in self.map_warnings]
        return "\n".join(lines)

    def as_dict(self) -> dict[str, Any]:
        return {"status": self.status.value, "belt_speed_m_s": self.belt_speed, "figures": self.figures.as_dict(),
                "neighbour_checks": [list(r.checks) for r in self.runs],
                "fixture_infeasible": dict(self.fixture_infeasible), "map_warnings": list(self.map_warnings),
                "windows": [w.__dict__ for w in self.windows], "overlapping": [list(p) for p in self.overlapping]}


def station_shape_key(st: Station, belt: Belt) -> tuple:
    """What a station's task maps depend on besides the items: its arm, its base on ``belt`` (height, offset,
    rotation), its place in its base frame and its limits (part of the key that names stored maps)."""
    b = belt.to_belt(st.base_to_world[:3, 3])
    rel = st.world_to_base(st.place.position)
    lim = st.limits
    return (st.robot.name, round(float(b[1]), 9), round(float(b[2]), 9),
            tuple(np.round(st.base_to_world[:3, :3], 9).ravel()), tuple(np.round(rel, 9)),
            tuple(lim["vmax"]), tuple(lim["amax"]), lim["torque"])


def build_maps(spec: LineSpec, *, scheduler: Scheduler = None, known: dict | None = None,
               approach_maps: dict | None = None,
               progress: Callable[..., None] | None = None) -> dict[str, tuple[TaskMap, ...]]:
    """Task maps of every station, one per item type, built once per distinct station shape.
    ``approach_maps``: ``{station name: (box TaskMap, ...)}`` whose approach times the tray maps
    take (:func:`~.tray_maps.build_tray_map` ``approach_map``). ``progress(done, total, note)``:
    the map under way (``note``, e.g. ``"task map 'arm 1' (item)"``) and its columns planned so far."""
    cache: dict = {} if known is None else known
    out = {}
    near = {"cell": spec.cell, "clearance": spec.clearance}
    for st in spec.stations:
        trays = spec.trays_of(st.name)
        # with a cell the fixtures differ along the belt: the station's own maps
        own = () if spec.cell is None else (id(spec.cell), spec.clearance, tuple(np.round(st.base_to_world[:3, 3], 9)))
        if trays is not None:
            t = spec.stream.types[0]
            on_trays = tuple(np.round(trays.belt.to_belt(st.base_to_world[:3, 3])[1:], 9))  # parallel belts: shared
            fine = (approach_maps or {}).get(st.name, (None,))[0]
            key = (station_shape_key(st, spec.belt), "trays", id(trays), on_trays, spec.belt.speed, t.mass, t.size[2], spec.tracking,
                   spec.tray_grid, id(fine), own, spec.map_yaw == "none")
            if key not in cache:
                from pinarms.optim.line.map_request import TrayMapRequest
                from pinarms.optim.line.tray_maps import build_tray_map

                nu, nw, nv = spec.tray_grid
                rq = TrayMapRequest(st, spec.belt, trays, spec.tracking, mass=t.mass, item_height=t.size[2], nu=nu,
                                    nw=nw, nv=nv, approach_map=fine, yaw="none" if spec.map_yaw == "none" else "auto",
                                    **near)
                cache[key] = build_tray_map(rq, scheduler=scheduler,
                                            progress=_noted(progress, f"tray map {st.name!r}")).task_map
            out[st.name] = (cache[key],)
            continue
        maps = []
        for t in spec.stream.types:
            key = (station_shape_key(st, spec.belt), spec.belt.speed, t.mass, t.size[2], spec.tracking, spec.map_grid, own,
                   spec.map_yaw)
            if key not in cache:
                rq = MapRequest(st, spec.belt, spec.tracking, mass=t.mass, item_height=t.size[2],
                                nu=spec.map_grid[0], nw=spec.map_grid[1], yaw=spec.map_yaw, **near)
                cache[key] = build_task_map(rq, scheduler=scheduler,
                                            progress=_noted(progress, f"task map {st.name!r} ({t.name})")).task_map
            maps.append(cache[key])
        out[st.name] = tuple(maps)
    return out


def sim_arms(spec: LineSpec, maps: dict[str, tuple[TaskMap, ...]]) -> list[SimArm]:
    """The stations as the simulator sees them."""
    arms = []
    for st in spec.stations:
        u_base = float(spec.belt.to_belt(st.base_to_world[:3, 3])[0])
        rest = spec.belt.to_belt(st.place.position)
        trays = spec.trays_of(st.name)
        if trays is None:
            arms.append(SimArm(st.name, u_base, maps[st.name], (float(rest[0]), float(rest[1]))))
            continue
        from pinarms.optim.line.tray_sim import SimPlace

        tm = maps[st.name][0]
        place = SimPlace(tm, trays, float(trays.belt.to_belt(st.base_to_world[:3, 3])[0]))
        arms.append(SimArm(st.name, u_base, (tm.pick_map,), (float(rest[0]), float(rest[1])), place))
    return arms


def _run_seed(task: dict) -> SimResult:
    spec = task["spec"]
    items = spec.stream.items(spec.belt, task["seed"])
    guard = None
    if spec.cell is not None:
        from pinarms.optim.line.neighbours import NeighbourGuard

        guard = NeighbourGuard(spec.cell, spec.stations, spec.belt, spec.tracking, spec.stream.types,
                               clearance=spec.clearance, maps={a.name: a.maps for a in task["arms"]},
                               yaws=items.yaw)
    return simulate(task["arms"], items, spec.belt.speed, spec.rule, duration=spec.stream.duration,
                    width=spec.belt.width, guard=guard)


def _noted(progress: Callable[..., None] | None, note: str) -> Callable[..., None] | None:
    """``progress`` as a ``(done, total)`` callback that names the step (None stays None)."""
    if progress is None:
        return None
    return lambda done, total=None: progress(done, total, note)


def map_warnings(spec: LineSpec, maps: dict) -> tuple[str, ...]:
    """What the stations' maps say makes their times doubtful (:meth:`TaskMap.warnings`), once each;
    none for an arm that cannot turn its tool (its time cannot depend on the item's yaw)."""
    out: list[str] = []
    for st in spec.stations:
        if not can_yaw(st.robot):
            continue
        for m in maps.get(st.name, ()):
            for text in m.warnings():
                if text not in out:
                    out.append(text)
    return tuple(out)


def run_line(spec: LineSpec, *, maps: dict | None = None, scheduler: Scheduler = None,
             progress: Callable[..., None] | None = None) -> LineResult:
    """Simulate the line on every seed and summarise (module doc). ``progress(done, total, note)``:
    the step under way (``note``: a map being built, ``"seeds"``) and how far it is."""
    from pinarms.execution import map_chunks

    maps = build_maps(spec, scheduler=scheduler, progress=progress) if maps is None else maps
    arms = sim_arms(spec, maps)
    runs = map_chunks(_run_seed, [{"spec": spec, "arms": arms, "seed": s} for s in spec.seeds],
                      scheduler=scheduler if spec.cell is None else None, progress=_noted(progress, "seeds"))
    figures = summarise(runs)
    windows = tuple(window_of(st, spec.belt, _pick_part(maps[st.name][0])) for st in spec.stations)
    ordered = sorted(windows, key=lambda w: w.u_base)
    overlapping = tuple((a.station, b.station) for a, b in zip(ordered, ordered[1:]) if windows_overlap(a, b))
    ok = figures.miss_rate <= spec.target_miss_rate
    status = LineStatus.OK if ok else LineStatus.MISSES_ABOVE_TARGET
    reason = "" if ok else (f"mean miss rate {100 * figures.miss_rate:.2f} % over {figures.seeds} seeds is above the "
                            f"target {100 * spec.target_miss_rate:.2f} %: add an arm, slow the belt or lower the flow")
    blocked = ({} if spec.cell is None else
               {st.name: sum(int(getattr(m, "fixture_infeasible", 0)) for m in maps[st.name]) for st in spec.stations})
    return LineResult(status, figures, windows, overlapping, tuple(runs), maps, spec.belt.speed, blocked, reason,
                      map_warnings(spec, maps))


def _pick_part(m: Any) -> TaskMap:
    return m.pick_map if hasattr(m, "pick_map") else m


@dataclass(frozen=True)
class LineCurve:
    """Throughput and miss rate against one parameter: ``parameter`` (``"rate"``, ``"speed"`` or
    ``"arms"``), ``values`` (K,), ``picks_per_minute`` (K,), ``miss_rate`` (K,) and its interval
    ``miss_low``/``miss_high`` (K,), ``arrivals_per_minute`` (K,)."""

    parameter: str
    values: np.ndarray
    picks_per_minute: np.ndarray
    miss_rate: np.ndarray
    miss_low: np.ndarray
    miss_high: np.ndarray
    arrivals_per_minute: np.ndarray


def line_curve(make_spec: Callable[[float], LineSpec], parameter: str, values: Sequence[float],
               maps: Callable[[LineSpec], dict], *,
               scheduler: Scheduler = None) -> LineCurve:
    """Run ``make_spec(value)`` (a :class:`LineSpec`) for each value; ``maps(spec)`` gives its
    task maps (e.g. :func:`pinarms.studies.line.maps_for`, or :func:`build_maps`)."""
    if parameter not in ("rate", "speed", "arms"):
        raise InvalidInput(f"parameter must be 'rate', 'speed' or 'arms', got {parameter!r}")
    rows = []
    for v in values:
        spec = make_spec(v)
        f = run_line(spec, maps=maps(spec), scheduler=scheduler).figures
        rows.append((f.picks_per_minute, f.miss_rate, *f.miss_rate_ci, f.arrivals_per_minute))
    a = np.array(rows, dtype=float).reshape(-1, 5)
    return LineCurve(parameter, np.asarray(values, dtype=float), *a.T)
