"""optim.topp.torque_rows: the joint torque rows of several samplings from one batched RNEA call.

The rows must be those of :meth:`JointTorqueConstraint.rows` bit for bit (each RNEA column is
computed on its own), and a timing through them must give the same duration.
"""

from __future__ import annotations

import numpy as np

from pinarms import robots
from pinarms.optim.topp.dense_check import rows_at_sets
from pinarms.optim.topp.path_timing import time_optimal
from pinarms.optim.topp.torque_rows import batched, torque_rows
from pinarms.planning import joint_spline
from pinarms.planning.path_constraints import JointVelocityConstraint, PathSamples
from pinarms.planning.torque import JointTorqueConstraint


def _path(arm, seed=5, points=5):
    rng = np.random.default_rng(seed)
    lo, hi = np.maximum(arm.lower, -np.pi), np.minimum(arm.upper, np.pi)
    return joint_spline(lo + (hi - lo) * rng.uniform(0.3, 0.7, size=(points, arm.nq)), robot=arm)


def test_the_rows_of_every_sampling_are_those_of_the_constraint_bit_for_bit():
    arm = robots.load("ur5")
    path = _path(arm)
    con = JointTorqueConstraint(arm)
    assert batched(con)
    rng = np.random.default_rng(1)
    samplings = [PathSamples.of(path, np.sort(rng.uniform(0.0, path.length, k)), side)
                 for k, side in ((7, "right"), (1, "left"), (0, "left"), (30, "left"))]
    for got, smp in zip(torque_rows(con, samplings), samplings):
        want = con.rows(smp)
        for key in ("a", "b", "lo", "hi"):
            assert np.array_equal(getattr(got, key), getattr(want, key))
        assert got.labels == want.labels


def test_a_constraint_with_columns_reads_its_own_joints():
    arm = robots.load("ur5")
    W = np.random.default_rng(2).uniform(-1.0, 1.0, size=(4, arm.nq))
    path = joint_spline(np.hstack([np.zeros((4, 2)), W]))  # two idle columns first, the arm's after
    assert path.n_joints == arm.nq + 2
    con = JointTorqueConstraint(arm, columns=np.arange(2, 2 + arm.nq))
    smp = PathSamples.of(path, np.linspace(0.0, path.length, 9))
    got = rows_at_sets(path, [JointVelocityConstraint(np.ones(path.n_joints)), con], [(smp.s, "right")])[0]
    want = con.rows(smp)
    assert np.array_equal(got.a[:, -arm.nq:], want.a) and np.array_equal(got.hi[:, -arm.nq:], want.hi)


def test_a_timing_under_torque_limits_keeps_its_duration():
    import pinarms.optim.topp.torque_rows as module

    arm = robots.load("ur5")
    path = _path(arm, 9, 6)
    cons = [JointVelocityConstraint(arm.velocity_limit), JointTorqueConstraint(arm, 0.5 * np.asarray(arm.effort_limit))]
    fast = time_optimal(path, cons, grid=100).duration
    original = module.batched
    module.batched = lambda c: False  # every constraint's own rows, sampling by sampling
    try:
        slow = time_optimal(path, cons, grid=100).duration
    finally:
        module.batched = original
    assert fast == slow and fast > 0.0
