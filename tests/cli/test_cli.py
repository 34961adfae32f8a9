"""The `pinarms` command line through click's CliRunner: output, --json, units, errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from pinarms import robots
from pinarms.cli import read_via_file
from pinarms.papers import SEED000 as PAPER000
from tests.cli.cli_results import as_json, assert_user_error

SEED000 = [arg for deg in PAPER000.path_deg for arg in ("--via", f"{deg:g}")]  # --via 55.5 --via 69.7 ...


def test_robots_lists_every_name_with_dof(run):
    data = as_json(run("robots", "--json"))
    by_name = {r["name"]: r for r in data["robots"]}
    assert list(by_name) == robots.names()
    assert by_name["aubo_i3"]["dof"] == 6 and by_name["koji_turner"]["dof"] == 4
    assert by_name["panda"]["dof"] == 7 and by_name["panda"]["source"] == "example-robot-data"
    text = run("robots").stdout
    assert "scara_mushroom" in text and "ur5" in text


def test_fk_koji_paper_example_in_degrees_and_mm(run):
    # seed 004: (-90, 25, -30, 90) deg -> (1197.3, 250.0, -929.2) mm
    data = as_json(run("fk", "koji_turner", "-90", "25", "-30", "90", "--deg", "--mm", "--json"))
    np.testing.assert_allclose(data["position"], [1197.3, 250.0, -929.2], atol=0.05)
    assert data["units"] == {"position": "mm", "angles": "deg"}
    np.testing.assert_allclose(data["q_si"], np.radians([-90, 25, -30, 90]))
    assert data["within_limits"] is True
    text = run("fk", "koji_turner", "-90", "25", "-30", "90", "--deg", "--mm").stdout
    assert "1197.33" in text


def test_fk_si_matches_api_and_prismatic_mm(run):
    arm = robots.load("gantry_flower")
    q = np.array([0.3, 0.2, -0.1])
    data = as_json(run("fk", "gantry_flower", "300", "200", "-100", "--mm", "--json"))
    np.testing.assert_allclose(data["q_si"], q)
    np.testing.assert_allclose(np.array(data["T"]), arm.fk(q), atol=1e-12)
    np.testing.assert_allclose(data["position"], arm.position(q) * 1000, atol=1e-9)


def test_fk_frame_option_and_limit_warning(run):
    arm = robots.load("scara_mushroom")
    data = as_json(run("fk", "scara_mushroom", "0", "0", "0", "0", "--frame", "flange", "--json"))
    np.testing.assert_allclose(data["position"], arm.position(np.zeros(4), frame="flange"))
    text = run("fk", "scara_mushroom", "3", "0", "0", "0").stdout
    assert "outside the joint limits" in text and "j1" in text


def test_fk_errors_are_one_line(run):
    assert_user_error(run("fk", "no_such_arm", "1", ok=False), 1, "unknown robot 'no_such_arm'", "aubo_i3")
    assert_user_error(run("fk", "ur5", "1", "2", ok=False), 1, "has 6 joints", "got 2")
    assert_user_error(run("fk", "ur5", "1", "x", "0", "0", "0", "0", ok=False), 2, "not a valid float")
    assert_user_error(run("fk", "ur5", "0", "0", "0", "0", "0", "0", "--frame", "nope", ok=False), 1, "no frame 'nope'")
    assert_user_error(run("fk", "ok", ok=False), 2, "Missing argument")


def test_ik_round_trip_or_clear_error(run):
    arm = robots.load("koji_turner")
    result = run("ik", "koji_turner", "1197.3", "250", "-929.2", "--mm", "--deg", "--json")
    data = as_json(result)
    assert data["solutions"]
    for sol in data["solutions"]:
        assert sol["position_error_m"] < 1e-6
        p = arm.position(np.radians(sol["q"]))
        np.testing.assert_allclose(p * 1000, [1197.3, 250.0, -929.2], atol=1e-3)
    assert_user_error(run("ik", "koji_turner", "10", "10", "10", ok=False), 1, "out of reach")


def test_ik_all_without_solution_says_why(run):
    # seed 004's printed pose needs the shoulder 0.0011° past its 25° range end
    data = as_json(run("ik", "koji_turner", "1197.3", "250", "-929.2", "0", "0", "0", "--mm", "--deg", "--all", "--json"))
    assert data["solutions"] == []
    assert "outside its limits" in data["reason"] and "shoulder" in data["reason"]


def test_ik_all_needs_a_closed_form_and_pose_size(run):
    assert_user_error(run("ik", "ur5", "0.1", "0.2", ok=False), 1, "3 or 6 numbers")
    assert not robots.load("panda").has_analytic_ik
    assert_user_error(run("ik", "panda", "0.3", "0.1", "0.4", "--all", ok=False), 1, "no closed-form IK")
    data = as_json(run("ik", "ur5", "0.3", "0.1", "0.4", "180", "0", "0", "--deg", "--all", "--json"))
    assert len(data["solutions"]) >= 2


def test_plan_seed000_peaks_and_limit_check(run, tmp_path):
    args = ["plan", "--kind", "3-5-3", "--deg", "--times", "0,2,4,6", *SEED000, "--vmax", "55"]
    data = as_json(run(*args, "--json"))
    from pinarms import planning

    traj = planning.piecewise_polynomial(PAPER000.initial_knot_times_s, PAPER000.path_rad, degrees=(3, 5, 3))
    assert data["duration_s"] == pytest.approx(6.0)
    assert data["peaks"]["velocity"][0] == pytest.approx(np.degrees(traj.peaks().velocity[0]), rel=1e-9)
    assert data["limits_ok"] is True
    tight = as_json(run(*args[:-1], "20", "--json"))
    assert tight["limits_ok"] is False
    assert tight["violations"][0]["kind"].startswith("vel") and tight["violations"][0]["limit"] == pytest.approx(20)
    assert_user_error(run(*args, "--session", str(tmp_path / "p.pinarms"), ok=False), 2, "--robot")
    text = run("plan", "--kind", "quintic-bspline", "--times", "0,1,2,3", "--via", "0,0", "--via", "-0.5,0.2",
               "--via", "0.3,0.4", "--via", "1,1").stdout
    assert "quintic-bspline trajectory: 2 joint(s)" in text


def test_plan_from_csv_and_json_files(run, tmp_path):
    csv_file = tmp_path / "via.csv"
    csv_file.write_text("t,j1,j2\n0,0,0\n1,0.5,-0.2\n3,1.0,0.1\n4,1.2,0.0\n")
    doc = read_via_file(str(csv_file))
    np.testing.assert_allclose(doc["times"], [0, 1, 3, 4])
    assert doc["positions"].shape == (4, 2) and doc["joint_names"] == ["j1", "j2"]
    a = as_json(run("plan", "--kind", "multi-quintic", "--file", str(csv_file), "--json"))
    json_file = tmp_path / "via.json"
    json_file.write_text(json.dumps({"kind": "multi-quintic", "times": [0, 1, 3, 4],
                                     "positions": doc["positions"].tolist()}))
    b = as_json(run("plan", "--file", str(json_file), "--json"))
    assert b["kind"] == "multi-quintic"
    np.testing.assert_allclose(a["peaks"]["velocity"], b["peaks"]["velocity"])
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert_user_error(run("plan", "--file", str(bad), ok=False), 1, "not valid JSON")


def test_plan_bad_input(run):
    assert_user_error(run("plan", "--times", "0,1", ok=False), 2, "--via")
    assert_user_error(run("plan", "--via", "1", "--via", "2", ok=False), 2, "--times")
    assert_user_error(run("plan", "--times", "0,1,x", "--via", "1", "--via", "2", ok=False), 2, "comma-separated")
    assert_user_error(run("plan", "--kind", "3-5-3", "--times", "0,1,1,2", *SEED000, ok=False), 1)
    assert_user_error(run("plan", "--kind", "spline9", ok=False), 2, "spline9")


def test_optimize_seed000_exact_and_ga(run, tmp_path):
    exact = as_json(run("optimize", "--kind", "3-5-3", "--deg", *SEED000, "--vmax", "55", "--method", "exact", "--json"))
    assert exact["peaks"]["velocity"][0] == pytest.approx(55.0, rel=1e-3)
    assert sum(exact["durations_s"]) == pytest.approx(exact["total_s"])
    ga = as_json(run("optimize", "--kind", "3-5-3", "--deg", *SEED000, "--vmax", "55", "--generations", "30",
                     "--seed", "1", "--json"))
    assert ga["method"] == "ga"
    assert ga["total_s"] >= exact["total_s"] * (1 - 1e-6)
    assert ga["total_s"] <= 6.0 and ga["peaks"]["velocity"][0] <= 55.0 * (1 + 1e-6)
    session = tmp_path / "opt.pinarms"
    assert_user_error(run("optimize", *SEED000, "--vmax", "55", "--session", str(session), ok=False), 2, "--robot")
    via4 = ["--via", "1,0.5,0.02,0", "--via", "1.2,0.8,0.05,0.3", "--via", "1.5,1.0,0.02,0.6"]
    data = as_json(run("optimize", "--kind", "multi-quintic", *via4, "--robot", "scara_mushroom", "--method", "exact",
                       "--session", str(session), "--json"))
    arm = robots.load("scara_mushroom")
    assert np.all(np.array(data["peaks"]["velocity"]) <= arm.velocity_limit * (1 + 1e-6))
    assert session.is_file()
    assert_user_error(run("optimize", *SEED000, ok=False), 2, "--vmax")
    assert_user_error(run("optimize", *SEED000, "--vmax", "-1", ok=False), 1)


def test_export_html_and_view(run, tmp_path):
    session = tmp_path / "s.pinarms"
    run("plan", "--kind", "multi-quintic", "--times", "0,1,2", "--via", "0,0,0,0", "--via", "0.5,0.1,0.02,0",
        "--via", "1,0.2,0.05,0.5", "--robot", "scara_mushroom", "--session", str(session))
    out = tmp_path / "s.html"
    data = as_json(run("export-html", str(session), str(out), "--json"))
    assert out.is_file() and data["bytes"] == out.stat().st_size > 100_000
    assert "<html" in out.read_text(encoding="utf-8", errors="replace")[:2000].lower()
    view = as_json(run("view", str(session), "--no-wait", "--json"))
    assert view["url"].startswith("http://127.0.0.1:")
    assert_user_error(run("export-html", str(tmp_path / "missing.pinarms"), str(out), ok=False), 2, "does not exist")
    corrupt = tmp_path / "corrupt.pinarms"
    corrupt.write_bytes(b"not a session")
    assert_user_error(run("view", str(corrupt), "--no-wait", ok=False), 1)


def test_urdf_build_check_and_export(run, tmp_path):
    data = as_json(run("urdf", "build", "--out", str(tmp_path / "built"), "--json"))
    from pinarms.robots.cell import cell_names

    assert len(data["written"]) == len(robots.builtin_names()) + len(cell_names())  # arms and cells
    assert as_json(run("urdf", "build", "--check", "--json"))["stale"] == []
    out = tmp_path / "koji"
    data = as_json(run("urdf", "export", "koji_turner", str(out), "--json"))
    text = (out / "koji_turner.urdf").read_text()
    assert "<mimic" in text and data["urdf"].endswith("koji_turner.urdf")
    assert_user_error(run("urdf", "export", "koji_turner", str(out), ok=False), 1, "not empty")
    run("urdf", "export", "koji_turner", str(out), "--overwrite")
    assert_user_error(run("urdf", "export", "nope", str(tmp_path / "n"), ok=False), 1, "unknown robot")


def test_deg_with_a_robot_keeps_prismatic_joints_in_metres(run):
    # scara_mushroom's j3 is a prismatic stroke: 0.05 -> 0.10 m must stay metres under --deg
    via_deg = ["--via", "10,20,0.05,0", "--via", "20,30,0.1,0", "--via", "30,30,0.15,0"]
    via_si = [a if a == "--via" else ",".join(f"{v:.17g}" for v in np.array(a.split(","), float)
                                               * [np.pi / 180, np.pi / 180, 1, np.pi / 180]) for a in via_deg]
    common = ["--kind", "multi-quintic", "--robot", "scara_mushroom", "--json"]
    plan = as_json(run("plan", *common, "--deg", "--times", "0,1,2", *via_deg))
    assert plan["units"] == "deg|m"
    # quintic rest-to-rest over 1 s: peak |v| = 1.875 · stroke
    assert plan["peaks"]["velocity"][2] == pytest.approx(1.875 * 0.05, rel=1e-9)
    assert plan["peaks"]["velocity"][0] == pytest.approx(1.875 * 10, rel=1e-9)
    deg = as_json(run("optimize", *common, "--deg", "--method", "exact", *via_deg))
    si = as_json(run("optimize", *common, "--method", "exact", *via_si))
    assert deg["total_s"] == pytest.approx(si["total_s"], rel=1e-6)
    np.testing.assert_allclose(deg["peaks"]["velocity"][2:3], si["peaks"]["velocity"][2:3], rtol=1e-6)
    # the prismatic stroke is what limits the timing here: 0.5 m/s on j3
    assert si["peaks"]["velocity"][2] == pytest.approx(robots.load("scara_mushroom").velocity_limit[2], rel=1e-3)


def test_limit_options_are_never_silently_ignored(run):
    one = ["plan", "--kind", "multi-quintic", "--times", "0,1", "--via", "1", "--via", "2"]
    assert_user_error(run(*one, "--amax", "1", ok=False), 2, "--vmax")
    assert_user_error(run(*one, "--jmax", "1", ok=False), 2, "--vmax")
    data = as_json(run(*one, "--vmax", "10", "--amax", "1", "--json"))
    assert data["limits_ok"] is False and data["violations"][0]["kind"].startswith("acc")
    four = ["plan", "--kind", "multi-quintic", "--times", "0,1", "--via", "1,0,0,0", "--via", "2,0,0,0",
            "--robot", "scara_mushroom"]
    assert_user_error(run(*four, "--vmax", "1,2", ok=False), 1, "--vmax takes one value or one per joint (4)")
    assert_user_error(run("plan", *one[1:], "--robot", "scara_mushroom", ok=False), 1, "has 4 joints", "1 value")


def test_ik_seed_q_of_the_wrong_size_is_a_one_line_error(run):
    assert_user_error(run("ik", "koji_turner", "1197.3", "250", "-929.2", "--mm", "--deg", "--seed-q", "1,2",
                          ok=False), 1, "--seed-q needs 4 values", "got 2")
    data = as_json(run("ik", "koji_turner", "1.1973", "0.25", "-0.9292", "--seed-q", "-1.5,0.4,-0.5,1.5", "--json"))
    assert data["solutions"][0]["position_error_m"] < 1e-9


def test_optimize_progress_bar_spans_the_default_generation_budget(run, monkeypatch):
    import re

    import pinarms.cli._common as cli_common
    from pinarms import optim

    monkeypatch.setattr(cli_common, "show_progress", lambda as_json: not as_json)  # as on a terminal
    budget = optim.GASettings.seed002().max_generations

    def last_state(result) -> tuple[int, int]:
        line = result.stderr.split("\r\x1b[2K")[-1]
        assert line.startswith("GA generations  [") and line.endswith("s\n"), line
        done, total = re.search(r"(\d+)/(\d+)", line).groups()
        return int(done), int(total)

    done, total = last_state(run("optimize", "--kind", "3-5-3", "--deg", *SEED000, "--vmax", "55"))
    assert total == budget and 0 < done <= total
    done, total = last_state(run("optimize", "--kind", "3-5-3", "--deg", *SEED000, "--vmax", "55", "--generations", "7"))
    assert total == 7 and done <= 7
    quiet = run("optimize", "--kind", "3-5-3", "--deg", *SEED000, "--vmax", "55", "--generations", "7", "--json")
    assert quiet.stderr == ""  # never with --json
    assert run("optimize", "--kind", "3-5-3", "--deg", *SEED000, "--vmax", "55", "--method", "exact").stderr == ""


def test_ik_names_closed_form_solutions_just_outside_the_ranges(run):
    """seed 004: (1197.3, 250, -929.2) mm needs the shoulder 0.0011° above 25° and the forearm 0.0046° below -30°."""
    out = run("ik", "koji_turner", "1197.3", "250", "-929.2", "--mm", "--deg").output
    assert "note: the closed-form solution (-90  25.0011  -30.0046  90) lies outside the joint ranges: " \
           "shoulder by 0.001128 deg (above 25), forearm by 0.004608 deg (below -30); --limit-tol 0.0047 accepts it" in out
    data = as_json(run("ik", "koji_turner", "1197.3", "250", "-929.2", "--mm", "--deg", "--limit-tol", "0.0047", "--json"))
    (sol,) = data["solutions"]
    np.testing.assert_allclose(sol["q"], [-90.0, 25.0011, -30.0046, 90.0], atol=1e-4)
    assert sol["position_error_m"] < 1e-9
    assert sol["outside_limits"] == pytest.approx({"shoulder": 0.0011279, "forearm": -0.0046080}, abs=1e-6)
    # too small a tolerance: the numerical solution within the ranges, and the note again
    data = as_json(run("ik", "koji_turner", "1197.3", "250", "-929.2", "--mm", "--deg", "--limit-tol", "0.004", "--json"))
    assert data["solutions"][0]["outside_limits"] == {} and len(data["near_limit_solutions"]) == 1
    pose = ("1197.3", "250", "-929.2", "0", "0", "0", "--mm", "--deg")
    assert_user_error(run("ik", "koji_turner", *pose, ok=False), 1, "needs shoulder 0.001128 deg above its range end 25",
                      "--limit-tol accepts")
    data = as_json(run("ik", "koji_turner", *pose, "--limit-tol", "0.005", "--json"))
    np.testing.assert_allclose(data["solutions"][0]["q"], [-90.0, 25.0011, -30.0046, 90.0], atol=1e-4)


def test_unreachable_target_in_the_units_typed(run):
    err = run("ik", "koji_turner", "3000", "10", "10", "--mm", ok=False)
    assert_user_error(err, 1, "reaches (3000, 10, 10) mm", "out of reach", "1547 mm away")
    err = run("ik", "koji_turner", "3", "0.01", "0.01", ok=False)
    assert_user_error(err, 1, "reaches (3, 0.01, 0.01) m", "1.547 m away")


def test_robot_name_typo_suggests_close_names(run):
    assert_user_error(run("fk", "aubo_i5", "0", "0", "0", "0", "0", "0", ok=False), 1, "did you mean aubo_i3?")


def test_bad_csv_names_row_and_column(run, tmp_path):
    bad = tmp_path / "via.csv"
    bad.write_text("t,j1,j2\n\n0,0.1,0.2\n1,0.3,abc\n2,0.5,0.6\n", encoding="utf-8")
    assert_user_error(run("plan", "--kind", "multi-quintic", "--file", str(bad), ok=False), 1,
                      "CSV row 4, column 3 ('j2'): 'abc' is not a finite number")
    bad.write_text("t,j1,j2\n0,0.1,0.2\n1,0.3\n", encoding="utf-8")
    assert_user_error(run("plan", "--kind", "multi-quintic", "--file", str(bad), ok=False), 1,
                      "CSV row 3 has 2 cells, the header has 3 (t, j1, j2)")
    bad.write_text("t,j1\n0,0\n1,nan\n", encoding="utf-8")
    assert_user_error(run("plan", "--kind", "multi-quintic", "--file", str(bad), ok=False), 1, "row 3, column 2 ('j1')")


def test_piecewise_degrees_must_be_whole_numbers(run):
    base = ["plan", "--kind", "piecewise", "--times", "0,1,2,3", "--via", "0", "--via", "1", "--via", "2", "--via", "3"]
    assert_user_error(run(*base, "--degrees", "3.5,5,3", ok=False), 2, "whole polynomial degrees")
    assert_user_error(run(*base, "--degrees", "0,5,3", ok=False), 2, "whole polynomial degrees")
    data = as_json(run(*base, "--degrees", "3,5,3", "--json"))
    assert data["duration_s"] == pytest.approx(3.0)


@pytest.mark.parametrize("doc, fragment", [
    ({"positions": [["a"], ["b"]], "times": [0, 1]}, "'positions' must be rows of numbers"),
    ({"positions": [[1, 2], [3]], "times": [0, 1]}, "'positions' must be rows of numbers"),
    ({"positions": [[[1]], [[2]]], "times": [0, 1]}, "2-D list"),
    ({"positions": [1, 2], "times": "x"}, "'times' must be a list of numbers"),
    ({"positions": [0, 1], "times": [0, 1], "kind": "spline9"}, "unknown 'kind' 'spline9'"),
    ({"positions": [0, 1], "times": [0, 1], "kind": "polynomial", "degree": "x"}, "'degree' must be a whole number"),
])
def test_corrupt_via_files_are_one_line_errors(run, tmp_path, doc, fragment):
    path = tmp_path / "via.json"
    path.write_text(json.dumps(doc))
    assert_user_error(run("plan", "--file", str(path), ok=False), 1, fragment)
    assert_user_error(run("optimize", "--file", str(path), "--vmax", "1", ok=False), 1, fragment)


def test_one_column_json_via_file_plans(run, tmp_path):
    path = tmp_path / "via.json"
    path.write_text(json.dumps({"positions": [0, 1], "times": [0, 2], "kind": "polynomial", "degree": 5}))
    data = as_json(run("plan", "--file", str(path), "--json"))
    assert data["kind"] == "polynomial" and data["n_joints"] == 1
    assert data["peaks"]["velocity"][0] == pytest.approx(1.875 / 2)


