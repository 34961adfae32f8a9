"""Per-link travel bounds of the compiled edge proof (optim.motion.link_levers): every cover sphere
moves no farther than its link's bound along densely sampled edges, every pair group's distance
changes no more than its group's bound, and the compiled proof on them never calls clear an edge
the exact checker (coal) rejects."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.optim.motion import SCENES, MotionChecker, load_scene
from pinarms.optim.motion.fast import fast_check
from pinarms.optim.motion.link_levers import link_levers
from pinarms.robots.cell.motion import joint_levers

MARGIN = 0.01
SAMPLES = np.linspace(0.0, 1.0, 257)


def _edge(Qa: np.ndarray, Qb: np.ndarray) -> np.ndarray:
    return Qa[None] + SAMPLES[:, None] * (Qb - Qa)[None]


@pytest.mark.parametrize("name", ["panda_shelf", "aubo_crate_guard", "aubo_two_belt"])
def test_link_bound_holds_every_cover_sphere_centre_on_dense_edges(name):
    """|centre(s) − centre(0)| ≤ s · Σ_c |Δq_c| L[link, c] for every sphere, sample and edge (full cell
    configurations: every joint moves)."""
    cell = load_scene(name)
    checker = MotionChecker(cell, [SCENES[name].arm], margin=MARGIN)
    cover = checker.cover
    L = link_levers(cover, cell.model.lowerPositionLimit, cell.model.upperPositionLimit)
    Q = cell.random_q(24, seed=4)
    worst, moving = 0.0, cover.joint > 0
    for a in range(0, len(Q), 2):
        W = cover.world_centers(_edge(Q[a], Q[a + 1]))  # (257, S, 3)
        reach = np.abs(Q[a + 1] - Q[a]) @ L[cover.joint].T  # (S,) bound over the whole edge
        for k in (0, 128):  # from the start and from the middle: every sub-interval's share
            moved = np.linalg.norm(W - W[k][None], axis=2)
            bound = np.abs(SAMPLES - SAMPLES[k])[:, None] * reach[None]
            assert np.all(moved <= bound + 1e-9), f"{name}: a sphere moved {np.max(moved - bound):.3g} m past its bound"
            worst = max(worst, float(np.max(moved[:, moving] / np.maximum(bound[:, moving], 1e-12))))
    assert 0.2 < worst <= 1.0  # the bound is not vacuous either
    # the base links move far less than the whole arm's bound
    T = joint_levers(cell)
    first = int(cover.joint[moving].min())
    assert L[first].sum() < 0.5 * T.sum()


@pytest.mark.parametrize("name", ["panda_shelf", "aubo_crate_guard"])
def test_group_bound_holds_every_pair_distance_on_dense_edges(name):
    """Between the spheres of two links of a group the distance changes at most ``s · w_g``; against a
    fixture the link's spheres move at most ``s · w_g`` (planned edges, held arms still)."""
    cell = load_scene(name)
    checker = MotionChecker(cell, [SCENES[name].arm], margin=MARGIN)
    fc = fast_check(checker)
    cover = checker.cover
    hjoint, group_a, group_b = fc.grp[0], fc.grp[4], fc.grp[5]
    ja, jb = hjoint[group_a], hjoint[group_b]
    X = cell.random_q(16, seed=8)[:, checker.cols]
    checked = 0
    for a in range(0, len(X), 2):
        W = cover.world_centers(checker.full(_edge(X[a], X[a + 1])))
        w = np.minimum(fc.lam @ np.abs(X[a + 1] - X[a]), np.abs(X[a + 1] - X[a]) @ fc.levers)
        for g in range(ja.size):
            A = np.flatnonzero(cover.joint == ja[g])
            if jb[g] == 0:
                change = np.linalg.norm(W[:, A] - W[:1, A], axis=2)
            else:
                B = np.flatnonzero(cover.joint == jb[g])
                D = np.linalg.norm(W[:, A, None] - W[:, None, B], axis=3)
                change = np.abs(D - D[:1])
            assert np.all(change <= SAMPLES.reshape((-1,) + (1,) * (change.ndim - 1)) * w[g] + 1e-9), \
                f"{name}: group {g} (joints {ja[g]}, {jb[g]}) changed past its bound"
            checked += 1
    assert checked > 0 and np.any(fc.lam.sum(axis=1) < 0.5 * fc.levers.sum())


@pytest.mark.parametrize("name", ["panda_shelf", "aubo_crate_guard"])
def test_compiled_edge_proof_on_group_bounds_is_exact_clear(name):
    """Fast ⇒ exact on random edges between clear states, short and long (both verdicts occur)."""
    cell = load_scene(name)
    checker = MotionChecker(cell, [SCENES[name].arm], margin=MARGIN)
    fc = fast_check(checker)
    X = cell.random_q(240, seed=31)[:, checker.cols]
    C = X[[fc.state_proven(x) for x in X]][:16]
    rng = np.random.default_rng(7)
    verdicts = []
    for i in range(len(C)):
        for j in (i - 1, i - 3, i - 7):
            a, b = C[i], C[i] + rng.uniform(0.02, 1.0) * (C[j] - C[i])
            verdicts.append((fc.edge_proven(a, b), checker.edge_valid(a, b).ok))
    verdicts = np.array(verdicts)
    assert not np.any(verdicts[:, 0] & ~verdicts[:, 1]), "the cover proved an edge the exact proof rejects"
    assert verdicts[:, 0].any() and (~verdicts[:, 0]).any()


def test_compiled_search_steps_off_ends_the_cover_does_not_prove():
    """aubo_crate_guard: starts and goals deep in the crate the spheres do not prove clear (coal does) are
    joined to the compiled search by exactly proven edges; the path found is proven exactly, end to end."""
    from pinarms.optim.motion import scene_queries
    from pinarms.optim.motion.fast import fast_search

    cell = load_scene("aubo_crate_guard")
    queries, hold = scene_queries("aubo_crate_guard", 8, seed=0, margin=MARGIN)
    checker = MotionChecker(cell, ["aubo"], margin=MARGIN, hold=hold)
    fc = fast_check(checker)
    hard = [k for k, q in enumerate(queries) if not (fc.state_proven(q.start) and fc.state_proven(q.goal))]
    assert hard, "no query with an end the cover leaves unproven: the test would prove nothing"
    for k in hard[:2]:
        q = queries[k]
        r = fast_search(checker, q.start, np.atleast_2d(q.goal), time_limit=2.0, seed=k)
        assert r.path is not None, r.status
        assert np.array_equal(r.path[0], q.start) and np.array_equal(r.path[-1], q.goal)
        assert all(checker.edge_valid(r.path[i], r.path[i + 1]).ok for i in range(len(r.path) - 1))
