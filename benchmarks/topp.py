"""Time-optimal path scaling: pinarms' own TOPP-RA beside toppra on one UR5 joint spline.

Run: python benchmarks/topp.py
The path: a C² joint spline of the UR5 through 8 seeded random waypoints
(:func:`planning.joint_spline`), joint velocity limits from the URDF and accelerations of
2 × those per second. Printed side by side in one run (best of 5 repeats each):

  * the whole timing: ``optim.time_optimal`` (grid, profile, checks between the grid
    points, exact joint peaks, q(t) composed exactly) against toppra's ``TOPPRA`` on the
    same path and grid (its ``compute_trajectory``, interpolation scheme, its own spline
    of s(t));
  * algorithm against algorithm: the rows at the grid points and the reachability analysis
    (``optim.topp.topp_profile``) against toppra's ``compute_parameterization`` on the same
    grid;
  * the durations and their ratio (toppra enforces the limits at the grid points only;
    pinarms also between them, hence its small dilation).

toppra is in the test extra; without it the pinarms column is printed alone.
"""

from __future__ import annotations

import timeit

import numpy as np

from pinarms import optim, planning, robots


def best(fn, number: int, repeat: int = 11) -> float:
    """Best of ``repeat`` repeats, seconds per call (the best filters out a busy machine's pauses)."""
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number


def ur5_spline() -> tuple[object, np.ndarray, np.ndarray, object]:
    """The benchmark's path, velocity and acceleration limits (8 waypoints, seed 7)."""
    arm = robots.load("ur5")
    rng = np.random.default_rng(7)
    lo, hi = np.maximum(arm.lower, -np.pi), np.minimum(arm.upper, np.pi)
    waypoints = lo + (hi - lo) * rng.uniform(0.2, 0.8, size=(8, arm.nq))
    path = planning.joint_spline(waypoints, robot=arm)
    v = arm.velocity_limit
    return path, v, 2.0 * v, arm


def toppra_algorithm(path, v: np.ndarray, a: np.ndarray, grid: np.ndarray):
    """toppra's TOPPRA on ``path`` itself (q, q', q'' read through an adapter) and ``grid``."""
    import toppra
    import toppra.algorithm
    import toppra.constraint
    from pinarms.optim.timing.reference import toppra_path

    cons = [toppra.constraint.JointVelocityConstraint(np.column_stack([-v, v])),
            toppra.constraint.JointAccelerationConstraint(np.column_stack([-a, a]))]
    return toppra.algorithm.TOPPRA(cons, toppra_path(path), gridpoints=grid, parametrizer="ParametrizeConstAccel")


def main() -> None:
    from pinarms.optim.topp import topp_profile

    path, v, a, arm = ur5_spline()
    cons = [planning.JointVelocityConstraint(v), planning.JointAccelerationConstraint(a)]
    timing = optim.time_optimal(path, cons)
    grid = np.unique(timing.grid)

    def rows_and_profile():
        rows = planning.PathRows.concatenate([c.rows(planning.PathSamples.of(path, grid)) for c in cons])
        return topp_profile(rows.a, rows.b, rows.lo, rows.hi, grid)

    t_ours = best(lambda: optim.time_optimal(path, cons), 3)
    t_core = best(rows_and_profile, 3)
    d_core = rows_and_profile().duration
    print(f"UR5 joint spline, 8 waypoints, v + a limits: grid {grid.size} points")
    print(f"{'':<48} {'pinarms':>12} {'toppra':>12} {'ratio':>8}")
    try:
        import toppra  # noqa: F401
    except ImportError:
        print(f"{'time_optimal (whole timing)':<48} {t_ours * 1e3:9.2f} ms  toppra not installed")
        print(f"{'rows + profile on the grid':<48} {t_core * 1e3:9.2f} ms")
        print(f"{'duration [s]':<48} {timing.duration:12.6f}")
        return
    import toppra

    toppra.setup_logging("WARNING")
    t_whole = best(lambda: toppra_algorithm(path, v, a, grid).compute_trajectory(0.0, 0.0), 3)
    t_param = best(lambda: toppra_algorithm(path, v, a, grid).compute_parameterization(0.0, 0.0), 3)
    d_toppra = toppra_algorithm(path, v, a, grid).compute_trajectory(0.0, 0.0).duration
    print(f"{'whole timing: time_optimal / TOPPRA trajectory':<48} {t_ours * 1e3:9.2f} ms "
          f"{t_whole * 1e3:9.2f} ms {t_ours / t_whole:7.2f}x")
    print(f"{'rows + profile / compute_parameterization':<48} {t_core * 1e3:9.2f} ms "
          f"{t_param * 1e3:9.2f} ms {t_core / t_param:7.2f}x")
    print(f"{'duration [s]: time_optimal / toppra':<48} {timing.duration:12.6f} "
          f"{d_toppra:12.6f} {timing.duration / d_toppra:7.5f}")
    print(f"{'duration [s]: profile on the grid / toppra':<48} {d_core:12.6f} "
          f"{d_toppra:12.6f} {d_core / d_toppra:7.5f}")


if __name__ == "__main__":
    main()
