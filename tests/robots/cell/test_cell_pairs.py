"""A pair is left out of a check only when it is proven farther than the clearance asked (issue 24 item 1)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from pinarms import planning
from pinarms.optim.motion.scenes import load_scene, scene_names
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.robots.cell.collision import exact_min_distance
from pinarms.robots.cell.pairs import PairReason
from pinarms.errors import CellError, InvalidInput, PlacementError

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
    assert "smallest clearance 13.0 mm (arm_upper_arm ↔ post at t = 0.46" in repr(result)  # the earlier of two equal minima
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


# ----------------------------------------------- fixtures through an arm (issue 35 item 1)
SCARA_000 = Path(__file__).resolve().parents[3] / "urdf" / "scara_mushroom.urdf"


def _scara_with(tmp_path, fixture: str, extra: str = "") -> Path:
    """A cell description of seed 000's SCARA at the origin and one fixture (TOML lines ``fixture``)."""
    shutil.copy(SCARA_000, tmp_path / "scara.urdf")
    path = tmp_path / "cell.toml"
    path.write_text(f'name = "scara_fixture"\n[[arm]]\nname = "arm"\nurdf = "scara.urdf"\n[[fixture]]\n{fixture}\n'
                    f"{extra}", encoding="utf-8")
    return path


def test_a_table_through_the_scaras_links_is_a_placement_error_naming_the_pairs_and_depth(tmp_path):
    path = _scara_with(tmp_path, 'name = "table"\nbox = [1.6, 1.6, 0.04]\nxyz = [0.0, 0.0, 0.30]')
    with pytest.raises(PlacementError) as err:
        load_cell(path)
    text = str(err.value)
    for link in ("arm_upper_arm_link", "arm_forearm_link", "arm_quill_link", "arm_j2_drive"):
        assert f"{link} – table" in text, text
    assert "in collision" in text and "mm deep" in text and "disable_collisions" in text
    deepest = {(a, b): depth for a, b, share, depth in err.value.pairs}
    assert deepest[("arm_upper_arm_link", "table")] == pytest.approx(0.02, abs=1e-6)  # box top 0.30, table bottom 0.28
    assert all(share >= 0.95 for _, _, share, _ in err.value.pairs)


def test_a_sphere_fixture_around_the_whole_arm_is_a_placement_error(tmp_path):
    with pytest.raises(PlacementError, match="arm_forearm_link – ball"):
        load_cell(_scara_with(tmp_path, 'name = "ball"\nsphere = 3.0\nxyz = [0.0, 0.0, 0.3]'))


def test_a_base_mounted_on_its_table_is_allowed_as_rigid_and_the_links_above_are_checked(tmp_path):
    cell = load_cell(_scara_with(tmp_path, 'name = "table"\nbox = [1.6, 1.6, 0.04]\nxyz = [0.0, 0.0, 0.10]'))
    reasons = {(p.body_a, p.body_b): p.reason for p in cell.allowed}
    assert reasons[("arm_base_link", "table")] == PairReason.RIGID
    assert not any(p.reason not in PairReason.__members__.values() for p in cell.allowed)


def test_a_declared_contact_is_allowed_by_name_and_an_unknown_link_is_refused(tmp_path):
    declared = ('\n[[disable_collisions]]\nlink1 = "arm_upper_arm_link"\nlink2 = "table"\n'
                'reason = "the slab is cut out for the arm"\n')
    table = 'name = "table"\nbox = [1.6, 1.6, 0.04]\nxyz = [0.0, 0.0, 0.30]'
    with pytest.raises(PlacementError) as err:  # the other links are still through the table
        load_cell(_scara_with(tmp_path, table, declared))
    assert "arm_upper_arm_link – table" not in str(err.value) and "arm_forearm_link – table" in str(err.value)
    cell_text = post_cell_text().replace(
        "</robot>", '<disable_collisions link1="post" link2="arm_forearm" reason="by design"/></robot>')
    cell = make_cell(cell_text, "declared")
    declared_pairs = [p for p in cell.allowed if p.reason == PairReason.DECLARED]
    assert {(p.body_a, p.body_b) for p in declared_pairs} == {("arm_forearm", "post")}
    assert all(p.note == "by design" and p.distance_bound == np.inf for p in declared_pairs)
    with pytest.raises(CellError, match="disable_collisions.*'nowhere'"):
        make_cell(post_cell_text().replace("</robot>", '<disable_collisions link1="post" link2="nowhere"/></robot>'),
                  "unknown")


def test_a_shape_turning_about_its_own_axis_is_coaxial_and_proven_not_sampled():
    """A cylinder along the first joint's axis fills the same space at every angle: in contact with the table it
    stands on by design; the box on the same link is not (a placement error)."""
    def arm(shapes: str) -> str:
        return ('<robot name="hub"><link name="world"/>'
                '<link name="table"><collision><geometry><box size="1 1 0.1"/></geometry></collision></link>'
                '<joint name="table_joint" type="fixed"><parent link="world"/><child link="table"/>'
                '<origin xyz="0 0 -0.05"/></joint><link name="hub_base_link"/>'
                '<joint name="hub_mount" type="fixed"><parent link="world"/><child link="hub_base_link"/></joint>'
                f'<link name="hub_link1">{shapes}</link>'
                '<joint name="hub_j1" type="revolute"><parent link="hub_base_link"/><child link="hub_link1"/>'
                '<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint></robot>')

    hub = '<collision><origin xyz="0 0 0.05"/><geometry><cylinder radius="0.05" length="0.2"/></geometry></collision>'
    cell = make_cell(arm(hub), "hub")
    (pair,) = [p for p in cell.allowed if {p.body_a, p.body_b} == {"hub_link1", "table"}]
    assert pair.reason == PairReason.COAXIAL
    bar = '<collision><origin xyz="0.2 0 0"/><geometry><box size="0.3 0.05 0.05"/></geometry></collision>'
    with pytest.raises(PlacementError, match="hub_link1 – table"):
        make_cell(arm(hub + bar), "bar")


def test_cell_show_lists_the_skipped_pairs_with_their_reason(tmp_path):
    from click.testing import CliRunner

    from pinarms.cli import cli

    declared = '[[disable_collisions]]\nlink1 = "arm_hand_link"\nlink2 = "table"\nreason = "a soft pad"\n'
    path = _scara_with(tmp_path, 'name = "table"\nbox = [1.6, 1.6, 0.04]\nxyz = [0.0, 0.0, 0.10]', declared)
    out = CliRunner().invoke(cli, ["cell", "show", str(path)])
    assert out.exit_code == 0, out.output
    assert "skipped (rigid): arm_base_link – table" in out.stdout
    assert "skipped (adjacent): arm_base_link – arm_upper_arm_link" in out.stdout
    assert "skipped (declared): arm_hand_link – table (a soft pad)" in out.stdout
    data = json.loads(CliRunner().invoke(cli, ["cell", "show", str(path), "--json"]).stdout)
    rows = {tuple(r["bodies"]): r for r in data["allowed"]}
    assert rows[("arm_base_link", "table")]["reason"] == "rigid" and rows[("arm_base_link", "table")][
        "distance_bound_m"] is None
    assert rows[("arm_hand_link", "table")]["note"] == "a soft pad"
    bad = _scara_with(tmp_path, 'name = "table"\nbox = [1.6, 1.6, 0.04]\nxyz = [0.0, 0.0, 0.30]')
    out = CliRunner().invoke(cli, ["cell", "check", str(bad), "--random", "200"])
    assert out.exit_code == 1 and out.stderr.startswith("Error:") and out.stderr.count("\n") == 1, out.output
    assert "arm_upper_arm_link – table" in out.stderr


def test_the_sampled_pair_reasons_are_cached_by_content_and_a_poisoned_file_is_sampled_again(tmp_path, monkeypatch):
    """Issue 36 item 8: the 200-configuration sampling is kept in the user's cache folder; a planted file that
    calls every pair in contact in every configuration (a placement error, or pairs allowed) is refused by the check
    of its first configurations."""
    from pinarms.robots.cell import pair_samples

    monkeypatch.setenv("PINARMS_CACHE_DIR", str(tmp_path))
    make_cell(post_cell_text(), "post")
    assert not (tmp_path / "pair_samples").exists()  # sampled in milliseconds: not worth a file
    monkeypatch.setattr(pair_samples, "MIN_SECONDS", 0.0)
    clean = make_cell(post_cell_text(), "post")
    (path,) = (tmp_path / "pair_samples").glob("*.npz")
    again = make_cell(post_cell_text(), "post")
    assert again.pairs == clean.pairs and again.allowed == clean.allowed
    calls, measure = [], pair_samples._measure
    monkeypatch.setattr(pair_samples, "_measure", lambda *a: calls.append(1) or measure(*a))
    with np.load(path) as z:
        stored = {k: np.array(z[k]) for k in z.files}
    P = stored["hits"].size
    poison = dict(stored, hits=np.full(P, float(pair_samples.SAMPLES)), depth=np.full(P, 0.001),
                  first_depth=np.full_like(stored["first_depth"], 0.001),
                  first_hit=np.ones_like(stored["first_hit"]))
    np.savez(path, **poison)
    sampled = make_cell(post_cell_text(), "post")
    assert calls == [1] and sampled.pairs == clean.pairs and sampled.allowed == clean.allowed
    assert make_cell(post_cell_text(), "post").pairs == clean.pairs and calls == [1]  # the rewritten file is used


@pytest.mark.parametrize("entry, fragment", [
    ('link1 = "table"\nlink2 = "table"', "two different link names"),
    ('link1 = "table"\nlink2 = "arm_base_link"\nwhy = "typo"', "unknown key(s) why"),
    ('link1 = "table"\nlink2 = 3', "two different link names"),
    ('link1 = "table"\nlink2 = "arm_nowhere"', "'arm_nowhere'"),
])
def test_a_bad_declared_contact_in_a_description_is_a_cell_error(tmp_path, entry, fragment):
    path = _scara_with(tmp_path, 'name = "table"\nbox = [1.6, 1.6, 0.04]\nxyz = [0.0, 0.0, 0.10]',
                       f"[[disable_collisions]]\n{entry}\n")
    with pytest.raises(CellError, match="disable_collisions") as err:
        load_cell(path)
    assert fragment in str(err.value)


def test_two_links_of_one_arm_overlapping_away_from_their_joint_are_a_placement_error():
    """Self pairs: allowed only when joined by one joint; link 1's wide plate holds link 3 (two joints away) in every
    configuration: not adjacent, so never dropped because a sample found it in contact."""
    def link(name: str, shape: str, xyz: str = "0 0 0") -> str:
        return f'<link name="{name}"><collision><origin xyz="{xyz}"/><geometry>{shape}</geometry></collision></link>'

    def joint(name: str, parent: str, child: str, xyz: str) -> str:
        return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
                f'<origin xyz="{xyz}"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>'
                "</joint>")

    text = ('<robot name="plate"><link name="world"/><link name="p_base_link"/>'
            '<joint name="p_mount" type="fixed"><parent link="world"/><child link="p_base_link"/></joint>'
            + link("p_link1", '<box size="2 2 0.1"/>', "0 0 0.5") + joint("p_j1", "p_base_link", "p_link1", "0 0 0")
            + link("p_link2", '<sphere radius="0.01"/>', "0 0 0.3") + joint("p_j2", "p_link1", "p_link2", "0.1 0 0")
            + link("p_link3", '<box size="0.05 0.05 0.05"/>', "0 0 0.5") + joint("p_j3", "p_link2", "p_link3", "0.1 0 0")
            + "</robot>")
    with pytest.raises(PlacementError, match="p_link1 – p_link3 in 100% of 200") as err:
        make_cell(text, "plate")
    assert [(a, b) for a, b, _, _ in err.value.pairs] == [("p_link1", "p_link3")]
    assert err.value.pairs[0][3] == pytest.approx(0.075, abs=1e-6)  # inside the 100 mm plate: 75 mm to push it out
    allowed = make_cell(text.replace("</robot>", '<disable_collisions link1="p_link3" link2="p_link1"/></robot>'),
                        "plate declared")
    assert {(p.body_a, p.body_b): p.reason for p in allowed.allowed}[("p_link1", "p_link3")] == PairReason.DECLARED


def test_an_arm_files_own_declared_contacts_come_with_it_into_a_composed_cell(tmp_path):
    shutil.copy(SCARA_000.with_name("gantry_flower.urdf"), tmp_path / "gantry.urdf")
    path = tmp_path / "cell.toml"
    path.write_text('name = "one_gantry"\n[[arm]]\nname = "g"\nurdf = "gantry.urdf"\n', encoding="utf-8")
    cell = load_cell(path)
    (pair,) = [p for p in cell.allowed if {p.body_a, p.body_b} == {"g_x_carriage_link", "g_z_ram_link"}]
    assert pair.reason == PairReason.DECLARED and "10 mm" in pair.note
