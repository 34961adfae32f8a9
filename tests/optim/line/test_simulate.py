"""The simulation against independent references: closed forms and brute-force schedules."""

import itertools

import numpy as np
import pytest

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.items import ItemType, Items, poisson_items, regular_items
from pinarms.optim.line.report import confidence_interval, summarise
from pinarms.optim.line.rules import Rule
from pinarms.optim.line.simulate import SimArm, simulate
from pinarms.optim.line.task_maps import TaskMap

BELT = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)


def const_map(t_a, t_c, du=(0.0, 1e-3), track=0.5, release=0.1, w=(-0.15, 0.15)):
    du, w = np.asarray(du, float), np.asarray(w, float)
    tc = np.broadcast_to(np.asarray(t_c, float), (du.size, w.size)).copy()
    return TaskMap("a", du, w, np.full((du.size, w.size), float(t_a)), tc, track, release, BELT.speed, 0.1)


@pytest.mark.parametrize("task, every", [(1.5, 1), (2.0, 1), (3.0, 2), (4.0, 2), (5.0, 3), (6.5, 4)])
def test_one_arm_regular_pitch_constant_task_is_exact(task, every):
    # one arm, an item every P = 2 s, task time D, a window too short to catch up: the arm
    # takes every k-th item, k = ceil(D / P) (closed form); misses = N - ceil(N / k)
    P, N = 2.0, 50
    m = const_map(0.5, task - 0.5 - 0.6)
    items = regular_items(BELT, P, N * P, w=0.0)
    r = simulate([SimArm("a", 1.0, (m,))], items, BELT.speed, duration=N * P)
    assert len(items) == N
    assert r.picks == -(-N // every)
    assert r.misses == N - -(-N // every)
    assert r.picks_per_minute == pytest.approx(60.0 * r.picks / (N * P), rel=1e-12)
    picked = np.flatnonzero(r.picked_by == 0)
    assert np.all(np.diff(picked) == every)
    # the rendezvous is at the window entry: meet = t0 + u / v exactly
    assert np.allclose(r.meet[picked], items.t0[picked] + 1.0 / BELT.speed, atol=1e-9)


def test_capacity_exceeded_is_a_miss_rate_not_an_error():
    m = const_map(0.8, 0.8, du=np.linspace(-0.3, 0.3, 13))
    items = poisson_items(BELT, 3.0, 300.0, seed=1)  # 180 / min on one arm of about 25 / min
    r = simulate([SimArm("a", 1.0, (m,))], items, BELT.speed, duration=300.0)
    cycle = 0.8 + 0.5 + 0.8 + 0.1
    last_meet = 300.0 + 1.3 / BELT.speed  # the last arrival leaves the window (u = 1.3 m) then
    assert r.picks <= last_meet / cycle + 1  # never faster than one cycle per pick
    assert 0.8 < r.miss_rate < 0.95
    assert 0.97 < r.utilisation[0] <= 1.0  # always busy: overloaded, never idle for long


def _brute_force(items, m, u_base, speed):
    """Most picks (then the earliest end) over every order of every subset, one arm, a map with a
    constant approach time: intercept = max(ready + t_A, t0 + u_min / v) while ≤ t0 + u_max / v."""
    u_min, u_max = u_base + m.du[0], u_base + m.du[-1]
    t_a = m.approach[0, 0]
    tc = m.rows(items.w)[1][:, 0]
    best = (0, 0.0)
    n = len(items)
    for r in range(1, n + 1):
        for seq in itertools.permutations(range(n), r):
            t, ok = 0.0, True
            for i in seq:
                meet = max(t + t_a, items.t0[i] + u_min / speed)
                if meet > items.t0[i] + u_max / speed + 1e-12:
                    ok = False
                    break
                t = meet + m.track + m.release + tc[i]
            if ok and (r, -t) > (best[0], -best[1]):
                best = (r, t)
    return best


@pytest.mark.parametrize("seed", range(6))
def test_look_ahead_matches_brute_force_on_small_cases(seed):
    rng = np.random.default_rng(seed)
    n = 6
    items = Items(np.sort(rng.uniform(0.0, 4.0, n)), rng.uniform(-0.12, 0.12, n), np.zeros(n, int), np.zeros(n),
                  (ItemType("x"),))
    m = const_map(0.4, [[0.3, 2.0]] * 7, du=np.linspace(-0.3, 0.3, 7))  # leave time grows across the belt
    ref = _brute_force(items, m, 1.0, BELT.speed)
    la = simulate([SimArm("a", 1.0, (m,))], items, BELT.speed, Rule("lookahead", horizon=6), duration=4.0)
    first = simulate([SimArm("a", 1.0, (m,))], items, BELT.speed, "first", duration=4.0)
    assert la.picks == ref[0]
    assert first.picks <= ref[0]


def test_look_ahead_gains_where_orders_matter():
    # items far across the belt cost a long leave: ordering by look-ahead picks more of them
    gains = []
    for seed in range(4):
        items = poisson_items(BELT, 0.6, 300.0, seed=seed)
        m = const_map(0.4, [[0.3, 2.5]] * 13, du=np.linspace(-0.3, 0.3, 13))
        arm = [SimArm("a", 1.0, (m,))]
        la = simulate(arm, items, BELT.speed, Rule("lookahead", horizon=5), duration=300.0)
        fi = simulate(arm, items, BELT.speed, "first", duration=300.0)
        gains.append(la.picks - fi.picks)
    assert sum(gains) > 0


def test_bands_and_split_keep_their_share():
    m = const_map(0.5, 0.5, du=np.linspace(-0.3, 0.3, 13))
    items = poisson_items(BELT, 0.5, 200.0, seed=3)
    arms = [SimArm("up", 1.0, (m,)), SimArm("down", 2.0, (m,))]
    r = simulate(arms, items, BELT.speed, "bands", duration=200.0, width=BELT.width)
    took = r.picked_by >= 0
    assert np.all(items.w[took & (r.picked_by == 0)] < 0.0) and np.all(items.w[took & (r.picked_by == 1)] >= 0.0)
    s = simulate(arms, items, BELT.speed, "split", duration=200.0)
    idx = np.flatnonzero(s.picked_by >= 0)
    assert np.all(s.picked_by[idx] == idx % 2)


def test_report_interval_over_seeds():
    m = const_map(0.8, 0.8, du=np.linspace(-0.3, 0.3, 13))
    runs = [simulate([SimArm("a", 1.0, (m,))], poisson_items(BELT, 0.5, 200.0, seed=s), BELT.speed, duration=200.0)
            for s in range(4)]
    f = summarise(runs)
    rates = [r.miss_rate for r in runs]
    assert f.miss_rate == pytest.approx(np.mean(rates))
    assert f.miss_rate_ci[0] <= f.miss_rate <= f.miss_rate_ci[1]
    mean, lo, hi = confidence_interval([1.0, 2.0, 3.0])
    assert (mean, hi - mean) == pytest.approx((2.0, 4.302652729911275 / np.sqrt(3)))  # t(0.975, 2) · s / √n
    assert f.picks_share == pytest.approx((1.0,))
