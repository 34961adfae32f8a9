"""`pinarms workspace` and `pinarms layout`: where one robot reaches, from the command line (CliRunner)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from tests.cli.cli_results import as_json, assert_user_error


def test_workspace_json_and_session(run, tmp_path):
    out = tmp_path / "ws.pinarms"
    data = as_json(run("workspace", "gantry_flower", "-n", "2000", "--seed", "3", "--json", "--session", str(out)))
    arm = robots.load("gantry_flower")
    lo, hi = np.array(data["bounding_box_m"]["min"]), np.array(data["bounding_box_m"]["max"])
    # the gantry's workspace is its stroke box (tcp offset aside): extent equals the strokes
    np.testing.assert_allclose(hi - lo, arm.upper - arm.lower, atol=0.02)
    assert data["n"] == 2000 and out.is_file()
    from pinarms import viz

    assert viz.load_session(out).workspaces
    assert_user_error(run("workspace", "gantry_flower", "-n", "0", ok=False), 2, "-n")


def test_workspace_progress_from_a_million_samples(run, monkeypatch):
    import pinarms.cli._common as cli_common

    monkeypatch.setattr(cli_common, "show_progress", lambda as_json: not as_json)
    assert run("workspace", "gantry_flower", "-n", "20000").stderr == ""
    big = run("workspace", "gantry_flower", "-n", "1000000")
    assert big.stderr.split("\r\x1b[2K")[-1].startswith("workspace samples  [########################]  1000000/1000000  100%")


def test_workspace_prints_the_recommended_table_region(run):
    from pinarms.robots.reach.table_band import recommend_region
    from pinarms.robots.reach.workspace import sample_workspace

    data = as_json(run("workspace", "aubo_i3", "-n", "3000", "--frame", "flange", "--json"))
    region = recommend_region(sample_workspace(robots.load("aubo_i3"), n=3000, seed=0, frame="flange"))
    assert data["region"]["side"] == "above" == region.side
    assert data["region"]["r_inner_m"] == pytest.approx(region.r_inner)
    assert data["region"]["r_outer_m"] == pytest.approx(region.r_outer)
    assert 0.1 < data["region"]["r_inner_m"] < data["region"]["r_outer_m"] < 0.8
    text = run("workspace", "aubo_i3", "-n", "3000", "--frame", "flange").stdout
    assert "recommended table region" in text and f"{region.r_outer * 1000:.0f} mm" in text


def test_layout_reports_reachable_and_unreachable_points(run):
    from pinarms.robots.reach.workspace import sample_workspace

    arm = robots.load("aubo_i3")
    result = run("layout", "aubo_i3", "0.3", "0.2", "0.2", "10", "0", "0", "-n", "5000", "--seed", "2", "--json")
    assert result.exit_code == 0  # an unreachable point is a report, not an error
    data = as_json(result)
    expected = robots.check_layout(arm, [[0.3, 0.2, 0.2], [10, 0, 0]], workspace=sample_workspace(arm, 5000, seed=2),
                                   seed=2)
    assert data["robot"] == "aubo_i3" and data["method"] == "analytic" and data["all_reachable"] is False
    assert data["n"] == 5000 and data["seed"] == 2 and data["units"]["position"] == "m"
    near, far = data["points"]
    assert [near["name"], far["name"]] == ["P1", "P2"]
    assert near["reachable"] is True and far["reachable"] is False
    p = expected.points[0]
    assert near["branches"] == p.n_branches >= 1 and near["solutions"] == p.n_solutions
    assert near["manipulability"] == pytest.approx(p.manipulability[p.best], rel=1e-12)
    assert near["dexterity_ratio"] == pytest.approx(p.dexterity_ratio, rel=1e-12) and near["dexterity_ratio"] > 0
    assert near["boundary_margin"] == pytest.approx(p.boundary_margin) and near["boundary_margin"] > 0
    np.testing.assert_allclose(arm.position(np.array(near["q_best_si"])), [0.3, 0.2, 0.2], atol=1e-9)
    assert far["branches"] == 0 and far["manipulability"] == 0 and far["q_best_si"] is None
    text = run("layout", "aubo_i3", "0.3", "0.2", "0.2", "10", "0", "0", "-n", "5000").stdout
    assert "NO" in text and "1 point(s) NOT reachable" in text
    assert "all points reachable" in run("layout", "aubo_i3", "0.3", "0.2", "0.2", "-n", "5000").stdout


def test_layout_mm_and_names(run):
    si = as_json(run("layout", "aubo_i3", "0.3", "-0.2", "0.25", "-n", "5000", "--json"))
    mm = as_json(run("layout", "aubo_i3", "300", "-200", "250", "--mm", "--names", "tray", "-n", "5000", "--json"))
    assert mm["units"]["position"] == mm["units"]["boundary_margin"] == "mm"
    assert mm["points"][0]["name"] == "tray" and mm["points"][0]["position"] == [300, -200, 250]
    assert mm["points"][0]["boundary_margin"] == pytest.approx(si["points"][0]["boundary_margin"] * 1000, rel=1e-9)
    assert mm["points"][0]["branches"] == si["points"][0]["branches"]
    assert mm["points"][0]["manipulability"] == pytest.approx(si["points"][0]["manipulability"], rel=1e-12)
    assert "margin [mm]" in run("layout", "aubo_i3", "300", "-200", "250", "--mm", "-n", "5000").stdout


def test_layout_bad_input_is_one_line(run):
    assert_user_error(run("layout", "aubo_i3", "0.3", "0.2", ok=False), 1, "X Y Z triples", "got 2")
    assert_user_error(run("layout", "aubo_i3", "0.3", "x", "0.2", ok=False), 2, "not a valid float")
    assert_user_error(run("layout", "aubo_i3", "0.3", "0.2", "0.1", "--names", "a,b", ok=False), 1, "--names needs 1")
    assert_user_error(run("layout", "no_such_arm", "0", "0", "0", ok=False), 1, "unknown robot")
    assert_user_error(run("layout", "aubo_i3", ok=False), 2, "Missing argument")
    assert_user_error(run("layout", "aubo_i3", "0", "0", "0", "-n", "0", ok=False), 2, "-n")


def test_workspace_text_gives_extent_and_manipulability_once(run):
    text = run("workspace", "aubo_i3", "-n", "2000", "--seed", "4").stdout
    assert text.count("bounding box") == 1 and "bounding box [mm]" in text
    assert text.count("manipulability: mean") == 1
    assert text.splitlines()[0] == "workspace of aubo_i3 (tcp), 2000 samples (seed 4)"
    data = as_json(run("workspace", "aubo_i3", "-n", "2000", "--seed", "4", "--json"))
    assert set(data) >= {"bounding_box_m", "manipulability", "summary", "region"}
