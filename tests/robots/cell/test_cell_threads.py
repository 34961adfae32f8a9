"""One Cell hammered by four threads gives the single-thread answers (issue 29 item 7).

Each thread has its own configurations and its own margins (so the margin-dependent coal
request settings differ between threads at the same moment); the switch interval is
shortened to one microsecond so that threads interleave inside every call.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np

from pinarms import planning
from pinarms.robots.cell import ArmMotion, load_cell

MARGINS = (0.0, 0.004, 0.012, 0.03)


def _motion(cell, k):
    left = cell.arm("left")
    rng = np.random.default_rng(100 + k)
    a, b = left.robot.random_q(2, seed=rng)
    return [ArmMotion("left", planning.multi_quintic([0.0, 0.5], np.array([a, b])))]


def _work(cell, k, Q, motion):
    m = MARGINS[k]
    clearance = cell.clearance(Q)
    return (
        clearance.distance.copy(),
        clearance.pair.copy(),
        np.array([bool(cell.in_collision(q, margin=m)) for q in Q]),
        np.asarray(cell.in_collision(Q, margin=m)).copy(),
        cell.collisions(Q, margin=m).touching,
        cell.check_motion(motion, margin=0.01, clearance=m),
    )


def _same(a, b):
    for x, y in zip(a[:5], b[:5]):
        if isinstance(x, np.ndarray):
            assert np.array_equal(x, y)
        else:
            assert x == y
    ca, cb = a[5], b[5]
    assert (ca.clear, ca.collision_free) == (cb.clear, cb.collision_free)
    assert ca.lower_bound == cb.lower_bound and np.array_equal(ca.clearance, cb.clearance)
    assert (ca.first_contact is None) == (cb.first_contact is None)
    if ca.first_contact is not None:
        assert ca.first_contact.time == cb.first_contact.time and ca.first_contact.pair == cb.first_contact.pair


def test_four_threads_on_one_cell_give_the_single_thread_results(fast_switching):
    line = load_cell("mushroom_line")
    inputs = [(line.random_q(8, seed=k), _motion(line, k)) for k in range(4)]
    expected = [_work(line, k, Q, motion) for k, (Q, motion) in enumerate(inputs)]
    fresh = load_cell("mushroom_line")  # a cell no thread has used yet: its per-thread data start in the threads
    with ThreadPoolExecutor(max_workers=4) as pool:
        for _ in range(2):
            futures = [pool.submit(_work, fresh, k, Q, motion) for k, (Q, motion) in enumerate(inputs)]
            for k, f in enumerate(futures):
                _same(f.result(), expected[k])
