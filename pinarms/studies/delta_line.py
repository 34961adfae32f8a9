"""SCARA or delta, and how many: seed 000's enoki stream picked by deltas above the belt.

The same belt, stream and rule as seed 000's SCARA line (:func:`pinarms.studies.line.scara_line`:
enoki bunches, 0.15 kg, Poisson, a 0.3 m belt at 0.2 m/s, first in window, 5 seeds × 600 s), picked
by copies of a shipped delta (``delta_flexpicker``, docs/delta.md) hung above the belt's centre line,
``DELTA_SPACING`` m apart (each pick window is about 1.5 m of belt: the windows do not overlap), each
base ``DELTA_HEIGHT`` m above the belt's surface and its box beside the belt. The delta's task maps
(:func:`pinarms.optim.line.delta_maps.build_delta_map`) are built, not stored (about 20 s a map): one map
serves every delta of a line (the same shape shifted along the belt).

:func:`delta_arms_needed` is :func:`pinarms.studies.line.arms_needed` for deltas; :func:`delta_rows`
puts deltas beside the SCARAs (the rows of the demo's line study).
"""

from __future__ import annotations

from typing import Any

from pinarms.optim.line import Belt, LineSpec, PlaceBox, Rule, Station, Stream, TrackingSpec, base_pose, run_line
from pinarms.optim.line.delta_maps import build_delta_map
from pinarms.optim.line.map_request import DeltaMapRequest
from pinarms.optim.line.delta_tracking import DeltaArm
from pinarms.robots.delta import delta_names, load_delta
from pinarms.errors import InvalidInput

__all__ = ["delta_line", "delta_maps", "delta_arms_needed", "delta_rows", "DELTA_SPACING", "DELTA_HEIGHT", "DELTA_BOX"]

#: Distance between deltas along the belt [m].
DELTA_SPACING = 1.6
#: Height of a delta's base (the plane of its motor axes) above the belt's surface [m].
DELTA_HEIGHT = 1.1
#: A delta's box from its base (along the belt, across, up) [m]: beside the belt, 0.1 m above it.
DELTA_BOX = (0.0, 0.45, -1.0)


def delta_line(n_arms: int, rate: float, *, item: Any,
               name: str = "delta_flexpicker", speed: float = 0.2, rule: str = "first",
               seeds: tuple[int, ...] = (0, 1, 2, 3, 4), duration: float = 600.0, spacing: float = DELTA_SPACING,
               height: float = DELTA_HEIGHT, box: tuple[float, float, float] = DELTA_BOX, first: float = 1.0,
               map_grid: tuple[int, int] = (12, 5)) -> LineSpec:
    """``n_arms`` deltas ``name`` above seed 000's belt at ``speed`` [m/s], ``rate`` items/min of ``item``
    (an :class:`pinarms.optim.line.ItemType`; the study: :data:`pinarms.studies.line.ENOKI`) (module doc).

    Raises:
        InvalidInput: a name that is not a shipped delta (names them)."""
    if name not in delta_names():
        raise InvalidInput(f"{name!r} is not a shipped delta; shipped: {', '.join(delta_names())}")
    arm = DeltaArm(load_delta(name))
    z = 0.80
    stations = tuple(Station(f"delta {k + 1}", arm, base_pose(first + spacing * k, 0.0, z + height),
                             PlaceBox((first + spacing * k + box[0], box[1], z + height + box[2]), f"box {k + 1}"),
                             vmax=arm.velocity_limit, amax=arm.acceleration_limit)
                     for k in range(int(n_arms)))
    belt = Belt((0.0, 0.0, z), speed=speed, width=0.3, length=first + spacing * int(n_arms) + 0.5)
    return LineSpec(belt, stations, Stream("poisson", rate / 60.0, duration, types=(item,)), TrackingSpec(), Rule(rule),
                    seeds, 0.01, tuple(map_grid))


def delta_maps(spec: LineSpec, *, n: int = 24, progress: Any = None) -> dict:
    """``{station: (TaskMap,)}``: one map built for the first delta (:func:`build_delta_map`), shared by
    every delta of ``spec`` (same arm, height, box and belt speed; shifted along the belt)."""
    st = spec.stations[0]
    kind = spec.stream.types[0]
    m = build_delta_map(DeltaMapRequest(st, spec.belt, spec.tracking, mass=kind.mass, item_height=kind.size[2],
                                        nu=spec.map_grid[0], nw=spec.map_grid[1], n=n), progress=progress).task_map
    return {s.name: (m,) for s in spec.stations}


def delta_arms_needed(rate: float, *, max_arms: int = 20, maps: Any = None, **kw: Any) -> tuple[int | None, Any, Any]:
    """Fewest deltas whose mean miss rate is ≤ 1 % at ``rate`` items/min: (arms or None, that line's
    result, the map used)."""
    last, one = None, maps
    for k in range(1, max_arms + 1):
        spec = delta_line(k, rate, **kw)
        one = one or delta_maps(spec)[spec.stations[0].name]
        last = run_line(spec, maps={st.name: one for st in spec.stations})
        if last.status == "ok":
            return k, last, one
    return None, last, one


def delta_rows(scara: dict[str, Any], rate: float = 60.0, *, item: Any, seeds: tuple[int, ...] = (0, 1, 2, 3, 4),
               duration: float = 600.0, map_grid: tuple[int, int] = (12, 5),
               faster: tuple[float, ...] = (0.6,)) -> list[Any]:
    """The rows "SCARA or delta" of the demo's line study: deltas needed for ``rate`` bunches/min at
    ≤ 1 % miss beside ``scara`` (the line study's figures of seed 000's SCARAs at the model's limits:
    ``arms``, ``picks_per_min``, ``miss_rate``), one delta saturated, and the deltas needed on a belt at
    each speed of ``faster`` [m/s] (a map each)."""
    from dataclasses import replace

    from pinarms.report import Row

    k, res, m = delta_arms_needed(rate, item=item, seeds=seeds, duration=duration, map_grid=map_grid)
    f = res.figures
    places = ", ".join(f"{w.u_base:.1f}" for w in res.windows)
    note = (f"delta_flexpicker (docs/delta.md, motor limits assumed) above the belt's centre line, {DELTA_SPACING} m "
            f"apart "
            f"(bases at {places} m along the belt), same Poisson {rate:g} bunches/min, belt {res.belt_speed} m/s, "
            f"rule first-in-window: {f.picks_per_minute:.1f} picks/min, miss {100 * f.miss_rate:.2f} % (95 % CI "
            f"{100 * f.miss_rate_ci[0]:.2f}-{100 * f.miss_rate_ci[1]:.2f} %, {len(seeds)} seeds); against "
            f"{scara['arms']} SCARAs ({scara['picks_per_min']:.1f} picks/min, miss {100 * scara['miss_rate']:.2f} %); "
            f"task times depend on the item's yaw by up to {100 * m[0].yaw_spread:.0f} % (fourth axis)")
    one = delta_line(1, rate, item=item, seeds=(0,), duration=120.0)
    sat = run_line(replace(one, stream=Stream("regular", 4.0, 120.0, types=(item,))), maps={"delta 1": m})
    rows = [Row("000", f"SCARA or delta: deltas for {rate:g} bunches/min at <= 1 % miss", None, k, "arms", None, note),
            Row("000", "one delta saturated on the belt", None, sat.figures.picks_per_minute, "picks/min", None,
                "conveyor tracking, box beside the belt; timed in the motors' space under speed, acceleration "
                "and torque limits with the bunch as payload")]
    for v in faster:
        kv, rv, _ = delta_arms_needed(rate, item=item, seeds=seeds, duration=duration, map_grid=map_grid, speed=v)
        fv = rv.figures
        rows.append(Row("000", f"SCARA or delta: deltas for {rate:g} bunches/min at <= 1 % miss, belt {v:g} m/s", None,
                        kv, "arms", None, f"as above on a belt at {v:g} m/s: {fv.picks_per_minute:.1f} picks/min, miss "
                                         f"{100 * fv.miss_rate:.2f} % (95 % CI {100 * fv.miss_rate_ci[0]:.2f}-"
                                         f"{100 * fv.miss_rate_ci[1]:.2f} %)"))
    return rows
