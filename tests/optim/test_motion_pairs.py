"""The checker's per-pair route: the cover's verdict per pair, coal only on the pairs it leaves open.

The same verdicts as the all-pairs route (a configuration the cover does not prove as a
whole: coal on every pair) on seeded states of a UR5, a Panda and an AUBO-i3 scene, close
ones included; the pairs sent to coal are exactly those the cover does not prove; nothing
reported clear comes closer than its threshold (coal's exact distances)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinarms.optim.motion import MotionChecker, load_scene
from pinarms.optim.motion.coal_batches import CheckRoute
from pinarms.robots.cell.cover import link_cover

MARGIN = 0.01
SCENE_ARMS = (("ur5_table_box", "ur5"), ("panda_shelf", "panda"), ("aubo_crate_guard", "aubo"))


@pytest.fixture(scope="module")
def setups():
    out = {}
    for name, arm in SCENE_ARMS:
        cell = load_scene(name)
        pairwise = MotionChecker(cell, [arm], margin=MARGIN, route=CheckRoute(pairwise=True))
        whole = MotionChecker(cell, [arm], margin=MARGIN, route=CheckRoute(pairwise=False))
        out[name] = (cell, pairwise, whole, _states(cell, whole))
    return out


def _states(cell, checker, n: int = 160, seed: int = 7) -> np.ndarray:
    """Seeded random states and, for each, the state half-way to a clear one repeatedly (close states:
    a bisection towards the boundary between clear and not)."""
    X = cell.random_q(n, seed=seed)[:, checker.cols]
    bad = checker.coal_collides(checker.full(X), "margin")
    clear, hit = X[~bad], X[bad]
    m = min(len(clear), len(hit), 24)
    a, b = clear[:m].copy(), hit[:m].copy()
    for _ in range(8):  # bisect each clear–colliding segment towards contact
        mid = 0.5 * (a + b)
        c = checker.coal_collides(checker.full(mid), "margin")
        a[~c], b[c] = mid[~c], mid[c]
    return np.concatenate([X, a, b])


def _distances(checker, Q: np.ndarray) -> np.ndarray:
    """coal's exact distance of every pair ``(N, P)`` [m]."""
    gm, gd, data = checker.geometry, checker._gd_dist, checker.model.createData()
    out = np.empty((Q.shape[0], len(checker.pairs)))
    for i, q in enumerate(Q):
        pin.updateGeometryPlacements(checker.model, data, gm, gd, q)
        out[i] = [pin.computeDistance(gm, gd, k).min_distance for k in range(len(checker.pairs))]
    return out


@pytest.mark.parametrize("name", [n for n, _ in SCENE_ARMS])
def test_per_pair_and_all_pairs_routes_give_the_same_verdicts(setups, name):
    cell, pairwise, whole, X = setups[name]
    Q = pairwise.full(X)
    for which in ("margin", 0, -2):
        a = pairwise.batch_collides(Q, which)
        b = whole.coal_collides(Q, which)
        assert np.array_equal(a, b), which
        if which == "margin":
            assert 0 < b.sum() < b.size  # both kinds of state are in the set
    near = X[-48:]
    assert [pairwise.state_valid(x) for x in near] == [whole.state_valid(x) for x in near]


@pytest.mark.parametrize("name", [n for n, _ in SCENE_ARMS])
def test_stop_at_the_first_hit_is_kept(setups, name):
    _, pairwise, whole, X = setups[name]
    Q = pairwise.full(X[-48:])
    a = pairwise.batch_collides(Q, 0, stop=True)
    b = whole.coal_collides(Q, 0, stop=True)
    assert a.sum() <= 1 and np.array_equal(a, b)


def test_coal_gets_exactly_the_pairs_the_cover_leaves_open(setups):
    cell, checker, _, X = setups["ur5_table_box"]
    Q = checker.full(X)
    cover = link_cover(cell)
    t = checker.pair_margin + 0.005  # screen level 0
    pa = np.array([p.index_a for p in checker.pairs])
    pb = np.array([p.index_b for p in checker.pairs])
    # each pair alone through the whole-configuration screen: the cover's verdict on that pair
    alone = np.stack([cover.screen(Q, cover.prepare(pa[k:k + 1], pb[k:k + 1]), t[k:k + 1])
                      for k in range(pa.size)], axis=1)
    open_ = checker.open_pairs(Q, 0)
    assert np.array_equal(open_, ~alone)
    assert np.array_equal(~open_.any(axis=1), cover.screen(Q, checker._cover_pairs, t))
    before = dict(checker.counts)
    checker.batch_collides(Q, 0)
    assert checker.counts["coal_pairs"] - before["coal_pairs"] == int(open_.sum())
    assert checker.counts["coal"] - before["coal"] == int(open_.any(axis=1).sum())
    assert open_.sum() < 0.5 * open_.size  # the point of the route: most pairs never reach coal


@pytest.mark.parametrize("name", [n for n, _ in SCENE_ARMS])
def test_nothing_reported_clear_comes_closer_than_its_threshold(setups, name):
    _, checker, _, X = setups[name]
    Q = checker.full(X)
    clear = ~checker.batch_collides(Q, "margin")
    D = _distances(checker, Q[clear])
    assert clear.any()
    assert np.all(D >= checker.pair_margin[None] - 1e-9)


def test_edges_get_the_same_verdicts_either_way(setups):
    cell, pairwise, whole, X = setups["aubo_crate_guard"]
    rng = np.random.default_rng(3)
    clear = X[~whole.coal_collides(whole.full(X), "margin")]
    for _ in range(6):
        i, j = rng.choice(len(clear), 2, replace=False)
        xa, xb = clear[i], clear[i] + 0.3 * (clear[j] - clear[i])
        assert pairwise.edge_valid(xa, xb).ok == whole.edge_valid(xa, xb).ok


def test_ur5_edges_get_the_same_verdicts_either_way(setups):
    cell, pairwise, whole, X = setups["ur5_table_box"]
    rng = np.random.default_rng(4)
    clear = X[~whole.coal_collides(whole.full(X), "margin")]
    before = dict(pairwise.counts), dict(whole.counts)
    for _ in range(4):
        i, j = rng.choice(len(clear), 2, replace=False)
        xa, xb = clear[i], clear[i] + 0.1 * (clear[j] - clear[i])
        assert pairwise.edge_valid(xa, xb).ok == whole.edge_valid(xa, xb).ok
    sent = [c["coal_pairs"] - b["coal_pairs"] for c, b in zip((pairwise.counts, whole.counts), before)]
    assert sent[0] < sent[1]  # fewer pairs reach coal by the per-pair route


def test_edges_proven_with_per_pair_shares_are_clear_when_sampled_densely(setups):
    """The per-pair route scales each pair's screen raise by its share of the edge's travel: what it
    proves, coal finds clear at samples 0.5 mm of travel apart (and the shares lie in [0, 1])."""
    cell, pairwise, whole, X = setups["ur5_table_box"]
    rng = np.random.default_rng(5)
    clear = X[~whole.coal_collides(whole.full(X), "margin")]
    proven = 0
    for _ in range(6):
        i, j = rng.choice(len(clear), 2, replace=False)
        xa, xb = clear[i], clear[i] + 0.1 * (clear[j] - clear[i])
        share = pairwise._travel_share(xa, xb)
        assert np.all((share >= 0.0) & (share <= 1.0)) and share.min() < 1.0
        if not pairwise.edge_valid(xa, xb).ok:
            continue
        proven += 1
        n = int(np.ceil(pairwise.travel(xa, xb) / 5e-4)) + 1
        S = xa + np.linspace(0.0, 1.0, n)[:, None] * (xb - xa)
        assert not whole.coal_collides(whole.full(S), "margin").any()
    assert proven >= 2


def test_check_route_is_one_checked_object():
    """MotionChecker takes threads, cover and per-pair route as one CheckRoute, checked when made."""
    from pinarms.optim import InvalidSettings

    assert (CheckRoute().threads, CheckRoute().cover, CheckRoute().pairwise) == (1, True, None)
    with pytest.raises(InvalidSettings, match="threads must be"):
        CheckRoute(threads=0)
    with pytest.raises(InvalidSettings, match="cover must be True or False"):
        CheckRoute(cover="yes")
    with pytest.raises(InvalidSettings, match="route must be a CheckRoute, got dict"):
        MotionChecker(None, ["a"], route={"threads": 2})
