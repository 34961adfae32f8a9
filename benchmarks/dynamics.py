"""Dynamics timings, side by side: batched RNEA against a Python loop of Pinocchio's own call.

Run: python benchmarks/dynamics.py
Prints, for the same states, pinarms's batched ``Robot.inverse_dynamics`` (one
``pinocchio.rneaInParallel`` call) and a loop of ``pinocchio.rnea`` (what a user writes
first), per sample and their ratio; then the cost of one torque-limited exact timing
against the kinematic-only one on the same via points (AUBO-i3, 3 kg), and the torque peak
refinement against a 200 001-sample brute force.
"""

from __future__ import annotations

import timeit

import numpy as np
import pinocchio as pin

from pinarms import optim, planning, robots

VIA = np.array([[0.3, -0.4, 1.2, 0.2, 1.57, 0.0],
                [0.3, -0.3, 1.3, 0.3, 1.57, 0.0],
                [-0.9, 0.4, 1.8, 0.5, 1.2, 0.5],
                [-0.9, 0.3, 1.7, 0.4, 1.2, 0.5]])


def best(fn, number: int) -> float:
    """Best of 5 repeats, seconds per call."""
    return min(timeit.repeat(fn, number=number, repeat=5)) / number


def main() -> None:
    for name in ("aubo_i3", "koji_turner"):
        arm = robots.load(name)
        n = 20_000
        rng = np.random.default_rng(0)
        q, qd, qdd = arm.random_q(n, seed=0), rng.normal(size=(n, arm.nq)), rng.normal(size=(n, arm.nq))
        qp = arm.q_to_pinocchio(q)
        data = arm.model.createData()

        def loop() -> np.ndarray:
            return np.array([pin.rnea(arm.model, data, qp[k], qd[k], qdd[k]) for k in range(n)])

        t_batch = best(lambda: arm.inverse_dynamics(q, qd, qdd), 1)
        t_loop = best(loop, 1)
        print(f"{name}: inverse dynamics of {n} states: batched {t_batch / n * 1e6:.2f} us/state, "
              f"loop of pin.rnea {t_loop / n * 1e6:.2f} us/state, ratio {t_loop / t_batch:.2f}x")

    arm = robots.load("aubo_i3")
    t_kin = best(lambda: optim.minimize_time(optim.TimingRequest(VIA, "multi-quintic", arm.velocity_limit, 8.0, method="exact")), 1)
    t_tau = best(lambda: optim.minimize_time(optim.TimingRequest(VIA, "multi-quintic", arm.velocity_limit, 8.0, method="exact",
                                             robot=arm, payload=3.0, torque_limits=True)), 1)
    print(f"exact timing, 3 segments, AUBO-i3: kinematic {t_kin:.3f} s, with torque limits and 3 kg {t_tau:.3f} s "
          f"(ratio {t_tau / t_kin:.2f}x)")
    move = planning.multi_quintic([0.0, 0.35, 0.8, 1.1], VIA)
    loaded = arm.with_payload(3.0)
    t_peak = best(lambda: move.torque_peaks(loaded), 3)
    t = np.linspace(0.0, move.duration, 200_001)
    t_brute = best(lambda: np.abs(move.torques(loaded, t)).max(axis=0), 1)
    gap = np.max(np.abs(move.torque_peaks(loaded).torque / np.abs(move.torques(loaded, t)).max(axis=0) - 1.0))
    print(f"torque peaks of 3 pieces: refined {t_peak * 1e3:.1f} ms, brute force 200 001 samples "
          f"{t_brute * 1e3:.1f} ms (ratio {t_brute / t_peak:.1f}x), values within {gap:.1e}")


if __name__ == "__main__":
    main()
