"""The line: simulation speed, map building, look-ahead vs simple rules, sizing serial vs Dask.

Parts (figures printed, not timed tests; docs/line.md quotes a full run):

1. ``simulate``: one hour of a four-arm SCARA line at 120 items/min (about 7 200 items),
   maps loaded (seed 000's SCARA, model limits), each rule, one core.
2. ``maps``: one arm's task-time maps built (24 × 7 grid on each IK branch, refined twice where
   the times bend, serial) and their error against exact planning at 100 random picks.
3. ``rules``: look-ahead (horizon 4) against first / nearest / shortest on the same streams:
   one arm below, at and above its capacity; four arms at 60 and 120 items/min.
4. ``sizing``: a sizing sweep (``optim.line.sizing.evaluate_layouts``: 24 layouts × 4 seeds,
   one task per layout) serial vs a LocalCluster of two single-thread workers (127.0.0.1, no
   dashboard), both sides warmed alike, interleaved; the results must be identical.

5. ``trays``: the tray map of the CLI's tray run (seed 000's SCARA, trays on a belt through its
   box; 10 × 5 × 8 grid or ``trays NU,NW,NV``, ``coarse``: without the box map's approach times;
   each place on both elbows; serial) and its error against exact pick-to-tray planning at 100
   random (pick, place) points.

6. ``fixtures``: the cost of the fixture clearance on map building: the left SCARA of
   ``mushroom_line`` (its cell: belt, guards, table, box walls), 24 × 7 grid on both elbows, serial,
   built without the cell, with it (compiled cover check where it proves, exact elsewhere) and with
   the exact check alone; the counts of each route.
7. ``neighbours``: the two facing SCARAs of ``mushroom_line``, 30 items/min Poisson for 120 s, first
   in window, every start checked against the neighbour's ongoing pick: through the compiled cover
   check where it proves (exact elsewhere) against the cell's exact check alone.

8. ``speed``: the simulator against issue 39's goals, each printed met or with its gap and reason:
   <= 20 µs per decision (one hour of four SCARAs, 120 items/min, each rule, the whole ``simulate``
   call and its loop alone), the look-ahead (horizon 8) over that hour < 2 s, 10^6 items on seven
   SCARAs < 30 s. The Python loop (every rule object runs there) is the peer, interleaved with the
   compiled loop on the same items (Python, compiled, Python, compiled); both must give the same runs.

Run: python benchmarks/line.py [simulate|maps|rules|synthetic|sizing|trays|fixtures|neighbours|speed|all]
"""

from __future__ import annotations

import sys
import time

import numpy as np


def _scara(n: int, rate: float, duration: float = 3600.0, seeds=(0,), rule: str = "first"):
    from pinarms.studies.line import maps_for, scara_line

    spec = scara_line(n, rate, seeds=seeds, duration=duration, rule=rule)
    return spec, maps_for(spec)


def part_simulate() -> None:
    from pinarms.optim.line import Rule, simulate
    from pinarms.optim.line.api import sim_arms
    from threadpoolctl import threadpool_limits

    spec, maps = _scara(4, 120.0)
    items = spec.stream.items(spec.belt, 0)
    arms = sim_arms(spec, maps)
    print(f"[simulate] 4 SCARAs, 120 items/min Poisson, 1 h: {len(items)} items")
    with threadpool_limits(1):
        simulate(arms, items, spec.belt.speed, "first", duration=3600.0, width=spec.belt.width)  # numba's cache loaded
        for rule in ("first", "nearest", "shortest", "split", "bands", Rule("lookahead", 8)):
            t = time.perf_counter()
            r = simulate(arms, items, spec.belt.speed, rule, duration=3600.0, width=spec.belt.width)
            dt = time.perf_counter() - t
            print(f"  {getattr(rule, 'name', rule):9s} {dt:6.2f} s   picks/min {r.picks_per_minute:6.1f}   miss {100 * r.miss_rate:5.1f} %"
                  f"   decisions {r.decisions}")


def part_maps() -> None:
    from pinarms.optim.line import MapRequest, build_task_map, map_error
    from pinarms.studies.line import ENOKI, scara_line

    spec = scara_line(1, 60.0)
    st = spec.stations[0]
    t = time.perf_counter()
    m = build_task_map(MapRequest(st, spec.belt, spec.tracking, mass=ENOKI.mass, item_height=ENOKI.size[2], nu=24,
                                  nw=7, refine=2)).task_map
    print(f"[maps] one SCARA, 24 x 7 grid refined to {m.du.size} x {m.w.size}, {len(m.branches)} IK branches: built in "
          f"{time.perf_counter() - t:.1f} s, {np.isfinite(m.approach).sum()} feasible nodes")
    e = map_error(m, st, spec.belt, spec.tracking, n=100, item_height=ENOKI.size[2], seed=11)
    print(f"  error vs exact planning at {e.relative.size} random picks: mean {100 * e.mean:.3f} %, "
          f"max {100 * e.max:.3f} %, 95th {100 * np.percentile(e.relative, 95):.3f} % "
          f"({e.planning_seconds / e.relative.size:.2f} s per exact pick)")


def part_rules() -> None:
    from pinarms.optim.line import Rule, simulate
    from pinarms.optim.line.api import sim_arms

    print("[rules] picks on the same streams (3 seeds x 600 s); gain of look-ahead (horizon 4) over the best simple rule")
    for n, rate in ((1, 10.0), (1, 20.0), (1, 40.0), (4, 60.0), (4, 120.0)):
        spec, maps = _scara(n, rate, duration=600.0)
        arms = sim_arms(spec, maps)
        picks = {}
        t_la = 0.0
        for rule in ("first", "nearest", "shortest", "lookahead"):
            total = 0
            for seed in range(3):
                items = spec.stream.items(spec.belt, seed)
                t = time.perf_counter()
                r = simulate(arms, items, spec.belt.speed, Rule(rule, 4), duration=600.0)
                if rule == "lookahead":
                    t_la += time.perf_counter() - t
                total += r.picks
            picks[rule] = total
        best = max(picks[k] for k in ("first", "nearest", "shortest"))
        print(f"  {n} arm(s) {rate:5.0f}/min  " + "  ".join(f"{k} {v}" for k, v in picks.items()) +
              f"   gain {100 * (picks['lookahead'] / best - 1):+.1f} %   look-ahead {t_la:.1f} s")


def part_rules_synthetic() -> None:
    """Where look-ahead gains: task times that differ strongly between items (a synthetic map
    whose leave time grows from 0.3 s to 2.5 s across the belt), one arm near its capacity."""
    from pinarms.optim.line import Belt, Rule, TaskMap, poisson_items, simulate
    from pinarms.optim.line.simulate import SimArm

    belt = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)
    du, w = np.linspace(-0.3, 0.3, 13), np.array([-0.15, 0.15])
    m = TaskMap("synthetic", du, w, np.full((13, 2), 0.4), np.tile([0.3, 2.5], (13, 1)), 0.5, 0.1, 0.2, 0.1)
    for rate in (20.0, 36.0, 60.0):
        picks = {}
        for rule in ("first", "shortest", "lookahead"):
            picks[rule] = sum(simulate([SimArm("a", 1.0, (m,))], poisson_items(belt, rate / 60.0, 600.0, seed=s),
                                       0.2, Rule(rule, 5), duration=600.0).picks for s in range(3))
        best = max(picks["first"], picks["shortest"])
        print(f"  synthetic 1 arm {rate:4.0f}/min  " + "  ".join(f"{k} {v}" for k, v in picks.items()) +
              f"   gain {100 * (picks['lookahead'] / best - 1):+.1f} %")


def _layouts(k: int, rng: np.random.Generator):
    return [(0.6 + np.concatenate([[0.0], np.cumsum(rng.uniform(0.9, 1.4, 3))]), 0.2) for _ in range(k)]


def _warm_problem():
    from pinarms.optim.line.sizing import SizingProblem
    from pinarms.studies.line import ENOKI, maps_for, scara_line

    spec = scara_line(1, 60.0)
    return SizingProblem({0.2: maps_for(spec)["scara 1"][0]}, 60.0, item=ENOKI, seeds=(0, 1, 2, 3), duration=600.0)


def _warm() -> None:
    """One small evaluation: imports, first-call costs; run in this process and on each worker alike."""
    from pinarms.optim.line.sizing import evaluate_layouts

    evaluate_layouts(_warm_problem(), _layouts(1, np.random.default_rng(99)))


def _where_the_time_goes(stream: list, wall: float) -> str:
    """From Dask's task stream of one parallel run: each worker's compute time, the wait before the
    first task started, the tail (one worker done, the other still computing) and the rest
    (client, transfers, result gathering)."""
    spans = [(t["worker"], t["startstops"]) for t in stream]
    busy: dict = {}
    first, last, ends = np.inf, -np.inf, {}
    for worker, ss in spans:
        for s in ss:
            if s["action"] != "compute":
                continue
            busy[worker] = busy.get(worker, 0.0) + s["stop"] - s["start"]
            first, last = min(first, s["start"]), max(last, s["stop"])
            ends[worker] = max(ends.get(worker, -np.inf), s["stop"])
    tail = max(ends.values()) - min(ends.values()) if len(ends) > 1 else 0.0
    compute = max(busy.values()) if busy else 0.0
    return (f"compute per worker {', '.join(f'{v:.2f}' for v in busy.values())} s, makespan {last - first:.2f} s, "
            f"tail {tail:.2f} s, outside the workers' compute {wall - compute:.2f} s")


#: Dask settings of the sizing benchmark's workers: no statistical profiler (a thread taking the
#: GIL every 10 ms to sample the task's stack; ``sizing profiled`` keeps it on to compare).
QUIET_WORKERS = {"distributed.worker.profile.enabled": False}


def part_sizing(rounds: int = 3) -> None:
    """Serial and two workers interleaved (serial, dask, serial, dask, ...) on equally warm
    processes: the machine is shared, so each ratio compares runs a few seconds apart; the load
    average (1 min) is printed with each round, and where the parallel time went (Dask's task
    stream: compute per worker, the tail, the rest)."""
    import os

    from dask.distributed import Client, LocalCluster, get_task_stream

    from pinarms.optim.line.sizing import evaluate_layouts

    problem = _warm_problem()
    layouts = _layouts(24, np.random.default_rng(0))
    if len(sys.argv) > 2 and sys.argv[2].isdigit():
        rounds = int(sys.argv[2])
    import dask

    quiet = {} if "profiled" in sys.argv else QUIET_WORKERS
    with dask.config.set(quiet), LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1",
                                              dashboard_address=None, processes=True) as cluster, \
            Client(cluster) as client:
        _warm()
        client.run(_warm)  # both sides warm before any clock starts
        print(f"[sizing] workers' statistical profiler {'on' if not quiet else 'off'} "
              f"(distributed.worker.profile.enabled)", flush=True)
        ratios, same = [], True
        for k in range(rounds):
            load = os.getloadavg()[0]
            t, c = time.perf_counter(), time.process_time()
            serial = evaluate_layouts(problem, layouts)
            t_serial, c_serial = time.perf_counter() - t, time.process_time() - c
            w0 = client.run(time.process_time)
            with get_task_stream(client) as ts:
                t, c = time.perf_counter(), time.process_time()
                parallel = evaluate_layouts(problem, layouts, scheduler=client)
                t_dask, c_client = time.perf_counter() - t, time.process_time() - c
            w1 = client.run(time.process_time)
            c_workers = [w1[a] - w0[a] for a in w0]
            same &= bool(np.array_equal(serial, parallel))
            ratios.append(t_serial / t_dask)
            # CPU seconds: what each side computed; wall / CPU shows the share of the cores it got
            print(f"[sizing] round {k + 1} (load average {load:.1f} -> {os.getloadavg()[0]:.1f}): {len(layouts)} "
                  f"layouts x {len(problem.seeds)} seeds (4 SCARAs, 60/min, 600 s), one task per layout: serial "
                  f"{t_serial:.2f} s wall ({c_serial:.2f} s CPU), 2 workers {t_dask:.2f} s wall (CPU per worker "
                  f"{', '.join(f'{x:.2f}' for x in c_workers)} s, client {c_client:.2f} s), ratio "
                  f"{t_serial / t_dask:.2f}, in CPU terms {c_serial / max(c_workers):.2f}", flush=True)
            print(f"[sizing]   parallel: {_where_the_time_goes(ts.data, t_dask)}", flush=True)
    print(f"[sizing] ratios {', '.join(f'{r:.2f}' for r in ratios)}; identical: {same}")


def tray_scene():
    """The CLI's tray run: seed 000's SCARA of the study's line (belt 0.2 m/s), trays every 0.3 m at
    0.1 m/s, 2 slots, on a belt along the item belt through its box (``belt run --trays 0.3,0.1,2``)."""
    from dataclasses import replace

    from pinarms.optim.line.trays import trays_beside
    from pinarms.studies.line import scara_line

    spec = scara_line(1, 10.0, seeds=(0, 1), duration=300.0)
    trays = trays_beside(spec.belt, spec.stations[0].place.position, 0.3, 0.1, 2)
    return replace(spec, trays=trays)


def part_trays(grid=(10, 5, 8)) -> None:
    """``trays [NU,NW,NV] [coarse]``: ``coarse`` leaves out the box map's approach times."""
    from pinarms.optim.line.map_request import TrayMapRequest
    from pinarms.optim.line.tray_maps import build_tray_map, tray_map_error
    from pinarms.studies.line import maps_for

    if len(sys.argv) > 2:  # python benchmarks/line.py trays NU,NW,NV
        grid = tuple(int(x) for x in sys.argv[2].split(","))
    spec = tray_scene()
    st, belt, trays, kind = spec.stations[0], spec.belt, spec.trays["scara 1"], spec.stream.types[0]
    fine = None if "coarse" in sys.argv else maps_for(spec)[st.name][0]
    t = time.perf_counter()
    m = build_tray_map(TrayMapRequest(st, belt, trays, spec.tracking, mass=kind.mass, item_height=kind.size[2],
                                      nu=grid[0], nw=grid[1], nv=grid[2], approach_map=fine)).task_map
    ok = np.isfinite(m.transfer + m.back)
    print(f"tray map {m.du.size} x {m.w.size} x {m.dv.size} ({'approach from the box map' if fine else 'coarse'}): "
          f"{time.perf_counter() - t:.1f} s, {ok.mean():.0%} of nodes feasible, dv {np.round(m.dv, 3).tolist()} m")
    e = tray_map_error(m, st, belt, trays, spec.tracking, n=100, item_height=kind.size[2], seed=11)
    r = e.relative
    print(f"tray map error, {r.size} random picks (seed 11): mean {100 * r.mean():.3f} %, "
          f"p95 {100 * np.percentile(r, 95):.3f} %, max {100 * r.max():.3f} % ({e.planning_seconds:.1f} s)")
    worst = e.points[np.argsort(r)[-3:]]
    print("worst points (du, w, dv):", np.round(worst, 3).tolist())


def _mushroom():
    from pinarms.optim.line import Belt, PlaceBox, Station
    from pinarms.robots.cell import load_cell

    cell = load_cell("mushroom_line")
    belt = Belt((-1.0, 0.0, 0.80), speed=0.1, width=0.30, length=2.0)
    st = [Station(n, cell.arm(n).robot, cell.arm(n).base_to_world, PlaceBox((0.22, s * 0.68, 0.93), f"{n} box"))
          for n, s in (("left", 1.0), ("right", -1.0))]
    return cell, belt, st


def part_fixtures() -> None:
    from pinarms.optim.line import MapRequest, TrackingSpec, build_task_map
    from pinarms.optim.line.fixtures import _CHECKS, fixture_check

    cell, belt, st = _mushroom()
    kw = dict(mass=0.15, item_height=0.04, nu=24, nw=7)
    print("[fixtures] mushroom_line's left SCARA, 24 x 7 grid on both elbows, clearance 10 mm, serial")
    for label in ("no cell", "fast + exact", "exact alone", "no cell", "fast + exact", "exact alone"):
        _CHECKS.clear()
        if label == "exact alone":
            fixture_check(cell, "left", 0.01).fast = None
        t = time.perf_counter()
        m = build_task_map(MapRequest(st[0], belt, TrackingSpec(), cell=None if label == "no cell" else cell,
                                      clearance=0.01, **kw)).task_map
        dt = time.perf_counter() - t
        check = None if label == "no cell" else fixture_check(cell, "left", 0.01)
        extra = "" if check is None else f"   checks {check.seconds:5.1f} s   {check.counts}"
        print(f"  {label:13s} {dt:6.1f} s   feasible nodes {int(np.isfinite(m.branch_approach).sum())}"
              f"   fixture-infeasible {m.fixture_infeasible}{extra}")


def part_neighbours() -> None:
    from pinarms.optim.line import ItemType, MapRequest, TrackingSpec, build_task_map, poisson_items, simulate
    from pinarms.optim.line.neighbours import NeighbourGuard
    from pinarms.optim.line.simulate import SimArm

    cell, belt, st = _mushroom()
    enoki = ItemType("enoki bunch", 0.15, (0.12, 0.06, 0.04))
    maps = {s.name: (build_task_map(MapRequest(s, belt, TrackingSpec(), mass=0.15, item_height=0.04, nu=12,
                                               nw=5)).task_map,) for s in st}
    arms = [SimArm(s.name, float(belt.to_belt(s.base_to_world[:3, 3])[0]), maps[s.name]) for s in st]
    items = poisson_items(belt, 0.5, 120.0, types=(enoki,), seed=3)
    print(f"[neighbours] mushroom_line's two facing SCARAs, 30 items/min Poisson, 120 s: {len(items)} items")
    for fast in (True, False, True, False):
        guard = NeighbourGuard(cell, st, belt, TrackingSpec(), (enoki,), clearance=0.01,
                               maps={a.name: a.maps for a in arms}, yaws=items.yaw)
        guard.fast = fast
        t = time.perf_counter()
        r = simulate(arms, items, belt.speed, "first", duration=120.0, width=belt.width, guard=guard)
        dt = time.perf_counter() - t
        print(f"  {'fast + exact' if fast else 'exact alone':13s} {dt:6.2f} s   picks {int((r.picked_by >= 0).sum())}"
              f"   checks {guard.checks}   {guard.counts if fast else ''}")


def _in_python(rule):
    """``rule`` as a rule object the compiled loop does not know: the same choices, in the Python loop."""
    from pinarms.optim.line.rules import AssignmentRule

    class InPython(AssignmentRule):
        name, needs_width = rule.name, rule.needs_width
        looks_beyond = rule.looks_beyond

        def prefer(self, d):
            return rule.prefer(d)

        def takes(self, arm, n_arms, index, w, width):
            return rule.takes(arm, n_arms, index, w, width)

    return InPython()


def _goal(label: str, value: float, goal: float, unit: str, reason: str) -> None:
    verdict = "met" if value <= goal else f"NOT met: {value / goal:.1f}x the goal ({reason})"
    print(f"  goal {label}: {value:.3g} {unit} against <= {goal:g} {unit}: {verdict}")


def part_speed() -> None:
    import os

    from threadpoolctl import threadpool_limits

    from pinarms.optim.line import Rule, simulate
    from pinarms.optim.line.api import sim_arms
    from pinarms.optim.line.sim_arm import arm_states
    from pinarms.optim.line.sim_compiled import run_compiled

    spec, maps = _scara(4, 120.0)
    items = spec.stream.items(spec.belt, 0)
    arms = sim_arms(spec, maps)
    run = dict(duration=3600.0, width=spec.belt.width)
    print(f"[speed] 4 SCARAs, 120 items/min Poisson, 1 h: {len(items)} items; load average {os.getloadavg()[0]:.1f}")
    with threadpool_limits(1):
        simulate(arms, items, spec.belt.speed, "first", **run)  # numba's cache loaded, imports done
        t = time.perf_counter()
        states = arm_states(sorted(arms, key=lambda a: a.u_base), items, spec.belt.speed)
        print(f"  item rows (the maps read at every item, shared by the four arms): {time.perf_counter() - t:.3f} s")
        worst, t_la = ("", 0.0, 0.0), 0.0
        for name in ("first", "nearest", "shortest", "bands", "split", "lookahead"):
            rule = Rule(name, 8).build()
            times: dict = {"python": [], "compiled": [], "loop": []}
            runs = {}
            for side in ("python", "compiled", "loop", "python", "compiled", "loop"):
                t = time.perf_counter()
                if side == "loop":
                    run_compiled(states, items, spec.belt.speed, rule.kernel_form(), spec.belt.width)
                else:
                    runs[side] = simulate(arms, items, spec.belt.speed,
                                          _in_python(rule) if side == "python" else rule, **run)
                times[side].append(time.perf_counter() - t)
            same = all(np.array_equal(getattr(runs["python"], c), getattr(runs["compiled"], c), equal_nan=True)
                       for c in ("picked_by", "meet", "start", "finish"))
            n = runs["compiled"].decisions
            py, co, loop = (min(times[k]) for k in ("python", "compiled", "loop"))
            worst = max(worst, (name, 1e6 * co / n, 1e6 * loop / n), key=lambda x: x[1])
            t_la = co if name == "lookahead" else t_la
            print(f"  {name:9s} {n} decisions: compiled {co:6.3f} s ({1e6 * co / n:5.1f} µs a decision, the loop alone "
                  f"{1e6 * loop / n:5.1f} µs), Python loop {py:6.2f} s ({1e6 * py / n:6.1f} µs), ratio {py / co:5.1f}, "
                  f"same runs: {same}")
    load = os.getloadavg()[0]
    _goal(f"per decision (whole call, worst rule: {worst[0]})", worst[1], 20.0, "µs",
          f"its loop alone takes {worst[2]:.1f} µs a decision (the look-ahead: a branch and bound over up to 8! "
          f"orders), the rest reading the maps at every item; load average {load:.1f} on two cores")
    _goal("look-ahead, horizon 8, one hour of four arms", t_la, 2.0, "s", f"load average {load:.1f}")
    big, bmaps = _scara(7, 240.0, duration=250_000.0)
    items = big.stream.items(big.belt, 0)
    arms = sim_arms(big, bmaps)
    with threadpool_limits(1):
        t = time.perf_counter()
        r = simulate(arms, items, big.belt.speed, "first", duration=250_000.0, width=big.belt.width)
        dt = time.perf_counter() - t
    print(f"  {len(items)} items on seven SCARAs (240 items/min, first in window): {dt:.1f} s, {r.decisions} "
          f"decisions, {r.picks} picks")
    _goal("10^6 items on seven arms", dt, 30.0, "s", f"load average {os.getloadavg()[0]:.1f} on two cores")


PARTS = {"simulate": part_simulate, "maps": part_maps, "rules": part_rules, "synthetic": part_rules_synthetic,
         "sizing": part_sizing, "trays": part_trays, "fixtures": part_fixtures, "neighbours": part_neighbours, "speed": part_speed}

if __name__ == "__main__":
    which = sys.argv[1] if len(sys.argv) > 1 else "all"
    for name, fn in PARTS.items():
        if which in (name, "all"):
            fn()
