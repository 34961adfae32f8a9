"""Benchmark of optim/layout in a cell: candidates per second, before and after, serial vs 2 workers.

Run: ``python benchmarks/layout.py [--serial 4] [--workers 16] [--no-workers] [--unscreened]``.
The cell is the planning scene ``aubo_crate_guard`` (the AUBO-i3 food station with a guard
plate over the crate's near half): picking on the food table and placing in the crate's far
half, no lift or via point clears the plate from most placements, so their cycle ends with a
planned transfer (:mod:`optim.motion.transfer`). Candidates: 1 000 seeded random placements
(x, y within ±80 mm of the scene's base, yaw within ±0.3 rad, the stand carried along); the
benchmark times the first few and extrapolates to 1 000 (stated).

1. **Serial**, one process, interleaved in blocks of two candidates: the route before
   (``planning.extrema.COMPILED = False``: the exact timings' peaks by the numpy route), now
   (the peaks compiled; every IK branch of an attempt's waypoints screened first, its move to
   place screened before its move back is timed; ``bound=True``, branch and bound over the
   candidates) and exhaustive (now with ``bound=False``); ``--unscreened`` adds
   ``screen=False`` (every attempt timed and checked in full). Their outcomes must agree
   (failure class and cycle time; the bounded and the exhaustive route exactly). The goal line
   gives 1 000 placements on two idle cores (the CPU time halved) against 60 s, the candidates
   the bounds skip, and that agreement. Per candidate: the search's ``"cycles"`` phase
   (:attr:`LayoutSearch.seconds`); the one-offs (the reach screen and bounds of all 1 000,
   the best placement planned again with its report) are timed apart and added once to the
   extrapolation. The lower bounds of all 1 000 candidates are printed against the best cycle
   found: what branch and bound can skip on this cell.
2. **Two workers** (``scheduler="processes:2"``, a local Dask cluster; its start, the cell
   rebuilt on each worker and the compiled kernels loaded there are counted), screened.
3. **Two arms** (``--two-arms``): ``plan_around`` on the scene ``aubo_two_belt`` (the right
   arm reaches across the shared belt and back; the left arm must wait for it), its start
   delays screened or each proven in turn, interleaved, median of the repetitions.

The machine's load (``os.getloadavg``) is printed with every figure.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

# This file's folder holds scripts named like packages: keep it off the import path.
_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or os.curdir) != _HERE]

import numpy as np  # noqa: E402

from pinarms import optim  # noqa: E402

PICK = np.array([0.40, 0.10, 0.78])  # on the food table [m, world]
PLACE = np.array([0.0, -0.46, 0.78])  # in the crate's far half, beyond the guard plate's edge
TOTAL = 1000


def _load() -> str:
    return "load {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def _cell():
    from pinarms.optim.motion.scenes import scene_path
    from pinarms.robots.cell import load_cell

    return load_cell(scene_path("aubo_crate_guard"))


def _search(cell, cand: np.ndarray, screen: bool, scheduler=None, bound: bool = False):
    return optim.search_layout(optim.LayoutRequest(cell, PICK, PLACE, cand, refine=0, carry=("stand",), workspace_samples=2000,
                               chunk_size=1, screen=screen, bound=bound), scheduler=scheduler)


#: The serial routes: (screen, the attempts' branch and move-to-place screens, bound, compiled peaks).
#: "before" is the code before the compiled peaks (``planning.extrema.COMPILED = False``: every exact
#: timing's peaks by the numpy route), "now" all of it; "exhaustive" is "now" without the bound.
ROUTES = {"before": (True, True, True, False), "now": (True, True, True, True),
          "exhaustive": (True, True, False, True), "unscreened": (False, False, False, True)}
#: Goal of issue 39: 1 000 placements with planned moves within this many seconds on two cores.
GOAL_SECONDS = 60.0


def _route(cell, block: np.ndarray, name: str):
    from pinarms.optim.cycle import in_cell
    from pinarms.planning import extrema

    screen, new_screens, bound, compiled = ROUTES[name]
    in_cell.SCREEN_BRANCHES = in_cell.SCREEN_MOVES = new_screens
    extrema.COMPILED = compiled
    try:
        return _search(cell, block, screen, bound=bound)
    finally:
        in_cell.SCREEN_BRANCHES = in_cell.SCREEN_MOVES = extrema.COMPILED = True


def _one_offs(cell, cand: np.ndarray) -> tuple[float, np.ndarray]:
    """CPU seconds of the reach screen, bounds and margins of all candidates, and their lower bounds [s]."""
    from pinarms.optim.layout import search as layout_search

    planned = layout_search._plan_candidates
    layout_search._plan_candidates = lambda *a, **k: (np.full(cand.shape[0], np.nan), np.full(cand.shape[0], -1),
                                                      np.full(cand.shape[0], np.nan))
    try:  # the search without its cycles: what it does once for all candidates
        res = _search(cell, cand, True, bound=True)
    finally:
        layout_search._plan_candidates = planned
    return res.seconds["screen"][1], res.lower_bound


def serial(cell, cand: np.ndarray, everything: np.ndarray, routes: tuple[str, ...]) -> float:
    """The routes interleaved in blocks of two; returns the candidates per second of the route now."""
    wall = {r: 0.0 for r in routes}
    cpu = {r: 0.0 for r in routes}
    whole = {r: 0.0 for r in routes}
    best = {r: 0.0 for r in routes}
    outcomes: dict[str, list] = {r: [] for r in routes}
    for s in range(0, cand.shape[0], 2):
        block = cand[s : s + 2]
        for r in routes:
            c = time.process_time()
            res = _route(cell, block, r)
            whole[r] += time.process_time() - c
            wall[r] += res.seconds["cycles"][0]
            cpu[r] += res.seconds["cycles"][1]
            best[r] += res.seconds["best"][1]
            outcomes[r] += list(zip(res.failure, res.cycle_time))
    n = cand.shape[0]
    ref = outcomes[routes[0]]
    same = all(all(a[0] == b[0] and (a[0] or abs(a[1] - b[1]) <= 1e-9 * abs(a[1])) for a, b in zip(ref, outcomes[r]))
               for r in routes)
    kinds = sorted({f or "clear" for f, _ in outcomes["now"]})
    screen_cpu, lower = _one_offs(cell, everything)
    once = screen_cpu + best["now"] / (n / 2)
    print(f"serial, {n} candidates ({', '.join(kinds)}); outcomes of every route agree: {same}  [{_load()}]")
    print(f"  once per search: reach screen, bounds and margins of {everything.shape[0]} candidates {screen_cpu:.2f} s "
          f"CPU; the best placement planned again with its report {best['now'] / (n / 2):.2f} s CPU")
    for r in routes:
        rate = n / wall[r]
        total = TOTAL * cpu[r] / n + once
        print(f"  {r:10s}  {wall[r] / n:6.2f} s/candidate ({cpu[r] / n:5.2f} s CPU; whole searches of 2: "
              f"{whole[r] / n:5.2f} s CPU per candidate)  {rate:6.3f} candidates/s  1 000 placements ≈ "
              f"{TOTAL / rate / 60:6.1f} min (extrapolated; on two idle cores from the CPU time ≈ {total / 2 / 60:5.1f} min)")
    if "before" in routes:
        print(f"  CPU per candidate, before / now: {cpu['before'] / cpu['now']:.2f}x")
    times = np.array([t for f, t in outcomes["now"] if not f])
    skip = -1
    if times.size:
        skip = int(np.sum(lower > times.min()))
        print(f"  lower bounds of the {lower.size} candidates {lower.min():.2f} … {lower.max():.2f} s (median "
              f"{np.median(lower):.2f}); cycles planned {times.min():.2f} … {times.max():.2f} s: {skip} of "
              f"{lower.size} candidates' bounds exceed the best cycle found (what branch and bound skips)")
    agree = "exhaustive" in routes and all(a == b or (a[0] == b[0] and abs(a[1] - b[1]) <= 1e-12 * abs(a[1]))
                                           for a, b in zip(outcomes["now"], outcomes["exhaustive"]))
    _goal(TOTAL * cpu["now"] / n + once, skip, agree, n)
    return n / wall["now"]


def _goal(cpu_total: float, skipped: int, agree: bool, n: int) -> None:
    """The goal line: 1 000 placements on two idle cores (CPU / 2) against :data:`GOAL_SECONDS`, skips, agreement."""
    seconds = cpu_total / 2.0
    verdict = "met" if seconds <= GOAL_SECONDS else f"GAP x{seconds / GOAL_SECONDS:.1f}"
    print(f"goal: 1 000 placements with planned moves <= {GOAL_SECONDS:.0f} s on two cores: "
          f"{seconds:.0f} s from the CPU time (two idle cores, the cycles of every candidate split between them) "
          f"{verdict}; candidates skipped by proof {max(skipped, 0)} of {TOTAL}; the bounded and the exhaustive "
          f"search give the same outcomes on the {n} candidates timed: {agree}")
    if seconds > GOAL_SECONDS:
        print("  reason: nearly every placement's cycle ends with a transfer planned round the guard plate (the "
              "lift and via-point attempts fail first), and no sound bound sees that detour before it is "
              "planned (the bounds see the joint travel from pick to place); each candidate still plans "
              "its own cycle: the moved cell, the free cycle's exact timing, the screened attempts, the "
              "planned transfer's search and timing, and its continuous proof")


def workers(cell, cand: np.ndarray, serial_rate: float | None) -> None:
    """Screened, on a local Dask cluster of two single-thread workers (start-up counted)."""
    t = time.perf_counter()
    try:
        res = _search(cell, cand, True, scheduler="processes:2", bound=True)
    except Exception as exc:  # a cluster that cannot start is reported, not fatal
        print(f"2 workers: failed ({type(exc).__name__}: {exc})")
        return
    wall = time.perf_counter() - t
    rate = cand.shape[0] / wall
    ok = sum(1 for f in res.failure if not f)
    print(f"2 workers, {cand.shape[0]} candidates ({ok} clear), screened: {wall:.1f} s wall incl. cluster start, "
          f"{rate:.3f} candidates/s, 1 000 placements ≈ {TOTAL / rate / 60:.1f} min (extrapolated)  [{_load()}]")
    if serial_rate:
        print(f"  speed-up over serial (screened): {rate / serial_rate:.2f}x")


def _belt_query():
    """The shared-belt query of the two-arm tests: (cell, hold, B's start and goal, A's trajectory)."""
    from pinarms import planning
    from pinarms.optim.motion import MotionChecker, load_scene
    from pinarms.optim.motion.goals import ik_candidates
    from pinarms.optim.motion.scenes import Region, region_pose

    belt = load_scene("aubo_two_belt")
    box = Region("r", (0, 0, 0), (1, 1, 1))

    def ik(arm, point, hold):
        checker = MotionChecker(belt, [arm], margin=0.01, hold=hold)
        a = belt.arm(arm)
        q, _ = ik_candidates(a.robot, a.to_base(region_pose(box, np.asarray(point, dtype=float))),
                             belt.neutral[a.q_slice])
        return [x for x in q if checker.state_valid(x)][0]

    def quintic(q0, q1, v):
        return planning.polynomial([0.0, float(np.max(1.875 * np.abs(q1 - q0) / v)) * 1.2], np.stack([q0, q1]), 5)

    hold = belt.neutral.copy()
    hold[belt.arm("right").q_slice] = qa0 = ik("right", (0.0, -0.78, 0.84), hold)
    hold[belt.arm("left").q_slice] = qb0 = ik("left", (0.0, 0.78, 0.84), hold)
    qa1 = ik("right", (0.0, 0.10, 0.84), hold)
    v = belt.arm("right").robot.velocity_limit
    there = quintic(qa0, qa1, v)
    A = there.concatenated(quintic(qa1, qa0, v).shifted(there.duration))
    return belt, hold, qb0, ik("left", (0.05, 0.10, 0.86), hold), A


def two_arms(reps: int) -> None:
    """``plan_around`` with its delays screened or each proven in turn, interleaved."""
    import statistics

    from pinarms.optim.motion import MotionOptions, MotionRequest
    from pinarms.optim.motion.two_arms import plan_around

    belt, hold, qb0, qb1, A = _belt_query()
    wall: dict[bool, list[float]] = {False: [], True: []}
    kept = set()
    for _ in range(reps):
        for screen in (False, True):
            t = time.perf_counter()
            request = MotionRequest(belt, "left", qb0, qb1, hold=hold, options=MotionOptions(seed=0, time_limit=20.0))
            plan = plan_around(request, {"right": A}, screen=screen)
            wall[screen].append(time.perf_counter() - t)
            kept.add((plan.delay, plan.delays_tried, float(plan.trajectory.end_time)))
    print(f"two arms, plan_around on aubo_two_belt, {reps} repetitions; the same delay every time: "
          f"{len(kept) == 1} (delay {sorted(kept)[0][0]:.2f} s)  [{_load()}]")
    for screen in (False, True):
        print(f"  screen={str(screen):5s}  median {statistics.median(wall[screen]) * 1e3:6.0f} ms  "
              f"min {min(wall[screen]) * 1e3:6.0f} ms")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--serial", type=int, default=4, help="candidates timed serially per mode (default 4)")
    ap.add_argument("--workers", type=int, default=16, help="candidates on 2 workers (default 16)")
    ap.add_argument("--no-workers", action="store_true", help="skip the Dask run")
    ap.add_argument("--unscreened", action="store_true", help="also time screen=False (slow: ~16 s per candidate)")
    ap.add_argument("--two-arms", type=int, default=5, help="plan_around repetitions per mode (0: skip; default 5)")
    args = ap.parse_args(argv)
    if args.two_arms > 0:
        two_arms(args.two_arms)
    cand = optim.random_candidates(TOTAL, x=(-0.08, 0.08), y=(-0.08, 0.08), z=0.7, yaw=(-0.3, 0.3), seed=1)
    cell = _cell()
    _search(cell, cand[-1:], True)  # compiled kernels loaded, caches warm: not timed
    routes = ("before", "now", "exhaustive") + (("unscreened",) if args.unscreened else ())
    rate = serial(cell, cand[: args.serial], cand, routes) if args.serial > 0 else None
    if not args.no_workers and args.workers > 0:
        workers(cell, cand[args.serial : args.serial + args.workers], rate)


if __name__ == "__main__":
    main()
