"""Batched forward kinematics against a Python loop of Pinocchio calls, measured side by side.

Target: 1e6 AUBO-i3 configurations at least 5x faster than the loop (stretch 20x), with
results equal to Pinocchio's within 1e-9 m. The loop is timed on a subset and
extrapolated to the full count (printed as such); both run in this process, one after
the other, so machine load affects them alike.

    python benchmarks/fk.py [--n 1000000] [--loop-n 50000] [--robot aubo_i3]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
import pinocchio as pin

from pinarms import robots


def pinocchio_loop(robot: robots.Robot, q: np.ndarray, frame: str = "tcp") -> np.ndarray:
    """The straightforward way: one framesForwardKinematics call per configuration."""
    model, data = robot.model, robot.model.createData()
    fid = robot.frame_id(frame)
    q_pin = robot.q_to_pinocchio(q)
    out = np.empty((len(q), 4, 4))
    for k in range(len(q)):
        pin.framesForwardKinematics(model, data, q_pin[k])
        out[k] = data.oMf[fid].homogeneous
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="aubo_i3")
    parser.add_argument("--n", type=int, default=1_000_000)
    parser.add_argument("--loop-n", type=int, default=50_000, help="loop subset, extrapolated")
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs each")
    args = parser.parse_args()

    robot = robots.load(args.robot)
    q = robot.random_q(args.n, seed=0)
    sub = q[: args.loop_n]

    best_vec, best_loop = np.inf, np.inf
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        T = robot.fk(q)
        best_vec = min(best_vec, time.perf_counter() - t0)
        t0 = time.perf_counter()
        T_loop = pinocchio_loop(robot, sub)
        best_loop = min(best_loop, (time.perf_counter() - t0) * args.n / len(sub))

    err = np.abs(T[: len(sub)] - T_loop).max()
    pos_err = np.linalg.norm(T[: len(sub), :3, 3] - T_loop[:, :3, 3], axis=1).max()
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    print(f"robot {robot.name}: {args.n:,} configurations, best of {args.repeat}; "
          f"{os.cpu_count()} cores, load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print(f"  pinarms batched FK     : {best_vec:8.3f} s  ({best_vec / args.n * 1e9:7.1f} ns/config)")
    print(f"  Pinocchio Python loop  : {best_loop:8.3f} s  ({best_loop / args.n * 1e9:7.1f} ns/config, "
          f"timed on {len(sub):,} and extrapolated)")
    print(f"  ratio loop / batched   : {best_loop / best_vec:8.1f} x   (target >= 5, stretch 20)")
    print(f"  max |T - T_pinocchio|  : {err:.2e}   max position error {pos_err:.2e} m (target <= 1e-9)")
    if pos_err > 1e-9:
        raise SystemExit("batched FK disagrees with Pinocchio")


if __name__ == "__main__":
    main()
