"""Inverse kinematics beside the Robotics Toolbox for Python's C++ ``ik_LM`` (when installed) and ikpy, in one run.

Targets are the FK of random in-limit configurations (reachable by construction).

1. Closed form, batched ``ik_all``: UR5 and AUBO-i3 poses per second, branches per pose
   (each once), largest FK error.
2. One target at a time: ``Robot.ik`` (the compiled Levenberg–Marquardt solver, seeded restarts;
   the interpreted path with closed-form branches only if that fails) beside ``ik_LM`` (C++,
   its own random starts, ``tol = 5e-13``), both judged by the same strict check (1e-6 m,
   1e-6 rad, joint limits); median, p95 and mean, after one warm-up call each; interleaved target
   by target (the first tool alternating), so that both see the same load.
3. Batched: ``Robot.ik(T (N, 4, 4))`` per target (total time / N), beside ``ik_LM``'s median
   and mean per target, in ``--rounds`` interleaved rounds (the ratio's median over them, both
   tools' success shares, iterations per target of both).
4. ``NumericalIK`` alone on random starts (no closed form anywhere), and ikpy on the first
   ``--ikpy-n`` poses when installed (ikpy takes tens of ms per solve).

Goals (issue 21, 27): one target at least as fast as ``ik_LM`` at the strict check, 100 % within
limits; batched at least 5x faster per target than ``ik_LM``'s median; ``ik_all`` >= 100 000 poses/s.
Section 3 also prints CPU times (the batch's over all its threads, ``ik_LM``'s per call), which do
not depend on the machine's load as wall times do.

    python benchmarks/ik.py [--n 300] [--n-batch 2000] [--n-analytic 100000] [--ikpy-n 0] [--rounds 3] [--sections 1234]
"""

from __future__ import annotations

import argparse
import functools
import os
import time
import xml.etree.ElementTree as ET

import sys
from pathlib import Path

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parent))
print = functools.partial(print, flush=True)  # noqa: A001 - progress visible when piped
from _peers import FAIRNESS, absent_line, rtb_ets, rtb_version  # noqa: E402

from pinarms import robots  # noqa: E402
from pinarms.errors import UnreachableTarget  # noqa: E402
from pinarms.robots.ik import NumericalIK  # noqa: E402


def analytic(n: int, seed: int, repeat: int = 3, name: str = "aubo_i3") -> dict:
    robot = robots.load(name)
    q = robot.random_q(n, seed=seed)
    T = robot.fk(q)
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        sols = robot.ik_all(T)
        best = min(best, time.perf_counter() - t0)
    counts = np.array([s.shape[0] for s in sols])
    allq = np.concatenate(sols)
    idx = np.repeat(np.arange(n), counts)
    F = robot.fk(allq)
    pos = np.linalg.norm(F[:, :3, 3] - T[idx, :3, 3], axis=1)
    rot = np.linalg.norm(F[:, :3, :3] - T[idx, :3, :3], axis=(1, 2)) / np.sqrt(2.0)
    return {
        "poses_per_s": n / best,
        "solved": float(np.mean(counts > 0)),
        "mean_solutions": float(counts.mean()),
        "max_pos_err": float(pos.max()),
        "max_rot_err": float(rot.max()),
        "in_limits": bool(np.all(robot.within_limits(allq))),
    }


def numerical(robot: robots.Robot, T: np.ndarray, starts: np.ndarray, tol: float = 1e-10, runs: int = 3) -> dict:
    """``NumericalIK.solve`` on every pose from its start; the run with the lowest median time."""
    solver = NumericalIK(robot)
    best = None
    for _ in range(runs):
        times, ok, attempts, iterations = [], 0, [], []
        for k in range(len(T)):
            t0 = time.perf_counter()
            res = solver.solve(T[k], starts[k], tol=tol, seed=k)
            times.append(time.perf_counter() - t0)
            good = res.success and robot.within_limits(res.q, tol=0.0)
            if good:  # check independently with the batched FK
                F = robot.fk(res.q)
                good = np.linalg.norm(F[:3, 3] - T[k, :3, 3]) <= tol and np.linalg.norm(
                    pin.log3(F[:3, :3].T @ T[k, :3, :3])
                ) <= tol
            ok += bool(good)
            attempts.append(res.attempts)
            iterations.append(res.iterations)
        run = {
            "success": ok / len(T),
            "median_ms": 1e3 * float(np.median(times)),
            "p90_ms": 1e3 * float(np.quantile(times, 0.9)),
            "mean_starts": float(np.mean(attempts)),
            "mean_iterations": float(np.mean(iterations)),
            "us_per_iteration": 1e6 * float(np.sum(times)) / max(1, int(np.sum(iterations))),
        }
        if best is None or run["median_ms"] < best["median_ms"]:
            best = run
    return best


def robot_ik(robot: robots.Robot, T: np.ndarray, starts: np.ndarray, tol: float = 1e-10, runs: int = 3) -> dict:
    """``Robot.ik`` (closed-form solution nearest the start, refined; numerical fallback)."""
    from pinarms.errors import UnreachableTarget

    best = None
    for _ in range(runs):
        times, ok = [], 0
        for k in range(len(T)):
            t0 = time.perf_counter()
            try:
                q = robot.ik(T[k], starts[k], tol=tol, seed=k)
            except UnreachableTarget:
                q = None
            times.append(time.perf_counter() - t0)
            if q is not None and robot.within_limits(q, tol=0.0):
                F = robot.fk(q)
                ok += bool(
                    np.linalg.norm(F[:3, 3] - T[k, :3, 3]) <= tol
                    and np.linalg.norm(pin.log3(F[:3, :3].T @ T[k, :3, :3])) <= tol
                )
        run = {"success": ok / len(T), "median_ms": 1e3 * float(np.median(times)), "p90_ms": 1e3 * float(np.quantile(times, 0.9))}
        if best is None or run["median_ms"] < best["median_ms"]:
            best = run
    return best


def _chain_elements(robot: robots.Robot) -> list[str]:
    """URDF link/joint names from the root link to the tcp link (ikpy's ``base_elements``)."""
    root = ET.fromstring(robot.urdf_text)
    parent_joint = {j.find("child").get("link"): j for j in root.findall("joint")}
    link = robot.model.frames[robot.frame_id("tcp")].name
    path = [link]
    while link in parent_joint:
        joint = parent_joint[link]
        link = joint.find("parent").get("link")
        path = [link, joint.get("name")] + path
    return path


def ikpy_run(robot: robots.Robot, T: np.ndarray, starts: np.ndarray) -> dict:
    from ikpy.chain import Chain

    elements = _chain_elements(robot)
    path = robot.urdf_path
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = Chain.from_urdf_file(str(path), base_elements=elements, symbolic=False)
        mask = [link.joint_type in ("revolute", "prismatic", "continuous") for link in chain.links]
        chain = Chain.from_urdf_file(
            str(path), base_elements=elements, symbolic=False, active_links_mask=mask
        )
    names = [link.name for link in chain.links]
    cols = [names.index(j) for j in robot.joint_names]
    times, ok = [], 0
    for k in range(len(T)):
        init = np.zeros(len(chain.links))
        init[cols] = starts[k]
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sol = chain.inverse_kinematics_frame(T[k], initial_position=init, orientation_mode="all")
        times.append(time.perf_counter() - t0)
        q = np.asarray(sol)[cols]
        F = robot.fk(q)
        pe = np.linalg.norm(F[:3, 3] - T[k, :3, 3])
        re = np.linalg.norm(pin.log3(F[:3, :3].T @ T[k, :3, :3]))
        ok += bool(pe <= 1e-6 and re <= 1e-6 and robot.within_limits(q))
    return {"success": ok / len(T), "median_ms": 1e3 * float(np.median(times))}


def _load() -> str:
    try:
        return "load average %.2f %.2f %.2f" % os.getloadavg()
    except OSError:
        return "load average unavailable"


def strict_ok(robot, q, T, tol: float = 1e-6) -> bool:
    """FK of ``q`` within ``tol`` m and ``tol`` rad of ``T`` and ``q`` within the joint limits (no tolerance)."""
    if q is None or not np.all(np.isfinite(q)) or not robot.within_limits(q, tol=0.0):
        return False
    F = robot.fk(q)
    return bool(np.linalg.norm(F[:3, 3] - T[:3, 3]) <= tol and np.linalg.norm(pin.log3(F[:3, :3].T @ T[:3, :3])) <= tol)


def one_at_a_time(robot, ets, T) -> dict:
    """Median, p95, success share, mean [s] (and, for ik_LM, the median CPU time of a call) of single solves.

    Interleaved target by target (which tool goes first alternates), so that a burst of load
    lands on both tools alike instead of on one whole side.
    """
    ours, ok = [], 0
    times, cpu, rok, its, searches = [], [], 0, [], []

    def pinarms_call(k: int) -> None:
        nonlocal ok
        t0 = time.perf_counter()
        try:
            q = robot.ik(T[k], seed=k)
        except UnreachableTarget:
            q = None
        ours.append(time.perf_counter() - t0)
        ok += strict_ok(robot, q, T[k])

    def rtb_call(k: int) -> None:
        nonlocal rok
        t0, c0 = time.perf_counter(), time.thread_time()
        sol = ets.ik_LM(T[k], tol=5e-13, joint_limits=True)
        cpu.append(time.thread_time() - c0)
        times.append(time.perf_counter() - t0)
        rok += strict_ok(robot, np.asarray(sol[0], dtype=float), T[k])
        its.append(getattr(sol, "iterations", np.nan))
        searches.append(getattr(sol, "searches", np.nan))

    for k in range(len(T)):
        calls = (pinarms_call,) if ets is None else ((pinarms_call, rtb_call) if k % 2 == 0 else (rtb_call, pinarms_call))
        for call in calls:
            call(k)
    out = {"pinarms": (np.median(ours), np.quantile(ours, 0.95), ok / len(T), np.mean(ours))}
    if ets is not None:
        out["rtb"] = (np.median(times), np.quantile(times, 0.95), rok / len(T), np.mean(times), np.median(cpu))
        out["rtb_work"] = (float(np.mean(its)), float(np.mean(searches)))
    return out


#: pinarms' tolerance per error (position [m], rotation [rad]) at which ``|e| <= 1e-6``, ik_LM's own criterion
#: at ``tol = 5e-13`` (it tests 1/2 |e|^2 with e the 6-vector of both errors)
SAME_AS_IK_LM = 1e-6 / np.sqrt(2.0)


def batch(robot, T, repeat: int = 2, tol: float = 1e-10) -> tuple[float, float, float]:
    """Wall time per target [s] (best of ``repeat``), success share, CPU time per target [s] (all threads)."""
    best, cpu, q = np.inf, np.inf, None
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        q = robot.ik(T, tol=tol)
        best = min(best, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    ok = np.mean([strict_ok(robot, q[k], T[k]) for k in range(len(T))])
    return best / len(T), ok, cpu / len(T)


def closed_form(n: int, seed: int) -> None:
    """Section 1: batched ``ik_all`` of the two UR-type arms."""
    print(f"1. closed form, batched ik_all, {n:,} random reachable poses (best of 3)")
    for name in ("ur5", "aubo_i3"):
        a = analytic(n, seed, name=name)
        print(f"  {name:<8} {a['poses_per_s']:>10,.0f} poses/s (goal >= 100,000)  solved {100 * a['solved']:.2f} %  "
              f"{a['mean_solutions']:.2f} branches/pose  max FK error {a['max_pos_err']:.1e} m {a['max_rot_err']:.1e} rad  "
              f"within limits: {a['in_limits']}")
    print()


def single_targets(samples: dict, n: int) -> None:
    """Section 2: one target at a time, pinarms beside ik_LM."""
    print(f"2. one target at a time, {n} random reachable poses per arm, strict check (1e-6 m, 1e-6 rad, limits); "
          "interleaved target by target")
    print(f"  {'arm':<9} {'pinarms median':>15} {'p95':>8} {'mean':>8} {'ok':>7} | {'ik_LM median':>13} {'p95':>8} "
          f"{'mean':>8} {'ok':>7} | {'ik_LM/pinarms median, mean':>26}")
    for name, (robot, T, ets) in samples.items():
        r = one_at_a_time(robot, ets, T[:n])
        med, p95, ok, mean = r["pinarms"]
        line = f"  {name:<9} {med * 1e3:13.3f}ms {p95 * 1e3:7.2f}ms {mean * 1e3:7.3f}ms {100 * ok:6.1f}%"
        if "rtb" in r:
            rm, rp, rok, rmean, _ = r["rtb"]
            line += (f" | {rm * 1e3:11.3f}ms {rp * 1e3:7.2f}ms {rmean * 1e3:7.3f}ms {100 * rok:6.1f}% | "
                     f"{rm / med:12.2f}x {rmean / mean:12.2f}x")
        print(line + "   (goal: ratio >= 1)")
    print()


def batched_rounds(samples: dict, n_batch: int, n_peer: int, rounds: int) -> None:
    """Section 3: batched ``Robot.ik`` beside ``ik_LM`` one target at a time, in interleaved rounds (each round,
    arm after arm: the batch at pinarms' default tolerance, the batch at ik_LM's, then the ``ik_LM`` calls); the
    median ratio per arm over the rounds."""
    print(f"3. batched Robot.ik(T (N, 4, 4)), N = {n_batch}, time per target (best of 2) beside ik_LM one target at a "
          f"time (the first {n_peer} targets, measured again in each round): its median per call; CPU: the batch's "
          f"(all threads) per target beside ik_LM's median per call. {rounds} interleaved rounds. pinarms at tol 1e-10 "
          f"(its default, stricter than ik_LM) and at tol {SAME_AS_IK_LM:.3g} per error (|e| <= 1e-6, ik_LM's criterion)")
    rows = {name: {"1e-10": [], "same": [], "cpu": [], "cpu_same": [], "ok": [], "ok_same": [], "peer_ok": []}
            for name in samples}
    for r in range(rounds):
        for name, (robot, T, ets) in samples.items():
            row = rows[name]
            per, ok, cpu = batch(robot, T[:n_batch])
            per_same, ok_same, cpu_same = batch(robot, T[:n_batch], tol=SAME_AS_IK_LM)
            row["ok"].append(ok)
            row["ok_same"].append(ok_same)
            line = (f"  round {r + 1}  {name:<9} {per * 1e6:6.1f} / {per_same * 1e6:6.1f} us/target (tol 1e-10 / same), "
                    f"CPU {cpu * 1e6:5.1f} / {cpu_same * 1e6:5.1f} us, ok {100 * ok:6.2f} / {100 * ok_same:6.2f}%")
            if ets is not None:
                peer = one_at_a_time(robot, ets, T[:n_peer])["rtb"]
                row["1e-10"].append(peer[0] / per)
                row["same"].append(peer[0] / per_same)
                row["cpu"].append(peer[4] / cpu)
                row["cpu_same"].append(peer[4] / cpu_same)
                row["peer_ok"].append(peer[2])
                line += (f" | ik_LM median {peer[0] * 1e6:6.1f} us (CPU {peer[4] * 1e6:6.1f} us), ok {100 * peer[2]:5.1f}% | "
                         f"ratio {row['1e-10'][-1]:5.2f}x / {row['same'][-1]:5.2f}x, CPU {row['cpu'][-1]:5.2f}x / "
                         f"{row['cpu_same'][-1]:5.2f}x")
            print(line + f"  ({_load()})")
    print("  per arm, over the rounds (ratio: ik_LM's median per call / pinarms' batch per target):")
    for name, (robot, T, ets) in samples.items():
        row = rows[name]
        its = NumericalIK(robot).solve_batch(T[:n_batch], seed=0).iterations / n_batch
        its_same = NumericalIK(robot).solve_batch(T[:n_batch], seed=0, tol=SAME_AS_IK_LM).iterations / n_batch
        line = (f"  {name:<9} ok {100 * min(row['ok']):.2f} / {100 * min(row['ok_same']):.2f}% (lowest round), "
                f"{its:5.2f} / {its_same:5.2f} iterations per target")
        if row["1e-10"]:
            peer_its, searches = one_at_a_time(robot, ets, T[:n_peer])["rtb_work"]
            med, med_same = float(np.median(row["1e-10"])), float(np.median(row["same"]))
            line += (f" | ik_LM ok {100 * min(row['peer_ok']):.1f}%, {peer_its:5.1f} iterations, {searches:4.2f} searches "
                     f"per target | median ratio {med:5.2f}x at 1e-10, {med_same:5.2f}x at the same tolerance "
                     f"(rounds {min(row['same']):.2f}-{max(row['same']):.2f}x; goal >= 5x: "
                     f"{'met' if med_same >= 5.0 else 'not met'}), CPU {float(np.median(row['cpu'])):5.2f}x / "
                     f"{float(np.median(row['cpu_same'])):5.2f}x")
        print(line)
    print(f"  ({_load()}, {os.cpu_count()} cores. The batch runs on {min(4, os.cpu_count() or 1)} threads: with its "
          "cores free, its wall time per target is its CPU time / threads; on a loaded machine a long batch gets a "
          "smaller share of the cores than one short ik_LM call, so a gap in the wall-time ratio there is the load's)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=300, help="targets per arm, one at a time")
    parser.add_argument("--n-batch", type=int, default=2000, help="targets per arm, batched")
    parser.add_argument("--n-analytic", type=int, default=100_000)
    parser.add_argument("--arms", nargs="+", default=["panda", "ur5", "aubo_i3"])
    parser.add_argument("--runs", type=int, default=1, help="runs of the NumericalIK-alone table")
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds of the batched comparison")
    parser.add_argument("--sections", default="1234", help="sections to run, e.g. 3 (default: all)")
    parser.add_argument("--ikpy-n", type=int, default=0, help="poses per arm given to ikpy (first ones; 0: skip)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    version = rtb_version()
    print(f"{os.cpu_count()} cores, {_load()}; " + (f"Robotics Toolbox for Python {version}" if version else absent_line()))
    print(FAIRNESS)
    print()
    if "1" in args.sections:
        closed_form(args.n_analytic, args.seed)
    samples = {}
    for name in args.arms:
        robot = robots.load(name)
        T = robot.fk(robot.random_q(max(args.n, args.n_batch), seed=args.seed + 1))
        ets = rtb_ets(robot)
        samples[name] = (robot, T, ets)
        t0 = time.perf_counter()
        robot.ik(T[-1])  # warm-up, not timed below: the process's first call loads the compiled solver
        if len(samples) == 1:
            print(f"(first Robot.ik call of this process: {time.perf_counter() - t0:.2f} s, numba loading the compiled "
                  "solver from its cache; a fresh install compiles it once, ~1-2.5 min)")
        if ets is not None:
            ets.ik_LM(T[-1], tol=5e-13, joint_limits=True)
    if "2" in args.sections:
        single_targets(samples, args.n)
    if "3" in args.sections:
        batched_rounds(samples, args.n_batch, min(args.n, 300), args.rounds)
        print()
    if "4" in args.sections:
        print(f"4. NumericalIK alone from random starts (tol 1e-10), {args.n} poses per arm"
              + (f"; ikpy on the first {args.ikpy_n}" if args.ikpy_n else ""))
        for name, (robot, T, _) in samples.items():
            starts = robot.random_q(args.n, seed=args.seed + 2)
            ours = numerical(robot, T[: args.n], starts, runs=args.runs)
            line = (f"  {name:<9} {100 * ours['success']:6.1f}%  median {ours['median_ms']:.3f} ms  p90 "
                    f"{ours['p90_ms']:.2f} ms  {ours['mean_starts']:.2f} starts  {ours['mean_iterations']:.1f} iterations  "
                    f"{ours['us_per_iteration']:.1f} us/iteration")
            if args.ikpy_n:
                peer = ikpy_run(robot, T[: args.ikpy_n], starts[: args.ikpy_n])
                line += f" | ikpy {100 * peer['success']:.1f}% median {peer['median_ms']:.2f} ms"
            print(line)
    print(_load(), flush=True)


if __name__ == "__main__":
    main()
