"""The re-check of a planned motion: the cover screen keeps every verdict of check_motion, and the
clearance profile's distances are exact at its samples and agree with a dense coal sampling."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinarms.optim.motion import (SCENES, MotionChecker, MotionOptions, MotionRequest, load_scene, plan_motion,
                                   scene_queries)
from pinarms.optim.motion.report import _Distances, _interval_speeds, clearance_profile, pair_speeds, sample_times
from pinarms.planning import multi_quintic
from pinarms.robots.cell import motion as cell_motion
from pinarms.robots.cell.motion import ArmMotion

SCENE = "aubo_two_belt"
MARGIN = 0.01


@pytest.fixture(scope="module")
def scene():
    cell = load_scene(SCENE)
    queries, hold = scene_queries(SCENE, 3, seed=0, margin=MARGIN, cell=cell)
    arm = SCENES[SCENE].arm
    plans = [plan_motion(MotionRequest(cell, arm, q.start, q.goal, hold=hold,
                                       options=MotionOptions(margin=MARGIN, seed=k, recheck=False)))
             for k, q in enumerate(queries)]
    # a timed straight joint line from a start into a seeded configuration in contact
    rng = np.random.default_rng(0)
    a = cell.arm(arm)
    for _ in range(2000):
        q = hold.copy()
        q[a.q_slice] = rng.uniform(a.robot.lower, a.robot.upper)
        if cell.in_collision(q):
            break
    else:
        raise AssertionError("no configuration in contact found")
    straight = multi_quintic([0.0, 1.0], np.array([queries[0].start, q[a.q_slice]]))
    return cell, arm, hold, [p.trajectory for p in plans], straight


def _check(cell, arm, traj, hold, clearance, rows, monkeypatch):
    monkeypatch.setattr(cell_motion, "COVER_ROWS", rows)
    return cell.check_motion([ArmMotion(arm, traj)], margin=MARGIN, clearance=clearance, hold=hold)


def test_cover_screen_keeps_every_verdict_and_sample(scene, monkeypatch):
    cell, arm, hold, trajs, straight = scene
    checker = MotionChecker(cell, [arm], margin=MARGIN, hold=hold)
    cases = []
    for traj in trajs:
        closest = clearance_profile(checker, traj).min_environment
        # near contact: the required clearance just below and just above the smallest distance
        cases += [(traj, 0.0), (traj, closest - 2e-3), (traj, closest + 2e-3)]
    cases.append((straight, 0.0))
    verdicts = set()
    for traj, clearance in cases:
        old = _check(cell, arm, traj, hold, clearance, 10**9, monkeypatch)  # broad phase alone
        new = _check(cell, arm, traj, hold, clearance, cell_motion.COVER_ROWS, monkeypatch)
        assert (new.collision_free, new.clear) == (old.collision_free, old.clear)
        assert new.lower_bound == old.lower_bound and new.min_clearance == old.min_clearance
        np.testing.assert_array_equal(new.times, old.times)
        np.testing.assert_array_equal(new.clearance, old.clearance)
        np.testing.assert_array_equal(new.exact, old.exact)
        assert (new.first_contact is None) == (old.first_contact is None)
        plain = cell.check_motion([ArmMotion(arm, traj)], margin=MARGIN, clearance=clearance, hold=hold, cover=False)
        np.testing.assert_array_equal(plain.exact, old.exact)  # cover=False: the broad phase alone
        assert plain.lower_bound == old.lower_bound
        if old.first_contact is not None:
            assert new.first_contact.time == old.first_contact.time
        verdicts.add((old.collision_free, old.clear))
    # clear; proven contact-free but not clear; in contact
    assert {(True, True), (True, False), (False, False)} <= verdicts


def _dense_distances(checker, traj, t):
    """Every pair's exact distance (coal, no pruning) at times ``t``: ``(len(t), P)``."""
    Q = checker.full(np.asarray(traj.sample(t)[0], dtype=float).reshape(t.size, -1))
    qp = checker.cell.robot.q_to_pinocchio(Q)
    gm = checker.geometry
    gd = pin.GeometryData(gm)
    data = checker.model.createData()
    out = np.empty((t.size, len(gm.collisionPairs)))
    for i in range(t.size):
        pin.updateGeometryPlacements(checker.model, data, gm, gd, qp[i])
        pin.computeDistances(gm, gd)
        out[i] = [r.min_distance for r in gd.distanceResults]
    return out


def test_profile_is_exact_at_its_samples_and_agrees_with_dense_sampling(scene):
    cell, arm, hold, trajs, _ = scene
    checker = MotionChecker(cell, [arm], margin=MARGIN, hold=hold)
    own = np.array([p.kind == "self" for p in checker.pairs])
    for traj in trajs[:2]:
        profile = clearance_profile(checker, traj)
        assert np.all(np.diff(profile.times) > 0)
        assert profile.times[0] == traj.start_time and profile.times[-1] == traj.end_time
        # exact at every sample: the pruned pass equals every pair's distance, smallest taken (coal's GJK
        # tolerance apart: its own data here, cold-started)
        D = _dense_distances(checker, traj, profile.times)
        np.testing.assert_allclose(profile.environment, D[:, ~own].min(axis=1), rtol=0, atol=5e-6)
        if own.any():
            np.testing.assert_allclose(profile.own, D[:, own].min(axis=1), rtol=0, atol=5e-6)
        k = profile.environment_pair
        np.testing.assert_allclose(D[np.arange(k.size), k], profile.environment, rtol=0, atol=5e-6)
        # a dense sampling (4x finer in time than the profile's count, uniform) finds the same minimum
        # to within the stated resolution: margin / 2 of travel between the profile's samples
        t_dense = np.linspace(traj.start_time, traj.end_time, 4 * profile.times.size)
        Dd = _dense_distances(checker, traj, t_dense)
        dense_env = Dd[:, ~own].min()
        assert profile.min_environment - MARGIN / 2 <= dense_env + 1e-12
        assert dense_env <= profile.min_environment + 1e-12 or profile.min_environment <= dense_env + MARGIN / 2
        assert abs(profile.min_environment - dense_env) <= MARGIN / 2
        assert profile.min_environment >= MARGIN  # the planned path keeps the margin


def test_pruned_pairs_keep_true_lower_bounds(scene):
    cell, arm, hold, trajs, _ = scene
    checker = MotionChecker(cell, [arm], margin=MARGIN, hold=hold)
    traj = trajs[0]
    dist = _Distances(checker, np.abs(traj.peaks().velocity))
    t = np.linspace(traj.start_time, traj.end_time, 60)
    env, _, own_d, bounds, _ = dist.at(traj, t)
    D = _dense_distances(checker, traj, t)
    assert np.all(np.isfinite(bounds))
    assert np.all(bounds <= D + 5e-6)  # a bound never above the distance (coal's tolerance)
    assert dist.calls < D.size / 2  # and most pairs were not computed
    # a second batch between the first one's samples uses the bounds carried over from them
    mid = 0.5 * (t[:-1] + t[1:])
    env_mid, _, _, bounds_mid, _ = dist.at(traj, mid)
    D_mid = _dense_distances(checker, traj, mid)
    own = np.array([p.kind == "self" for p in checker.pairs])
    np.testing.assert_allclose(env_mid, D_mid[:, ~own].min(axis=1), rtol=0, atol=5e-6)
    assert np.all(bounds_mid <= D_mid + 5e-6)


def test_pair_speeds_bound_every_distance_rate(scene):
    cell, arm, hold, trajs, _ = scene
    checker = MotionChecker(cell, [arm], margin=MARGIN, hold=hold)
    traj = trajs[0]
    speeds = pair_speeds(checker, np.abs(traj.peaks().velocity))
    t = np.linspace(traj.start_time, traj.end_time, 400)
    D = _dense_distances(checker, traj, t)
    change = np.abs(np.diff(D, axis=0))
    # coal's GJK tolerance (a few 1e-7 m between two calls on meshes that do not move) allowed
    assert np.all(change <= speeds * np.diff(t)[:, None] * (1 + 1e-9) + 5e-6)
    assert np.any(change > 1e-3)  # something moves
    # on each interval, from the end speeds and the acceleration peaks (what the profile's halving uses)
    dist = _Distances(checker, np.abs(traj.peaks().velocity))
    rates = np.abs(np.asarray(traj.sample(t)[1]))
    per_interval = _interval_speeds(dist, rates, np.abs(traj.peaks().velocity), np.abs(traj.peaks().acceleration),
                                    np.diff(t))
    assert np.all(change <= per_interval * np.diff(t)[:, None] * (1 + 1e-9) + 5e-6)
    assert np.all(per_interval <= speeds * (1 + 1e-12))
    own = np.array([p.kind == "self" for p in checker.pairs])
    whole = float(np.abs(traj.peaks().velocity) @ checker.levers)
    assert np.all(speeds <= whole * (1 + 1e-12))
    if own.any():  # links of one arm move one relative to the other only by the joints between them
        assert speeds[own].min() < 0.5 * whole


def test_sample_times_keep_the_travel_between_samples_within_the_margin(scene):
    _, arm, _, trajs, _ = scene
    cell = scene[0]
    checker = MotionChecker(cell, [arm], margin=MARGIN, hold=scene[2])
    traj = trajs[1]
    t = sample_times(traj, checker.levers, MARGIN)
    assert t[0] == traj.start_time and t[-1] == traj.end_time and np.all(np.diff(t) > 0)
    fine = np.linspace(traj.start_time, traj.end_time, 200_001)
    v = np.abs(np.asarray(traj.sample(fine)[1])) @ checker.levers
    travel = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(fine))])
    between = np.diff(np.interp(t, fine, travel))
    assert between.max() <= MARGIN * (1 + 1e-3)
    uniform = int(np.ceil(float(np.abs(traj.peaks().velocity) @ checker.levers) * traj.duration / MARGIN))
    assert t.size - 1 <= uniform  # never more samples than one per margin at the peak speed



@pytest.fixture(scope="module")
def table():
    """panda_table_box and two planned motions whose smallest clearance varies along them (no constant pair ties)."""
    cell = load_scene("panda_table_box")
    queries, hold = scene_queries("panda_table_box", 2, seed=0, margin=MARGIN, cell=cell)
    plans = [plan_motion(MotionRequest(cell, "panda", q.start, q.goal, hold=hold,
                                       options=MotionOptions(margin=MARGIN, seed=k, recheck=False)))
             for k, q in enumerate(queries)]
    return cell, "panda", hold, [p.trajectory for p in plans]


@pytest.mark.slow
def test_smallest_clearance_is_every_samples_exact_minimum_with_few_samples_computed(table, monkeypatch):
    """The report's smallest clearance (every candidate pair, coal) equals the minimum over every sample computed
    exactly, with or without the cover, while most samples are never computed (broad phase, approach budget)."""
    from pinarms.robots.cell import motion_minimum
    from pinarms.robots.cell.collision import exact_min_distance

    cell, arm, hold, trajs = table
    n_all = len(cell._candidates)
    computed = []
    real = motion_minimum.exact_min_distance

    def counting(cell_, Q, **kw):
        computed.append(len(Q))
        return real(cell_, Q, **kw)

    monkeypatch.setattr(motion_minimum, "exact_min_distance", counting)
    for traj in trajs[:2]:
        motion = [ArmMotion(arm, traj)]
        schedule = cell_motion._schedule(cell, motion, traj.start_time, traj.end_time, MARGIN)
        t = schedule.times
        Q = cell_motion.configurations(cell, motion, t, hold)
        d, k, _, _ = exact_min_distance(cell, Q, n=n_all)  # every sample, exact over every candidate pair
        i = int(np.flatnonzero(d <= d.min() + 1e-9)[0])  # the earliest of ties (times in order)
        for cover in (False, True):
            computed.clear()
            samples = cell_motion._Samples(cell, motion, hold, n_all, cover)
            # nothing known from a screen: the search alone finds the minimum
            got = motion_minimum.smallest_clearance(samples, schedule, t, np.zeros(t.size), np.full(t.size, -1),
                                                    np.zeros(t.size, dtype=bool), 0.0)
            assert got == (d[i], t[i], cell._candidates[int(k[i])])
            assert sum(computed) < t.size / 4, (cover, sum(computed), t.size)

def test_a_capped_distance_is_exact_below_the_cap_and_a_lower_bound_above(scene):
    from pinarms.robots.cell.collision import exact_min_distance

    cell = scene[0]
    Q = cell.random_q(40, seed=3)
    n_all = len(cell._candidates)
    exact, pair, _, _ = exact_min_distance(cell, Q, n=n_all)
    cap = float(np.median(exact))
    capped, capped_pair, _, _ = exact_min_distance(cell, Q, n=n_all, cap=cap)
    below = exact < cap
    assert below.any() and (~below).any()
    np.testing.assert_array_equal(capped[below], exact[below])
    np.testing.assert_array_equal(capped_pair[below], pair[below])
    assert np.all(capped[~below] >= cap) and np.all(capped[~below] <= exact[~below])


def test_one_moving_arm_approaches_at_most_at_its_own_speed_bound(scene):
    """One moving arm (the other held): the approach budget is the arm's own bound, not twice it, and no candidate
    pair's distance (its own links, the held arm, the fixtures) changes faster on a dense grid."""
    from pinarms.robots.cell.speed_bound import joint_levers
    from tests.robots.cell.test_cell_motion import approach_budget_holds

    cell, arm, hold, trajs, straight = scene
    levers = joint_levers(cell)[cell.arm(arm).q_slice]
    for traj in (trajs[0], straight):
        motion = [ArmMotion(arm, traj)]
        schedule, change, allowed = approach_budget_holds(cell, motion, (traj.start_time, traj.end_time),
                                                          traj.duration / 400, hold)
        assert change.max() > 0.05 * allowed.max()  # the arm does move towards things
        assert schedule.speed_bound == pytest.approx(float(np.abs(traj.peaks().velocity) @ levers), rel=1e-12)


def test_the_first_rounds_sweep_stands_in_for_the_screen_and_clears_only_far_samples(table):
    """Without the cover, one broad-phase pass at the first round's smallest distance replaces the screen's pass:
    the same samples flagged as by the screen over every sample, and every sample it clears farther than that
    distance by coal (every candidate pair)."""
    from pinarms.robots.cell.collision import exact_min_distance
    from pinarms.robots.cell.motion_minimum import first_round

    cell, arm, hold, trajs = table
    for traj in trajs:
        motion = [ArmMotion(arm, traj)]
        check = cell.check_motion(motion, margin=MARGIN, hold=hold, cover=False)
        schedule = cell_motion._schedule(cell, motion, traj.start_time, traj.end_time, MARGIN)
        Q = cell_motion.configurations(cell, motion, schedule.times, hold)
        at = np.searchsorted(check.times, schedule.times)
        assert np.array_equal(check.times[at], schedule.times)
        np.testing.assert_array_equal(check.exact[at], cell.in_collision(Q, margin=MARGIN + 1e-6))
        first = first_round(cell, Q, schedule.times, MARGIN)
        assert np.isfinite(first.swept) and (~first.near).sum() > schedule.times.size / 2  # it stood in, cleared most
        d, _, _, _ = exact_min_distance(cell, Q[~first.near], n=len(cell._candidates))
        assert np.all(d > first.swept)
