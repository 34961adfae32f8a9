"""Sweeps through the execution layer: serial beside two local Dask workers, side by side.

Parts (each measured in a fresh Python process, so peak memory is the run's own):

1. ``layout``: layout search of the AUBO-i3 over a grid of at least 1 000 base placements
   for one conveyor → crate pick (refinement off: the grid is what is timed). Wall time
   serial vs ``scheduler="processes:2"`` (a LocalCluster of two single-thread worker
   processes, its start-up included), ratio, candidates per second.
2. ``workspace``: a streamed 10⁸-sample AUBO-i3 workspace (``robots.stream_workspace``,
   reductions only) serial vs two workers: wall time and peak resident memory (this
   process; and the largest worker's), and 10⁷ samples serially beside it to show that the
   memory does not grow with the sample count.
3. ``station``: seed 001's station (the paper's Table 2 pick P1 and place P4 on the table,
   45 mm lift): where does the search put the arm? The best placement's pick and place in
   the arm's base frame beside the paper's recommended band (z > 0, 200 mm < r < 500 mm,
   r from the workspace sphere centre (0, 0, 160) mm).

Results must be identical serial and on the workers; the script checks it and says so.

Run: python benchmarks/sweep.py [layout|workspace|station|all] [--quick]
(--quick: smaller sizes for a smoke run; the figures in docs/ come from the full run.)
"""

from __future__ import annotations

import hashlib
import json
import os
import resource
import subprocess
import sys
import time

import numpy as np

PICK = (0.0, 0.0, 0.05)  # conveyor pick [m], line frame
PLACE = (0.30, 0.25, 0.10)  # crate place [m]


def _peaks() -> dict:
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    return {"peak_mb": round(own, 1), "largest_worker_peak_mb": round(children, 1)}


def _noop(task):
    return task


def child_startup() -> dict:
    from pinarms.execution import map_chunks

    t0 = time.perf_counter()
    map_chunks(_noop, [0, 1], scheduler="processes:2")
    return {"wall_s": time.perf_counter() - t0}


def child_layout(scheduler: str | None, quick: bool) -> dict:
    from pinarms import optim, robots

    arm = robots.load("aubo_i3")
    step = 0.1 if quick else 0.05
    cand = optim.grid_candidates(x=(-0.8, 0.8, step), y=(-0.6, 1.0, step))
    t0 = time.perf_counter()
    res = optim.search_layout(optim.LayoutRequest(arm, PICK, PLACE, cand, refine=0, chunk_size=4), scheduler=scheduler)
    wall = time.perf_counter() - t0
    return {"wall_s": wall, "candidates": len(cand), "planned": int(res.ok.sum()), "failures": res.failures(),
            "digest": hashlib.sha256(res.cycle_time.tobytes() + res.order.tobytes()).hexdigest(),
            "best": res.best_placement.tolist(), "best_ppm": res.best_picks_per_minute, **_peaks()}


def child_workspace(scheduler: str | None, n: int) -> dict:
    from pinarms import robots
    from pinarms.robots.reach.workspace_stream import StreamGrid, stream_workspace

    arm = robots.load("aubo_i3")
    t0 = time.perf_counter()
    s = stream_workspace(arm, n, seed=0, grid=StreamGrid(0.01), scheduler=scheduler)  # one grid for every n
    wall = time.perf_counter() - t0
    v = s.voxels
    return {"wall_s": wall, "n": n, "voxel_mm": v.voxel_size * 1000, "voxels": list(v.shape),
            "reachable_m3": v.reachable_volume, "sphere_mm": [*(s.summary.sphere.centre * 1000).tolist(),
                                                              s.summary.sphere.radius * 1000],
            "digest": hashlib.sha256(v.count.tobytes() + v.mean_manipulability.tobytes()
                                     + s.summary.sphere.centre.tobytes()).hexdigest(), **_peaks()}


def child_station(quick: bool) -> dict:
    from pinarms import optim, robots
    from pinarms.papers import SEED001

    arm = robots.load("aubo_i3")
    p1, p2 = (np.array(p) * 1e-3 for p in SEED001.table2_p1_p2_mm)
    place = np.array([42.0, 222.0, 244.0]) * 1e-3  # Table 2's P4 (printed "(42222244)")
    lift = float(p2[2] - p1[2])
    step = 0.1 if quick else 0.05
    cand = optim.grid_candidates(x=(-0.2, 0.7, step), y=(-0.3, 0.7, step), z=(0.0, 0.2, 0.1))
    t0 = time.perf_counter()
    res = optim.search_layout(optim.LayoutRequest(arm, p1, place, cand, lift=lift, refine=0 if quick else 2,
                                                  refine_evaluations=30), scheduler="processes:2")
    wall = time.perf_counter() - t0
    best = res.best_placement
    centre = np.array([0.0, 0.0, 0.16])
    out = {"wall_s": wall, "candidates": len(cand), "planned": int(res.ok.sum()), "lift_m": lift,
           "best_placement": best.tolist(), "best_ppm": res.best_picks_per_minute,
           "grid_best_ppm": float(res.picks_per_minute[res.best_index]),
           "refine_gain": None if res.refinement is None else res.refinement.gain, "points": {}}
    from pinarms.optim.layout.search import points_in_base_frame

    for name, p in (("pick P1", p1), ("place P4", place)):
        b = points_in_base_frame(p[None], best[None])[0, 0]
        out["points"][name] = {"base_frame_mm": (b * 1000).tolist(), "z_mm": b[2] * 1000,
                               "r_centre_mm": float(np.linalg.norm(b - centre) * 1000),
                               "r_axis_mm": float(np.hypot(b[0], b[1]) * 1000)}
    # the grid's planned placements: how many put both points inside the paper's band
    ok = np.flatnonzero(res.ok)
    inside = 0
    for i in ok:
        b = points_in_base_frame(np.vstack([p1, place]), cand[i][None])[0]
        r = np.linalg.norm(b - centre, axis=1)
        inside += int(np.all((b[:, 2] > 0) & (r > 0.2) & (r < 0.5)))
    out["planned_inside_band"] = inside
    # the best placement whose points keep 100 mm from the workspace edge (min_margin=0.1 would
    # rule the others out before planning: the same answer)
    kept = [i for i in res.order if res.ok[i] and res.margin[i] >= 0.1]
    if kept:
        i = kept[0]
        b = points_in_base_frame(np.vstack([p1, place]), cand[i][None])[0]
        out["best_margin_100"] = {"placement": cand[i].tolist(), "ppm": float(res.picks_per_minute[i]),
                                  "margin_mm": float(res.margin[i] * 1000),
                                  "z_mm": (b[:, 2] * 1000).tolist(),
                                  "r_centre_mm": (np.linalg.norm(b - centre, axis=1) * 1000).tolist()}
    out["best_margin_mm"] = float(res.margin[res.best_index] * 1000)
    top = res.order[:20]
    out["top20_inside_band"] = int(sum(
        np.all([(bb[2] > 0) and 0.2 < np.linalg.norm(bb - centre) < 0.5
                for bb in points_in_base_frame(np.vstack([p1, place]), cand[i][None])[0]]) for i in top))
    return out


def _run(part: str, *args: str) -> dict:
    cmd = [sys.executable, __file__, "--child", part, *args]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{part} {args} failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def bench_layout(quick: bool) -> None:
    q = ["--quick"] if quick else []
    serial = _run("layout", "serial", *q)
    two = _run("layout", "processes:2", *q)
    n = serial["candidates"]
    print(f"layout search, AUBO-i3, conveyor pick {PICK} m → crate place {PLACE} m, {n} placements "
          f"(grid, yaw 0), {serial['planned']} planned, failures {serial['failures']}")
    print(f"  serial      {serial['wall_s']:8.1f} s   {n / serial['wall_s']:6.2f} candidates/s   "
          f"peak {serial['peak_mb']:.0f} MB")
    print(f"  2 workers   {two['wall_s']:8.1f} s   {n / two['wall_s']:6.2f} candidates/s   "
          f"peak {two['peak_mb']:.0f} MB (+ largest worker {two['largest_worker_peak_mb']:.0f} MB)")
    print(f"  ratio serial / 2 workers: {serial['wall_s'] / two['wall_s']:.2f}")
    same = serial["digest"] == two["digest"] and serial["best"] == two["best"]
    print(f"  identical results: {'yes' if same else 'NO'}; best placement {np.round(serial['best'], 3).tolist()} m, "
          f"{serial['best_ppm']:.2f} picks/min")


def bench_workspace(quick: bool) -> None:
    n = 10_000_000 if quick else 100_000_000
    small = _run("workspace", "serial", str(n // 10))
    serial = _run("workspace", "serial", str(n))
    two = _run("workspace", "processes:2", str(n))
    print(f"streamed workspace, AUBO-i3 tcp, voxels {serial['voxel_mm']:.0f} mm {serial['voxels']}, "
          f"reachable {serial['reachable_m3']:.3f} m³, hull sphere (x, y, z, r) mm {np.round(serial['sphere_mm'], 1)}")
    print(f"  {n // 10:.0e} serial    {small['wall_s']:8.1f} s   peak {small['peak_mb']:.0f} MB")
    print(f"  {n:.0e} serial    {serial['wall_s']:8.1f} s   peak {serial['peak_mb']:.0f} MB   "
          f"({serial['wall_s'] / (n / 1e8):.1f} s per 1e8 samples)")
    print(f"  {n:.0e} 2 workers {two['wall_s']:8.1f} s   peak {two['peak_mb']:.0f} MB here + largest worker "
          f"{two['largest_worker_peak_mb']:.0f} MB   ratio {serial['wall_s'] / two['wall_s']:.2f}")
    print(f"  identical results: {'yes' if serial['digest'] == two['digest'] else 'NO'}")


def bench_station(quick: bool) -> None:
    r = _run("station", *(["--quick"] if quick else []))
    x, y, z, yaw = r["best_placement"]
    print(f"seed 001 station (pick P1, place P4 of Table 2, lift {r['lift_m'] * 1000:.0f} mm), {r['candidates']} "
          f"placements, {r['planned']} planned, 2 workers, {r['wall_s']:.0f} s")
    print(f"  best: base at ({x * 1000:.0f}, {y * 1000:.0f}, {z * 1000:.0f}) mm of the paper's frame, "
          f"{r['best_ppm']:.2f} picks/min (grid {r['grid_best_ppm']:.2f}, refinement +{r['refine_gain'] or 0:.2f})")
    for name, p in r["points"].items():
        inside = p["z_mm"] > 0 and 200 < p["r_centre_mm"] < 500
        print(f"  {name} in the base frame: z {p['z_mm']:.0f} mm, r {p['r_centre_mm']:.0f} mm from (0, 0, 160) mm "
              f"(horizontal {p['r_axis_mm']:.0f} mm): {'inside' if inside else 'outside'} the paper's band "
              "(z > 0, 200 < r < 500 mm)")
    print(f"  planned placements with both points in the band: {r['planned_inside_band']} of {r['planned']}; "
          f"among the 20 best: {r['top20_inside_band']}; the best's points are {r['best_margin_mm']:.0f} mm from "
          "the workspace edge")
    m = r.get("best_margin_100")
    if m:
        x, y, z, _ = m["placement"]
        print(f"  best with both points >= 100 mm from the workspace edge: base at ({x * 1000:.0f}, {y * 1000:.0f}, "
              f"{z * 1000:.0f}) mm, {m['ppm']:.2f} picks/min; P1, P4 at z {m['z_mm'][0]:.0f}, {m['z_mm'][1]:.0f} mm, "
              f"r {m['r_centre_mm'][0]:.0f}, {m['r_centre_mm'][1]:.0f} mm from (0, 0, 160) mm")


def main(argv: list[str]) -> None:
    if argv[:1] == ["--child"]:
        part, rest = argv[1], argv[2:]
        quick = "--quick" in rest
        rest = [a for a in rest if a != "--quick"]
        if part == "layout":
            out = child_layout(None if rest[0] == "serial" else rest[0], quick)
        elif part == "startup":
            out = child_startup()
        elif part == "workspace":
            out = child_workspace(None if rest[0] == "serial" else rest[0], int(rest[1]))
        else:
            out = child_station(quick)
        print(json.dumps(out))
        return
    quick = "--quick" in argv
    parts = [a for a in argv if not a.startswith("--")] or ["all"]
    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at the start (other work "
          "running on the machine slows both columns and lowers the ratio)")
    print(f"a local cluster of 2 worker processes starts and stops in {_run('startup')['wall_s']:.1f} s "
          "(included in every '2 workers' time below)")
    if parts == ["all"]:
        parts = ["layout", "workspace", "station"]
    for part in parts:
        {"layout": bench_layout, "workspace": bench_workspace, "station": bench_station}[part](quick)
    print(f"load average at the end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":  # worker processes are spawned: the guard is required
    main(sys.argv[1:])
