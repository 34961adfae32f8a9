"""The compiled check and search (optim.motion.fast): never clear what the exact checker finds too close,
a found path proven again exactly, seeded, within its time limit; the cover's cylinder-box bound."""

from __future__ import annotations

import time

import numpy as np
import pytest

from pinarms.optim.motion import (SCENES, MotionChecker, MotionLimits, MotionOptions, MotionRequest, load_scene,
                                   plan_motion, scene_queries)
from pinarms.optim.motion.ends import goal_candidates
from pinarms.optim.motion.fast import fast_check, fast_search, fast_shortcut
from pinarms.robots.cell.box_kernel import cylinder_box_gap

from tests.robots.cell.random_shapes import cylinder_and_box

MARGIN = 0.01


@pytest.fixture(scope="module")
def table():
    cell = load_scene("panda_table_box")
    queries, hold = scene_queries("panda_table_box", 4, seed=0, margin=MARGIN)
    checker = MotionChecker(cell, ["panda"], margin=MARGIN, hold=hold)
    goals = [np.array([g.q for g in goal_candidates(checker, ("panda",), q.goal, q.start, k, None) if g.valid])
             for k, q in enumerate(queries)]
    return cell, checker, queries, goals, hold


@pytest.mark.parametrize("name", ["panda_table_box", "aubo_two_belt"])
def test_fast_clear_is_exact_clear_on_random_states_and_edges(table, name):
    """Conservative agreement: every state and edge the cover proves, the exact checker (coal) accepts at the
    margin; the cover rejects only a small share of what the exact checker accepts (counted)."""
    if name == "panda_table_box":
        cell, checker = table[:2]
    else:
        cell = load_scene(name)
        checker = MotionChecker(cell, [SCENES[name].arm], margin=MARGIN)
    fc = fast_check(checker)
    X = cell.random_q(200, seed=21)[:, checker.cols]
    fast = np.array([fc.state_proven(x) for x in X])
    exact = np.array([checker.state_valid(x) for x in X])
    assert not np.any(fast & ~exact)
    excess, _, _ = checker.excess(checker.full(X[fast]))
    assert np.all(excess >= 0.0)
    assert fast.sum() >= 0.9 * exact.sum()  # inconclusive on few clear states
    C = X[fast & exact][:14]
    rng = np.random.default_rng(3)
    verdicts = []
    for i in range(len(C)):
        for j in (i - 1, i - 4):
            a, b = C[i], C[i] + rng.uniform(0.05, 1.0) * (C[j] - C[i])
            verdicts.append((fc.edge_proven(a, b), checker.edge_valid(a, b).ok))
    verdicts = np.array(verdicts)
    assert not np.any(verdicts[:, 0] & ~verdicts[:, 1]), "the cover proved an edge the exact proof rejects"
    assert verdicts[:, 0].any()
    if name == "panda_table_box":
        assert (~verdicts[:, 1]).any()  # both kinds of edges were tried
    rejected = int(np.sum(~verdicts[:, 0] & verdicts[:, 1]))
    print(f"{name}: states proven {fast.sum()} of {exact.sum()} clear; edges proven {verdicts[:, 0].sum()}, "
          f"exact {verdicts[:, 1].sum()}, rejected by the cover only {rejected} of {len(verdicts)}")
    assert rejected <= 0.5 * verdicts[:, 1].sum(), f"the cover rejected {rejected} edges the exact proof accepts"


def test_compiled_search_path_is_proven_exactly_and_seeded(table):
    _, checker, queries, goals, _ = table
    found = 0
    for k, q in enumerate(queries):
        r = fast_search(checker, q.start, goals[k], time_limit=2.0, seed=k)
        if r.path is None:
            continue
        found += 1
        assert np.array_equal(r.path[0], q.start) and any(np.array_equal(r.path[-1], g) for g in goals[k])
        assert all(checker.edge_valid(r.path[i], r.path[i + 1]).ok for i in range(len(r.path) - 1))
        again = fast_search(checker, q.start, goals[k], time_limit=2.0, seed=k)
        assert np.array_equal(again.path, r.path)  # the same seed, the same path
        S = fast_shortcut(checker, r.path, seed=k)
        assert np.array_equal(S, fast_shortcut(checker, r.path, seed=k))
        assert np.array_equal(S[0], r.path[0]) and np.array_equal(S[-1], r.path[-1])
        assert np.linalg.norm(np.diff(S, axis=0), axis=1).sum() <= np.linalg.norm(np.diff(r.path, axis=0), axis=1).sum()
        assert all(checker.edge_valid(S[i], S[i + 1]).ok for i in range(len(S) - 1))
    assert found >= 3


def test_compiled_search_keeps_its_time_limit(table):
    """The clock is read between chunks of iterations (each a few ms at most: edge proofs are capped)."""
    _, checker, queries, goals, _ = table
    for limit in (0.001, 0.01):
        for k, q in enumerate(queries):
            t0 = time.perf_counter()
            r = fast_search(checker, q.start, goals[k], time_limit=limit, seed=k)
            spent = time.perf_counter() - t0
            assert r.seconds <= spent and spent <= 1.1 * limit + 0.02, f"{spent:.4f} s at a {limit} s limit"


def test_plan_motion_searches_compiled_where_the_cover_is_tight(table):
    cell, _, queries, _, hold = table
    q = queries[1]
    options = MotionOptions(margin=MARGIN, time_limit=2.0, seed=1)
    plan = plan_motion(MotionRequest(cell, "panda", q.start, q.goal, options=options, hold=hold))
    assert plan.compiled and plan.planner == "RRTConnect" and plan.as_dict()["compiled_search"]
    assert plan.check.collision_free and plan.clearance.min_environment >= MARGIN
    quick = plan_motion(MotionRequest(cell, "panda", q.start, q.goal, hold=hold,
                                      options=MotionOptions(margin=MARGIN, time_limit=2.0, seed=1, recheck=False)))
    assert np.array_equal(quick.simplified, plan.simplified)  # the same seed, the same path
    assert quick.check is None and quick.clearance is None and quick.as_dict()["collision_free"] is None
    ompl = plan_motion(MotionRequest(cell, "panda", q.start, q.goal, hold=hold,
                                     options=MotionOptions(margin=MARGIN, time_limit=2.0, seed=1, compiled=False,
                                                           recheck=False)))
    assert not ompl.compiled and ompl.simplifier.startswith("OMPL")
    ur5 = load_scene("ur5_table_box")
    checker = MotionChecker(ur5, ["ur5"], margin=MARGIN)
    from pinarms.optim.motion.geometry import fast_share

    assert fast_share(checker, "rrtconnect") > 0.0  # meshes: the cover with its distance tables proves most states
    assert fast_share(MotionChecker(cell, ["panda"], margin=MARGIN), "rrtstar") == 0.0


def test_cylinder_box_gap_is_a_lower_bound_of_coal_distance():
    coal = pytest.importorskip("coal")
    rng = np.random.default_rng(0)
    for _ in range(300):
        r, h, half, Rb, pb, Rc, pc = cylinder_and_box(rng, 0.02)
        a, b = pc - h * Rc[:, 2], pc + h * Rc[:, 2]
        gap = cylinder_box_gap(a, b, r, Rb, pb, half)
        req, res = coal.DistanceRequest(), coal.DistanceResult()
        d = coal.distance(coal.Cylinder(r, 2 * h), coal.Transform3s(Rc, pc), coal.Box(*(2 * half)),
                          coal.Transform3s(Rb, pb), req, res)
        assert gap <= max(d, 0.0) + 1e-9
    # upright over a face it is exact
    gap = cylinder_box_gap(np.array([0.0, 0.0, 0.15]), np.array([0.0, 0.0, 0.25]), 0.05, np.eye(3), np.zeros(3),
                            np.array([0.1, 0.1, 0.1]))
    assert gap == pytest.approx(0.05, abs=1e-12)


@pytest.mark.parametrize("name", ["panda_table_box", "aubo_two_belt"])
def test_compiled_state_check_places_only_the_planned_arm_and_agrees_bit_for_bit(name):
    """The compiled check places the held arms and the fixtures once and only the planned arm per state:
    its excess equals, to the last bit, the cover's excess with every geometry placed at every state."""
    from pinarms.robots.cell.cover import pair_arrays

    cell = load_scene(name)
    arm = SCENES[name].arm
    hold = cell.random_q(1, seed=5)[0] if name == "aubo_two_belt" else None  # the other arm held off neutral
    checker = MotionChecker(cell, [arm], margin=MARGIN, hold=hold)
    fc = fast_check(checker)
    moving = fc.work[6]
    assert 0 < moving[2].size < checker.cover.joint.size  # fewer spheres placed per state than the cover has
    X = cell.random_q(300, seed=9)[:, checker.cols]
    fast = np.array([fc.excess(x) for x in X])
    margins = np.array([checker.self_margin if p.kind == "self" else checker.margin for p in fc.pairs])
    whole = checker.cover.excess(checker.full(X), checker.cover.prepare(*pair_arrays(fc.pairs)), margins,
                                 cap=fc.cap, floor=0.0)
    assert np.array_equal(fast, whole)
    assert (fast >= 0.0).any() and (fast < 0.0).any()  # both verdicts occur


def test_compiled_search_grows_the_smaller_tree(table):
    """RRT-Connect's next extension goes to the tree with fewer nodes (in turn when both are of one size): with
    one start node and three goal nodes, the start's tree grows even when the goals' tree was next in turn."""
    from pinarms.optim.motion import _fast_kernel as kernel
    from pinarms.optim.motion.fast import RANGE_SHARE, _rng

    _, checker, queries, goals, _ = table
    fc = fast_check(checker)
    lower, upper = np.asarray(checker.lower, dtype=float), np.asarray(checker.upper, dtype=float)
    step = RANGE_SHARE * float(np.linalg.norm(upper - lower))
    grown = 0
    for k, q in enumerate(queries):
        n = q.start.size
        nodes, parent = np.zeros((2, 64, n)), np.full((2, 64), -1, dtype=np.int64)
        nodes[0, 0] = q.start
        nodes[1, :3] = goals[k][0]
        counts = np.array([1, 3], dtype=np.int64)
        status = np.array([0, 0, 0, 1, 0], dtype=np.int64)  # the goals' tree next in turn
        kernel.rrt_connect(nodes, parent, counts, status, _rng(k), lower, upper, step, 1, *fc.args)
        assert status[3] == 1, "the larger tree (the goals') was extended"
        grown += int(counts[0] > 1)
        assert counts[0] > 1 or counts[1] == 3  # the start's tree grew, or its extension was trapped
    assert grown >= 1


def _edge_proven_fifo(fc, xa, xb):
    """The edge proof's rule written plainly (ends, then intervals first in first out, each halved at its
    middle): its verdict and the states it checks."""
    from pinarms.optim.motion import _fast_kernel as kernel
    from pinarms.robots.cell.ladder import interval_proven

    levers, lam, min_budget, max_states, hold, cols, fk, cov, grp, cap, work = fc.args
    q = np.zeros(hold.size + 1)
    T = float(np.sum(np.abs(xb - xa) * levers))
    d = np.abs(xb - xa)
    w = np.array([sum(d[j] * lam[g, j] for j in range(d.size) if d[j] > 0.0) for g in range(lam.shape[0])])
    inv = 1.0 / np.maximum(np.minimum(w, T), 1e-12)
    c = min(cap / T, 1.0)

    def e(x, cap_):
        return kernel.state_scaled(x, inv, hold, cols, fk, cov, grp, cap_, work, q)

    eb = e(xb, c)
    ea = e(xa, c) if eb >= 0.0 else -1.0
    if eb < 0.0 or ea < 0.0:
        return False, int(q[-1])
    queue = [(0.0, 1.0, ea, eb)]
    while queue:
        fa, fb, a, b = queue.pop(0)
        if interval_proven(a, b, fb - fa):
            continue
        if T * (fb - fa) < min_budget or max_states <= 0:
            return False, int(q[-1])
        max_states -= 1
        fm = 0.5 * (fa + fb)
        em = e(xa + fm * (xb - xa), min(c, max(fm - fa, fb - fm)))
        if em < 0.0:
            return False, int(q[-1])
        queue += [(fa, fm, a, em), (fm, fb, em, b)]
    return True, int(q[-1])


def test_compiled_edge_proof_checks_the_middle_first_with_the_same_verdicts():
    """The compiled edge proof checks an edge's middle before its start when the ends cannot prove the whole
    edge: the verdict is the plain rule's on every edge, with no more states (fewer on some edges that fail)."""
    from pinarms.optim.motion import _fast_kernel as kernel

    cell = load_scene("panda_shelf")
    _, hold = scene_queries("panda_shelf", 1, seed=0, margin=MARGIN)
    checker = MotionChecker(cell, ["panda"], margin=MARGIN, hold=hold)
    fc = fast_check(checker)
    X = cell.random_q(400, seed=4)[:, checker.cols]
    A = np.array([x for x in X if fc.excess(x) >= 0.0][:60])
    B = A[::-1] + 0.5 * (A - A[::-1]) * np.random.default_rng(2).uniform(0.0, 1.0, (len(A), 1))
    q, xm, queue, inv = np.zeros(fc.hold.size + 1), np.empty(checker.n), np.empty((kernel.QUEUE, 4)), np.empty(
        fc.lam.shape[0])
    fewer = 0
    verdicts = []
    for a, b in zip(A, B):
        before = q[-1]
        got = bool(kernel.edge_proven(a, b, *fc.args, q, xm, queue, inv))
        states = int(q[-1] - before)
        want, plain = _edge_proven_fifo(fc, a, b)
        assert got == want and states <= plain
        fewer += states < plain
        verdicts.append(got)
    assert any(verdicts) and not all(verdicts) and fewer >= 1


@pytest.fixture(scope="module")
def crate():
    cell = load_scene("aubo_crate_guard")
    queries, hold = scene_queries("aubo_crate_guard", 6, seed=0, margin=MARGIN)
    return cell, MotionChecker(cell, ["aubo"], margin=MARGIN, hold=hold), queries


def test_compiled_search_out_of_the_crate_is_proven_and_seeded_whatever_the_chunks(crate, monkeypatch):
    """aubo_crate_guard (an end in the crate under the guard plate): every query solved well within the limit,
    the path accepted edge by edge by the exact checker, the same path when the search runs in other chunks."""
    from pinarms.optim.motion import fast

    _, checker, queries = crate
    for k, q in enumerate(queries):
        r = fast_search(checker, q.start, q.goal[None], time_limit=2.0, seed=k)
        assert r.path is not None and r.seconds < 1.0, r.status
        assert np.array_equal(r.path[0], q.start) and np.array_equal(r.path[-1], q.goal)
        assert all(checker.edge_valid(r.path[i], r.path[i + 1]).ok for i in range(len(r.path) - 1))
        if k < 2:
            monkeypatch.setattr(fast, "FIRST_CHUNK", 1)
            again = fast_search(checker, q.start, q.goal[None], time_limit=2.0, seed=k)
            monkeypatch.setattr(fast, "FIRST_CHUNK", 64)
            third = fast_search(checker, q.start, q.goal[None], time_limit=2.0, seed=k)
            monkeypatch.undo()
            assert np.array_equal(again.path, r.path) and np.array_equal(third.path, r.path)


def test_compiled_shortcut_skips_tries_that_gain_too_little(table):
    """A shortcut try is proven only when it would shorten the path by ``min_gain`` of its length: with a gain
    no try can reach, only the vertex-dropping pass runs (the same path as with no tries); with none, the
    tries shorten the path."""
    from pinarms.optim.motion import _fast_kernel as kernel
    from pinarms.optim.motion.fast import _rng

    _, checker, queries, goals, _ = table
    fc = fast_check(checker)
    q = queries[0]
    P = fast_search(checker, q.start, goals[0], time_limit=2.0, seed=0).path
    detour = np.insert(P, 1, P[0] + 0.5 * (P[1] - P[0]) + 0.05, axis=0)  # a kink: room to shorten
    assert fc.path_proven(detour)

    def run(tries, gain):
        buf = np.zeros((detour.shape[0] + tries + 2, detour.shape[1]))
        buf[: detour.shape[0]] = detour
        return buf[: kernel.shortcut(buf, detour.shape[0], _rng(1), tries, gain, *fc.args)].copy()

    def length(X):
        return float(np.linalg.norm(np.diff(X, axis=0), axis=1).sum())

    assert np.array_equal(run(40, 1.0), run(0, 0.0))
    assert length(run(40, 0.0)) < length(run(0, 0.0)) <= length(detour)


def test_goals_best_keeps_the_path_with_the_shortest_time_bound():
    """``MotionOptions(goals="best")`` on the crate scene: the kept path ends at a clear goal branch, is proven,
    and its time bound is below that of the first goal's path (seed 0 reaches the long way round first);
    it is the default (a faster move than the first branch's), timed under the default acceleration limits
    (before, torques alone: peaks of 164 rad/s² where the limit rule gives 14.7); bad choices are refused."""
    from pinarms.optim.errors import InvalidLimits, InvalidSettings
    from pinarms.optim.motion.geometry import travel_time_bound
    from pinarms.optim.motion.goals import ik_candidates
    from pinarms.optim.motion.scenes import region_pose

    cell = load_scene("aubo_crate_guard")
    arm = cell.arm("aubo")
    table, crate = SCENES["aubo_crate_guard"].regions
    checker = MotionChecker(cell, ["aubo"], margin=0.01)
    q0 = next(q for q in ik_candidates(arm.robot, arm.to_base(region_pose(table, 0.5 * (np.array(table.lo) +
                                                                                        np.array(table.hi)))),
                                       cell.neutral)[0] if checker.state_valid(q))
    goal = region_pose(crate, 0.5 * (np.array(crate.lo) + np.array(crate.hi)))
    v = arm.robot.velocity_limit

    def plan(**options):
        return plan_motion(MotionRequest(cell, "aubo", q0, goal, options=MotionOptions(time_limit=10.0, seed=0,
                                                                                       **options)))

    first = plan(recheck=False, goals="first")
    best = plan(goals="best")
    default = plan(recheck=False)
    assert best.check.collision_free and best.compiled
    assert travel_time_bound(best.simplified, v) < travel_time_bound(first.simplified, v)
    assert np.array_equal(default.simplified, best.simplified)  # the default is the fastest clear branch
    assert round(default.duration, 3) == round(best.duration, 3) < round(first.duration, 3)
    # accelerations limited by default (velocity limit / 0.25 s), and the plan says so
    assert default.limits["amax_source"] == "default: velocity limit / 0.25 s"
    np.testing.assert_allclose(default.limits["amax"], v / 0.25)
    assert np.all(default.trajectory.peaks().acceleration <= v / 0.25 * (1 + 1e-6))
    with pytest.raises(InvalidLimits, match="amax must be None"):
        MotionLimits(amax=True)
    G = np.array([g.q for g in best.goals if g.valid])
    assert len(G) > 1 and any(np.array_equal(best.simplified[-1], g) for g in G)
    with pytest.raises(InvalidSettings, match="goals must be"):
        MotionOptions(goals="all")
