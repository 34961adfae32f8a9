"""Benchmark of optim/layout in a cell: candidates per second, screened vs not, serial vs 2 workers.

Run: ``python benchmarks/layout.py [--serial 4] [--workers 16] [--no-workers]``. The cell is the
planning scene ``aubo_crate_guard`` (the AUBO-i3 food station with a guard plate over the
crate's near half): picking on the food table and placing in the crate's far half, no lift or
via point clears the plate from most placements, so their cycle ends with a planned transfer
(:mod:`optim.motion.transfer`). Candidates: 1 000 seeded random placements (x, y within ±80 mm
of the scene's base, yaw within ±0.3 rad, the stand carried along); the benchmark times the
first few and extrapolates to 1 000 (stated).

1. **Serial**, one process, interleaved in blocks of two candidates: ``search_layout(...,
   screen=False)`` (every re-planning attempt timed and checked in full) and ``screen=True``
   (attempts rejected by exact distances at their via points and timed states first);
   their outcomes must agree (failure class and cycle time).
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


def _search(cell, cand: np.ndarray, screen: bool, scheduler=None):
    return optim.search_layout(cell, PICK, PLACE, cand, refine=0, carry=("stand",), workspace_samples=2000,
                               chunk_size=1, screen=screen, scheduler=scheduler)


def serial(cell, cand: np.ndarray) -> float:
    """Screened vs not, interleaved in blocks of two; returns the screened candidates per second."""
    spent = {False: 0.0, True: 0.0}
    cpu = {False: 0.0, True: 0.0}
    outcomes: dict[bool, list] = {False: [], True: []}
    for s in range(0, cand.shape[0], 2):
        block = cand[s : s + 2]
        for screen in (False, True):
            t, c = time.perf_counter(), time.process_time()
            res = _search(cell, block, screen)
            spent[screen] += time.perf_counter() - t
            cpu[screen] += time.process_time() - c
            outcomes[screen] += list(zip(res.failure, res.cycle_time))
    n = cand.shape[0]
    same = all(a[0] == b[0] and (a[0] or abs(a[1] - b[1]) <= 1e-9 * abs(a[1]))
               for a, b in zip(outcomes[False], outcomes[True]))
    kinds = sorted({f or "clear" for f, _ in outcomes[True]})
    print(f"serial, {n} candidates ({', '.join(kinds)}); outcomes of both agree: {same}  [{_load()}]")
    for screen in (False, True):
        rate = n / spent[screen]
        print(f"  screen={str(screen):5s}  {spent[screen] / n:6.2f} s/candidate ({cpu[screen] / n:5.2f} s CPU)  "
              f"{rate:6.3f} candidates/s  1 000 placements ≈ {TOTAL / rate / 60:6.1f} min (extrapolated; on two "
              f"idle cores from the CPU time ≈ {TOTAL * cpu[screen] / n / 2 / 60:5.1f} min)")
    print(f"  ratio (not screened / screened): {spent[False] / spent[True]:.2f}x")
    return n / spent[True]


def workers(cell, cand: np.ndarray, serial_rate: float | None) -> None:
    """Screened, on a local Dask cluster of two single-thread workers (start-up counted)."""
    t = time.perf_counter()
    try:
        res = _search(cell, cand, True, scheduler="processes:2")
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

    from pinarms.optim.motion.two_arms import plan_around

    belt, hold, qb0, qb1, A = _belt_query()
    wall: dict[bool, list[float]] = {False: [], True: []}
    kept = set()
    for _ in range(reps):
        for screen in (False, True):
            t = time.perf_counter()
            plan = plan_around(belt, "left", qb0, qb1, {"right": A}, hold=hold, seed=0, time_limit=20.0,
                               screen=screen)
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
    ap.add_argument("--two-arms", type=int, default=5, help="plan_around repetitions per mode (0: skip; default 5)")
    args = ap.parse_args(argv)
    if args.two_arms > 0:
        two_arms(args.two_arms)
    cand = optim.random_candidates(TOTAL, x=(-0.08, 0.08), y=(-0.08, 0.08), z=0.7, yaw=(-0.3, 0.3), seed=1)
    cell = _cell()
    _search(cell, cand[-1:], True)  # compiled kernels loaded, caches warm: not timed
    rate = serial(cell, cand[: args.serial]) if args.serial > 0 else None
    if not args.no_workers and args.workers > 0:
        workers(cell, cand[args.serial : args.serial + args.workers], rate)


if __name__ == "__main__":
    main()
