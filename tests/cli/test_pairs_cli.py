"""`pinarms pairs ROBOT`: the self-collision pairs of one arm, and why each skipped pair is skipped."""

from __future__ import annotations

from tests.cli.cli_results import as_json, assert_user_error


def test_pairs_lists_each_skipped_pair_of_links_with_its_reason_and_note(run):
    text = run("pairs", "gantry_flower").stdout
    assert "pairs checked: " in text
    assert "skipped (declared): x_carriage_link – z_ram_link (the y carriage wraps the bridge beam" in text
    assert "skipped (adjacent): " in text
    data = as_json(run("pairs", "gantry_flower", "--json"))
    ram = [a for a in data["allowed"] if set(a["bodies"]) == {"x_carriage_link", "z_ram_link"}]
    assert ram and ram[0]["reason"] == "declared" and "10 mm" in ram[0]["note"]
    assert data["pairs_checked"] == len(data["checked"]) > 0
    assert sum(data["pairs_allowed"].values()) == len(data["allowed"])


def test_pairs_of_an_unknown_robot_is_one_error_line(run):
    assert_user_error(run("pairs", "gantry_flowr", ok=False), 1, "gantry_flower")


def test_pairs_of_a_urdf_with_a_link_through_its_base_is_one_error_line_naming_them(run, tmp_path):
    from tests.robots.test_self_collision import _arm

    text = _arm('<box size="0.04 0.04 0.04"/>').replace(
        '<link name="link2"><collision>', '<link name="link2"><collision><origin xyz="0.1 0.05 0"/>')
    path = tmp_path / "plate_arm.urdf"
    path.write_text(text, encoding="utf-8")
    assert_user_error(run("pairs", str(path), ok=False), 1, "base_link – link2", "mm deep", "<disable_collisions")
