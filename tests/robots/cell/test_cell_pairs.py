"""A pair is left out of a check only when it is proven farther than the clearance asked (issue 24 item 1)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.optim.motion.scenes import load_scene, scene_names
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.robots.cell.collision import exact_min_distance
from pinarms.robots.errors import InvalidInput

from _cells import POST_GAP, Reference, facing_cell_text, make_cell, post_cell_text

SWEEP = planning.multi_quintic([0.0, 1.0], np.array([[-1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]]))


@pytest.fixture(scope="module")
def post():
    return make_cell(post_cell_text(), "post")


@pytest.fixture(scope="module")
def facing():
    return make_cell(facing_cell_text(), "facing")


def _post_pair(cell):
    return next(p for p in cell.allowed if {p.body_a, p.body_b} == {"arm_upper_arm", "post"})


def test_the_post_is_out_of_reach_with_a_proven_bound_below_its_distance(post):
    pair = _post_pair(post)
    assert pair.reason == "out of reach"
    assert 0.0 < pair.distance_bound <= POST_GAP
    assert post.pairs_for(0.0) == post.pairs
    assert post.pairs_for(pair.distance_bound - 1e-9) == post.pairs
    back = post.pairs_for(0.02)
    assert len(back) == len(post.pairs) + 1 and back[-1].bodies == ("arm_upper_arm", "post")
    assert post.pairs_for(float("inf"))[: len(post.pairs)] == post.pairs
    for design in (p for p in post.allowed if p.reason != "out of reach"):
        assert design.distance_bound == np.inf  # by design: never brought back
    back_by_bound = [p for p in post.allowed if p.distance_bound <= 0.02]
    assert [(p.index_a, p.index_b) for p in back_by_bound] == [(pair.index_a, pair.index_b)]


@pytest.mark.parametrize("bad", [-0.001, float("nan"), "0.02", None, True])
def test_pairs_for_refuses_what_is_not_a_clearance(post, bad):
    with pytest.raises(InvalidInput, match="clearance"):
        post.pairs_for(bad)


def test_a_sweep_past_the_post_is_not_clear_at_20_mm_and_reports_13_mm(post):
    result = post.check_motion({"arm": SWEEP}, margin=0.01, clearance=0.02)
    assert not result.clear and result.collision_free
    assert result.min_clearance_pair.bodies == ("arm_upper_arm", "post")
    assert abs(result.min_clearance - POST_GAP) < 3e-4
    assert result.lower_bound <= POST_GAP
    assert "smallest clearance 13.0 mm (arm_upper_arm ↔ post at t = 0.53" in repr(result)
    assert "the 20 mm clearance is NOT proven along the whole motion" in repr(result)


@pytest.mark.parametrize("margin, clearance, curve", [(0.005, 0.0, False), (0.005, 0.0, True), (0.01, 0.01, False)])
def test_the_smallest_clearance_is_the_true_distance_never_the_screening_bound(post, margin, clearance, curve):
    """Issue 36 item 11: with every sample screened clear, min_clearance was the screen's 5 mm, not the 13 mm."""
    result = post.check_motion({"arm": SWEEP}, margin=margin, clearance=clearance, curve=curve)
    assert result.collision_free and result.clear
    assert result.min_clearance_pair.bodies == ("arm_upper_arm", "post")
    assert abs(result.min_clearance - POST_GAP) < 3e-4  # the post pair is left out of the screen, not of the minimum
    assert 0.0 < result.lower_bound <= result.min_clearance
    # the true minimum at the samples: coal over every candidate pair, at the time reported
    q = post.robot.check_q(np.array([float(SWEEP.sample(np.array([result.min_clearance_time]))[0][0, 0]), 0, 0, 0]))
    assert post.clearance(q[0][0]).distance == pytest.approx(result.min_clearance, abs=1e-9)
    assert "screening" not in result.summary()
    assert f"smallest clearance {result.min_clearance * 1e3:.1f} mm (arm_upper_arm ↔ post" in result.summary()
    held = ("no contact along the whole motion" if clearance == 0.0 else
            f"the {clearance * 1e3:g} mm clearance holds along the whole motion")
    assert f"{held} (proven: no two shapes closer than {result.lower_bound * 1e3:.1f} mm)" in result.summary()


def test_the_old_names_of_the_minimum_warn_and_agree(post):
    result = post.check_motion({"arm": SWEEP}, margin=0.01, clearance=0.02)
    with pytest.deprecated_call():
        assert result.min_sample_distance == result.min_clearance
    with pytest.deprecated_call():
        assert result.min_clearance_is_exact


def test_in_collision_and_collisions_at_a_margin_see_the_post(post):
    q = np.zeros(post.nq)  # the end face square to the post: 15.5 mm
    d = Reference(post).distances(q)
    assert not post.in_collision(q, margin=0.015)
    assert post.in_collision(q, margin=0.016)
    hits = post.collisions(q, margin=0.016)
    assert [p.bodies for p in hits.pairs_at(0)] == [("arm_upper_arm", "post")]
    assert abs(post.clearance(q).distance - d.min()) < 1e-9
    assert post.clearance(q).pair_of().bodies == ("arm_upper_arm", "post")
    assert len(repr(hits)) < 200


def test_two_facing_scaras_clearance_is_arm_to_the_other_base(facing):
    q = facing.q_from_arms({"one": [np.pi / 2, 0, 0, 0], "two": [np.pi / 2, 0, 0, 0]})
    external = facing.with_pairs("external")
    result = external.clearance(q)
    assert abs(result.distance - 0.76) < 1e-9
    pair = result.pair_of()
    assert {pair.body_a, pair.body_b} in ({"one_base_link", "two_upper_arm"}, {"two_base_link", "one_upper_arm"})
    # the checked pairs alone (the old answer) miss it
    old, _, _, _ = exact_min_distance(external, q[None])
    assert old[0] > 0.8
    # the whole cell: the reference minimum over all pairs not allowed by design
    assert abs(facing.clearance(q).distance - Reference(facing).distances(q).min()) < 1e-9


def test_a_clearance_prints_a_short_summary_and_keeps_its_tables():
    line = load_cell("mushroom_line")
    Q = line.random_q(60, seed=3)
    result = line.clearance(Q)
    text = repr(result)
    assert len(text) < 300 and "mm" in text and " – " in text and "of 60" in text
    assert result.distance.shape == (60,) and result.point_a.shape == (60, 3)
    assert len(result.pairs) == len(line.pairs_for(float("inf")))


def test_a_view_of_some_kinds_keeps_only_their_out_of_reach_pairs(facing):
    arm_arm = facing.with_pairs("arm-arm")
    assert all(p.kind == "arm-arm" for p in arm_arm.pairs_for(float("inf")))
    assert len(arm_arm.pairs_for(float("inf"))) > len(arm_arm.pairs)


def test_the_planner_checks_the_pairs_not_proven_beyond_its_margin(post):
    from pinarms.optim.motion.checker import MotionChecker

    checker = MotionChecker(post, ["arm"], margin=0.02)
    assert ("arm_upper_arm", "post") in [p.bodies for p in checker.pairs]
    assert not checker.state_valid(np.zeros(4))  # 15.5 mm from the post: closer than 20 mm
    e, pair, d = checker.closest(np.zeros(4))
    assert pair.bodies == ("arm_upper_arm", "post") and abs(d - 0.0155) < 1e-3
    small = MotionChecker(post, ["arm"], margin=0.001)
    assert ("arm_upper_arm", "post") not in [p.bodies for p in small.pairs]
    assert small.state_valid(np.zeros(4))


def test_arm_motion_offsets_keep_the_pair_order(post):
    result = post.check_motion([ArmMotion("arm", SWEEP, offset=2.0)], margin=0.01, clearance=0.02)
    assert result.window == (2.0, 3.0)
    assert result.pairs == post.pairs_for(0.03 + 1e-6)


@pytest.mark.parametrize("name", ["mushroom_line", "aubo_food_station", "post", "facing"])
def test_every_out_of_reach_bound_holds_on_random_configurations(name, post, facing):
    _bounds_hold(({"post": post, "facing": facing}.get(name) or load_cell(name)))


@pytest.mark.slow
@pytest.mark.parametrize("name", scene_names())
def test_every_out_of_reach_bound_of_the_scenes_holds_on_random_configurations(name):
    _bounds_hold(load_scene(name))


def _bounds_hold(cell):
    import pinocchio as pin

    from pinarms.robots.collision_requests import cold_start

    reach = [p for p in cell.allowed if p.reason == "out of reach"]
    gm = cell.collision_model.copy()
    gm.removeAllCollisionPairs()
    for p in reach:
        gm.addCollisionPair(pin.CollisionPair(p.index_a, p.index_b))
    gd = cold_start(pin.GeometryData(gm), distance_tolerance=1e-10)
    data = cell.model.createData()
    bounds = np.array([p.distance_bound for p in reach])
    smallest = np.full(len(reach), np.inf)
    for q in cell.robot.q_to_pinocchio(cell.random_q(400, seed=21)):
        pin.updateGeometryPlacements(cell.model, data, gm, gd, q)
        pin.computeDistances(gm, gd)
        smallest = np.minimum(smallest, [r.min_distance for r in gd.distanceResults])
    assert np.all(bounds > 0.0)
    assert np.all(smallest >= bounds - 1e-9), [(reach[k].body_a, reach[k].body_b) for k in np.flatnonzero(smallest < bounds)]
