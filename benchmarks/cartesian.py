"""Cartesian motion timings: a straight 0.3 m lift of the AUBO-i3, built and time-scaled, beside TOPP-RA.

Run: python benchmarks/cartesian.py
Prints, side by side in one run:
  * building the lift's joint path (IK continuation + tolerance rule) at 1 mm deviation tolerance;
  * time-scaling it under the AUBO-i3's joint speed limits and an acceleration limit of
    2 x the speed limit per second (optim.time_optimal, the reachability analysis written here);
  * toppra on the same sampled path: a cubic spline through the joint path's knots (toppra's
    SplineInterpolator, what a toppra user feeds it), parameterised on a grid of the same size;
  * toppra on our path itself (the adapter optim.toppra_path_duration), on our grid;
  * the reachability analysis alone (optim.topp on the rows at the grid points) beside
    toppra's parameterisation on the same grid: algorithm against algorithm (ours then also
    checks between grid points, verifies the exact joint peaks and composes q(t) exactly);
and the durations, their ratio, and how far the tcp strays from the line on each path
(FK at 10 points per knot interval).
"""

from __future__ import annotations

import timeit

import numpy as np

from pinarms import optim, planning, robots
from pinarms.robots.reach.layout import default_orientation


def best(fn, number: int) -> float:
    """Best of 5 repeats, seconds per call."""
    return min(timeit.repeat(fn, number=number, repeat=5)) / number


def off_line(arm, q: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    p = arm.position(q)
    ab = b - a
    t = np.clip((p - a) @ ab / (ab @ ab), 0.0, 1.0)
    return float(np.linalg.norm(p - (a + t[:, None] * ab), axis=1).max())


def main() -> None:
    import toppra
    import toppra.algorithm
    import toppra.constraint

    arm = robots.load("aubo_i3")
    R = default_orientation(arm)
    poses = np.stack([np.eye(4), np.eye(4)])
    poses[:, :3, :3] = R
    poses[0, :3, 3], poses[1, :3, 3] = [0.35, 0.20, 0.00], [0.35, 0.20, 0.30]
    v = arm.velocity_limit
    a = 2.0 * v
    cons = [planning.JointVelocityConstraint(v), planning.JointAccelerationConstraint(a)]

    def build():
        return planning.cartesian_path(arm, poses, tolerance=1e-3)

    path = build()
    q0 = path.q_knots[0]

    def build_seeded():
        return planning.cartesian_path(arm, poses, tolerance=1e-3, q_start=q0)

    timing = optim.time_optimal(path, cons)
    grid = np.unique(timing.grid)

    def toppra_on_samples():
        spline = toppra.SplineInterpolator(path.breaks, path.q_knots)
        algo = toppra.algorithm.TOPPRA(
            [toppra.constraint.JointVelocityConstraint(np.column_stack([-v, v])),
             toppra.constraint.JointAccelerationConstraint(np.column_stack([-a, a]))],
            spline, gridpoints=np.linspace(0.0, path.length, grid.size), parametrizer="ParametrizeConstAccel")
        return algo.compute_trajectory(0.0, 0.0), spline

    traj_toppra, spline = toppra_on_samples()
    t_build = best(build, 3)
    t_seeded = best(build_seeded, 3)
    t_scale = best(lambda: optim.time_optimal(path, cons), 3)
    t_toppra = best(toppra_on_samples, 3)
    t_adapter = best(lambda: optim.toppra_path_duration(path, v, a, grid), 3)
    from pinarms.optim.topp import topp_profile

    rows = planning.PathRows.concatenate([c.rows(planning.PathSamples.of(path, grid)) for c in cons])
    t_core = best(lambda: topp_profile(rows.a, rows.b, rows.lo, rows.hi, grid), 5)
    t_rows = best(lambda: planning.PathRows.concatenate([c.rows(planning.PathSamples.of(path, grid)) for c in cons]), 5)
    d_adapter = optim.toppra_path_duration(path, v, a, grid)
    d_dense = optim.toppra_path_duration(path, v, a, np.linspace(0.0, path.length, 3001))

    s = np.linspace(0.0, path.length, 10 * (path.breaks.size - 1) + 1)
    dev_ours = off_line(arm, path(s), poses[0, :3, 3], poses[1, :3, 3])
    dev_spline = off_line(arm, spline(s), poses[0, :3, 3], poses[1, :3, 3])

    print(f"AUBO-i3, straight 0.3 m lift, tolerance 1 mm: {path.breaks.size} knots, grid {grid.size} points")
    print(f"{'':<52} {'pinarms':>12} {'toppra':>12} {'ratio':>8}")
    print(f"{'build the joint path (IK along the line)':<52} {t_build * 1e3:9.1f} ms {'-':>12}")
    print(f"{'  ... with q_start (one branch tried)':<52} {t_seeded * 1e3:9.1f} ms {'-':>12}")
    print(f"{'time-scale it (v, a) / toppra on the sampled path':<52} {t_scale * 1e3:9.1f} ms "
          f"{t_toppra * 1e3:9.1f} ms {t_scale / t_toppra:7.2f}x")
    print(f"{'  toppra reading our path (adapter), our grid':<52} {'':>12} {t_adapter * 1e3:9.1f} ms")
    print(f"{'  rows + reachability alone / toppra adapter':<52} {(t_rows + t_core) * 1e3:9.1f} ms "
          f"{t_adapter * 1e3:9.1f} ms {(t_rows + t_core) / t_adapter:7.2f}x")
    print(f"{'build + time-scale / toppra spline + parameterise':<52} {(t_build + t_scale) * 1e3:9.1f} ms "
          f"{t_toppra * 1e3:9.1f} ms {(t_build + t_scale) / t_toppra:7.2f}x")
    print(f"{'duration [s]: ours / toppra on the sampled path':<52} {timing.duration:12.6f} "
          f"{traj_toppra.duration:12.6f} {timing.duration / traj_toppra.duration:7.4f}")
    print(f"{'duration [s]: ours / toppra on our path, our grid':<52} {timing.duration:12.6f} "
          f"{d_adapter:12.6f} {timing.duration / d_adapter:7.4f}")
    print(f"{'duration [s]: ours / toppra on our path, 3001 points':<52} {timing.duration:12.6f} "
          f"{d_dense:12.6f} {timing.duration / d_dense:7.4f}")
    print(f"{'tcp off the line [mm] (FK, 10 per knot interval)':<52} {dev_ours * 1e3:12.4f} {dev_spline * 1e3:12.4f}")
    print("(toppra's spline passes through the same knots; between them it is a cubic, ours the quintic Hermite "
          "with the exact path derivatives)")


if __name__ == "__main__":
    main()
