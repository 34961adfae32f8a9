"""A Robot shared by several threads gives the single-thread answers (IK, FK, Jacobians).

Pinocchio's Data is scratch memory written by every algorithm; a Robot used to share one
between threads, and a thread switch between "compute" and "read" of another thread gave
false ``UnreachableTarget`` (2-7 of 400 Panda targets from 4 threads). The switch interval
is shortened to one microsecond here, so that threads interleave inside every call.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from pinarms import robots
from pinarms.errors import UnreachableTarget


def _work(robot, q, T, k):
    try:
        q_ik = robot.ik(T[k], seed=k)
    except UnreachableTarget:
        q_ik = None
    return (
        q_ik,
        robot.fk(q[k]),
        robot.jacobian(q[k], "tcp"),
        robot.manipulability(q[k]),
        robot.fk(q[k : k + 3]),  # a small batch (Pinocchio per configuration)
        robot.jacobian(q[k : k + 3]),
    )


@pytest.mark.parametrize("name", ["panda", "ur5"])
def test_threads_agree_with_one_thread(name, fast_switching):
    robot = robots.load(name)
    n = 60
    q = robot.random_q(n + 3, seed=11)
    T = robot.fk(q)
    expected = [_work(robot, q, T, k) for k in range(n)]
    assert all(e[0] is not None for e in expected)  # reachable by construction
    with ThreadPoolExecutor(max_workers=4) as pool:
        got = list(pool.map(lambda k: _work(robot, q, T, k), range(n)))
    unreachable = sum(g[0] is None for g in got)
    assert unreachable == 0, f"{unreachable} false UnreachableTarget from 4 threads"
    for k, (e, g) in enumerate(zip(expected, got)):
        for a, b in zip(e, g):
            assert np.array_equal(a, b), f"target {k}: a thread's result differs from the single-thread one"


def test_threads_share_one_numerical_solver_and_big_batches(fast_switching):
    robot = robots.load("panda")
    q = robot.random_q(4000, seed=5)
    fk_ref, jac_ref = robot.fk(q), robot.jacobian(q)
    with ThreadPoolExecutor(max_workers=3) as pool:
        outs = list(pool.map(lambda _: (robot.fk(q), robot.jacobian(q)), range(3)))
    for T, J in outs:
        assert np.array_equal(T, fk_ref) and np.array_equal(J, jac_ref)


def test_a_copied_robot_gets_its_own_scratch_data():
    import copy

    robot = robots.load("ur5")
    twin = copy.copy(robot)
    q = robot.random_q(1, seed=2)[0]
    assert np.array_equal(twin.fk(q), robot.fk(q))
    assert twin._local is not robot._local
