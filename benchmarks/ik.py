"""Inverse kinematics: batched closed form, numerical solver and ikpy, side by side in one run.

Targets are the FK of random in-limit configurations (reachable by construction); the
numerical solvers start from other random in-limit configurations. Targets of the
analytic part: AUBO-i3 poses per second (batched ``ik_all``), share solved, largest FK
error. Numerical part: ``NumericalIK`` alone (no closed form anywhere: the figure the
issue asks for) on aubo_i3, ur5 and panda: success rate at tol = 1e-10 (m and rad),
checked independently with the batched FK, median and p90 time per solve, starts and
iterations per pose; each arm's poses are solved ``--runs`` times and the run with the
lowest median is reported (the machine is shared: the load average is printed). Then
``Robot.ik`` (closed form first, refined by the numerical solver) for the arms that have
one, and ikpy (the same poses, the same starts, its default optimiser with full
orientation) with its success rate at 1e-6 m / 1e-6 rad and its median time.

    python benchmarks/ik.py [--n-analytic 100000] [--n 1000] [--runs 3] [--ikpy-n 200] [--seed 0]

ikpy is slow (tens of ms per solve); it runs on the first ``--ikpy-n`` poses of each arm.
"""

from __future__ import annotations

import argparse
import os
import time
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from pinarms import robots
from pinarms.robots.ik import NumericalIK


def analytic(n: int, seed: int, repeat: int = 3) -> dict:
    robot = robots.load("aubo_i3")
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
    from pinarms.robots.errors import UnreachableTarget

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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n-analytic", type=int, default=100_000)
    parser.add_argument("--n", type=int, default=1000, help="poses per arm for the numerical solver")
    parser.add_argument("--runs", type=int, default=3, help="runs per arm; the one with the lowest median is shown")
    parser.add_argument("--ikpy-n", type=int, default=200, help="poses per arm given to ikpy (first ones)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    print(f"{os.cpu_count()} cores, {_load()}")
    a = analytic(args.n_analytic, args.seed)
    print(f"analytic ik_all, AUBO-i3, {args.n_analytic} random reachable poses (batched, best of 3)")
    print(f"  poses/s           {a['poses_per_s']:>12,.0f}   (target >= 100,000)")
    print(f"  solved            {100 * a['solved']:>11.3f} %  (target 100 %), mean {a['mean_solutions']:.2f} solutions/pose")
    print(f"  max FK error      {a['max_pos_err']:>12.2e} m, {a['max_rot_err']:.2e} rad (target <= 1e-9 m); all within limits: {a['in_limits']}")
    print()
    print(
        f"numerical IK (NumericalIK alone, no closed-form seed): {args.n} random reachable poses per arm, "
        f"random starts, best of {args.runs} runs; ikpy on the first {args.ikpy_n}"
    )
    header = (
        f"{'arm':<10} {'pinarms ok':>11} {'median ms':>10} {'p90 ms':>8} {'starts':>7} {'iters':>6} {'us/iter':>8} | "
        f"{'ikpy ok':>8} {'median ms':>10} | {'speed-up':>8}"
    )
    print(header)
    print("-" * len(header))
    samples = {}
    for name in ("aubo_i3", "ur5", "panda"):
        robot = robots.load(name)
        q = robot.random_q(args.n, seed=args.seed + 1)
        starts = robot.random_q(args.n, seed=args.seed + 2)
        T = robot.fk(q)
        samples[name] = (robot, T, starts)
        ours = numerical(robot, T, starts, runs=args.runs)
        m = min(args.ikpy_n, args.n)
        peer = ikpy_run(robot, T[:m], starts[:m]) if m > 0 else {"success": float("nan"), "median_ms": float("nan")}
        print(
            f"{name:<10} {100 * ours['success']:>10.1f}% {ours['median_ms']:>10.3f} {ours['p90_ms']:>8.2f} "
            f"{ours['mean_starts']:>7.2f} {ours['mean_iterations']:>6.1f} {ours['us_per_iteration']:>8.1f} | "
            f"{100 * peer['success']:>7.1f}% {peer['median_ms']:>10.2f} | "
            f"{peer['median_ms'] / ours['median_ms']:>7.1f}x"
        )
    print("targets: pinarms >= 99.5 % at tol 1e-10 (m, rad), median <= 1 ms; ikpy success judged at 1e-6 m / 1e-6 rad")
    print()
    print("Robot.ik with the closed-form seed (solution nearest the start, refined to 1e-10), same poses and starts")
    for name in ("aubo_i3", "ur5"):
        robot, T, starts = samples[name]
        r = robot_ik(robot, T, starts, runs=args.runs)
        print(f"{name:<10} {100 * r['success']:>10.1f}% {r['median_ms']:>10.3f} {r['p90_ms']:>8.2f}")
    print(_load())


if __name__ == "__main__":
    main()
