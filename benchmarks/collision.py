"""Collision checks: pinarms against a plain loop of Pinocchio's computeCollisions, side by side.

For each model (two cells, two single arms' self-collision), the same random
configurations are checked by

* the plain loop users write: one ``GeometryData``, ``updateGeometryPlacements`` +
  ``computeCollisions(stop_at_first=True)`` per configuration (its verdicts are also
  compared with a fresh ``GeometryData`` per configuration, the ground truth: Pinocchio's
  default warm-started GJK misses some penetrations);
* the same loop with cold-started GJK (what pinarms compares itself with);
* pinarms one configuration at a time (``cell.in_collision(q)``, ``SelfCollision.in_collision``);
* pinarms batched (one call for all configurations).

Then distances (a ``computeDistances`` loop over every candidate pair against ``cell.clearance``) and the
continuous check of a 4 s two-arm cycle on ``mushroom_line`` (goal: under 0.2 s).

    python benchmarks/collision.py [--n 4000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
import pinocchio as pin

from pinarms import planning, robots
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.robots.collision_requests import cold_start
from pinarms.robots.self_collision import SelfCollision


def best_of(repeat: int, fn):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def plain_loop(model, gm, q_pin, cold: bool) -> np.ndarray:
    data = model.createData()
    gd = pin.GeometryData(gm)
    if cold:
        cold_start(gd)
    out = np.empty(len(q_pin), dtype=bool)
    for k, q in enumerate(q_pin):
        pin.updateGeometryPlacements(model, data, gm, gd, q)
        out[k] = pin.computeCollisions(gm, gd, True)
    return out


def truth(model, gm, q_pin) -> np.ndarray:
    data = model.createData()
    out = np.empty(len(q_pin), dtype=bool)
    for k, q in enumerate(q_pin):
        gd = pin.GeometryData(gm)
        pin.updateGeometryPlacements(model, data, gm, gd, q)
        out[k] = pin.computeCollisions(gm, gd, True)
    return out


def row(name, n_pairs, n, t_plain, t_cold, t_single, t_batch, misses):
    rate = lambda t: n / t  # noqa: E731
    print(f"{name:<22} {n_pairs:>5} {rate(t_plain):>10,.0f} {rate(t_cold):>10,.0f} {rate(t_single):>10,.0f} "
          f"{rate(t_batch):>10,.0f}   x{t_cold / t_single:4.1f}  x{t_cold / t_batch:4.1f}   {misses}")


def two_arm_cycle(cell):
    """Each SCARA: pick on the belt, lift, transfer, lower into its box and back, 4 s, half a cycle apart."""
    up = np.array([0.0, 0.0, -0.13, 0.0])
    out = []
    for name, pick, place in (("left", (-0.05, -0.03, 0.84), (0.22, 0.68, 0.84)),
                              ("right", (0.05, 0.03, 0.84), (0.22, -0.68, 0.84))):
        arm = cell.arm(name)
        qp = arm.robot.ik(arm.to_base(np.array(pick)), position_only=True)
        ql = arm.robot.ik(arm.to_base(np.array(place)), position_only=True)
        out.append(planning.multi_quintic([0.0, 0.4, 1.6, 2.0, 2.4, 3.6, 4.0],
                                          np.array([qp, qp + up, ql + up, ql, ql + up, qp + up, qp])))
    return [ArmMotion("left", out[0], 0.0, 4.0), ArmMotion("right", out[1], 2.0, 4.0)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=4000)
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs each")
    args = parser.parse_args()
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    print(f"{args.n:,} random configurations per model, best of {args.repeat}; {os.cpu_count()} cores, "
          f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print("configurations per second; ratios against the cold-started plain loop; last column: configurations "
          "in collision that Pinocchio's default (warm-started) plain loop reports free")
    print(f"{'model':<22} {'pairs':>5} {'plain':>10} {'plain cold':>10} {'single':>10} {'batched':>10}   "
          f"{'single':>5}  {'batch':>5}   missed")

    cells = {name: load_cell(name) for name in ("aubo_food_station", "mushroom_line")}
    for name, cell in cells.items():
        q = cell.random_q(args.n, seed=0)
        qp = cell.robot.q_to_pinocchio(q)
        gm = cell.collision_model
        t_plain, plain = best_of(args.repeat, lambda: plain_loop(cell.model, gm, qp, cold=False))
        t_cold, cold = best_of(args.repeat, lambda: plain_loop(cell.model, gm, qp, cold=True))
        t_single, single = best_of(args.repeat, lambda: np.array([cell.in_collision(x) for x in q]))
        t_batch, batch = best_of(args.repeat, lambda: cell.in_collision(q))
        ref = truth(cell.model, gm, qp)
        assert (cold == ref).all() and (single == ref).all() and (batch == ref).all(), name
        row(f"cell {name}", len(cell.pairs), args.n, t_plain, t_cold, t_single, t_batch, int((ref & ~plain).sum()))

    for name in ("aubo_i3", "panda"):
        arm = robots.load(name)
        sc = SelfCollision(arm)
        q = arm.random_q(args.n, seed=0)
        qp = arm.q_to_pinocchio(q)
        t_plain, plain = best_of(args.repeat, lambda: plain_loop(arm.model, sc._gm, qp, cold=False))
        t_cold, cold = best_of(args.repeat, lambda: plain_loop(arm.model, sc._gm, qp, cold=True))
        t_single, single = best_of(args.repeat, lambda: np.array([sc.in_collision(x) for x in q]))
        t_batch, batch = best_of(args.repeat, lambda: sc.in_collision(q))
        ref = truth(arm.model, sc._gm, qp)
        assert (cold == ref).all() and (single == ref).all() and (batch == ref).all(), name
        row(f"self-collision {name}", sc.n_pairs, args.n, t_plain, t_cold, t_single, t_batch, int((ref & ~plain).sum()))

    print("\ndistances (smallest over every pair not allowed by design, exact), configurations per second")
    for name, cell in cells.items():
        q = cell.random_q(min(args.n, 2000), seed=1)
        qp = cell.robot.q_to_pinocchio(q)
        gm = cell.collision_model.copy()  # the loop measures every candidate pair (cell.pairs_for(inf))
        gm.removeAllCollisionPairs()
        for p in cell.pairs_for(float("inf")):
            gm.addCollisionPair(pin.CollisionPair(p.index_a, p.index_b))

        def loop():
            data, gd = cell.model.createData(), cold_start(pin.GeometryData(gm), distance_tolerance=1e-10)
            out = np.empty(len(qp))
            for k, x in enumerate(qp):
                pin.updateGeometryPlacements(cell.model, data, gm, gd, x)
                pin.computeDistances(gm, gd)
                out[k] = min(r.min_distance for r in gd.distanceResults)
            return out

        t_loop, ref = best_of(args.repeat, loop)
        t_cl, cl = best_of(args.repeat, lambda: cell.clearance(q).distance)
        err = np.abs(np.where(ref > 0, cl - ref, 0.0)).max()
        print(f"  cell {name:<18} computeDistances loop {len(q) / t_loop:>8,.0f}/s   clearance {len(q) / t_cl:>8,.0f}/s"
              f"   x{t_loop / t_cl:4.1f}   max |difference| {err:.1e} m")

    cell = cells["mushroom_line"]
    motions = two_arm_cycle(cell)
    t_check, result = best_of(args.repeat, lambda: cell.check_motion(motions, margin=0.01))
    print(f"\ncontinuous check, mushroom_line, two SCARAs on 4 s cycles half a cycle apart, margin 10 mm:\n"
          f"  {t_check:.3f} s (goal < 0.2 s): {result.summary()}")


if __name__ == "__main__":
    main()
