"""`pinarms motion CELL ...`: a planned, proven, timed move from the command line."""

from __future__ import annotations

import json
from pathlib import Path

from click.testing import CliRunner

from pinarms.cli import cli

WALL = str(Path(__file__).resolve().parents[1] / "optim" / "data" / "aubo_wall.urdf.xacro")


def test_motion_over_the_wall_json_and_session(tmp_path):
    out = tmp_path / "move.pinarms"
    result = CliRunner().invoke(cli, ["motion", WALL, "--from", "450", "200", "800", "--to", "450", "-200",
                                      "800", "--margin", "10", "--mm", "--time-limit", "30", "--json",
                                      "--session", str(out), "--plot", str(tmp_path / "clearance.png")])
    assert result.exit_code == 0, (result.output, result.exception)
    data = json.loads(result.stdout)
    assert data["arm"] == "aubo" and data["planner"] == "RRTConnect" and data["collision_free"]
    assert data["margin_m"] == 0.01 and data["min_clearance_environment_m"] >= 0.01
    assert data["duration_s"] > 0.0 and len(data["tool_path_world_m"]) == 50
    assert abs(data["tool_path_world_m"][-1][1] + 0.2) < 1e-6  # ends at the goal
    from pinarms import viz

    assert (tmp_path / "clearance.png").stat().st_size > 10_000
    session = viz.load_session(out)
    assert session.robot().nq == 6 and "motion" in session.trajectories


def test_motion_goal_inside_the_wall_is_one_error_line():
    result = CliRunner().invoke(cli, ["motion", WALL, "--from", "0.45", "0.2", "0.80", "--to", "0.45", "0.0", "0.80"])
    assert result.exit_code == 1
    assert "Traceback" not in result.output
    assert result.stderr.startswith("Error:") and "inside fixture 'wall'" in result.stderr


def test_motion_needs_an_arm_in_a_two_arm_cell():
    result = CliRunner().invoke(cli, ["motion", "mushroom_line", "--to", "0", "0", "0.9"])
    assert result.exit_code == 1 and "give --arm" in result.stderr


def test_motion_goals_best_is_never_slower_in_bound_and_stays_proven():
    args = ["motion", "aubo_crate_guard", "--from", "0.41", "0.10", "0.79", "--to", "0", "-0.465", "0.78",
            "--time-limit", "10", "--json"]
    first = CliRunner().invoke(cli, [*args, "--goals", "first"])
    best = CliRunner().invoke(cli, args)  # --goals best is the default
    assert first.exit_code == 0 and best.exit_code == 0, (first.output, best.output)
    a, b = json.loads(first.stdout), json.loads(best.stdout)
    assert b["collision_free"] and b["min_clearance_environment_m"] >= 0.01
    assert b["duration_s"] < a["duration_s"]  # seed 0: the first goal reached is the long way round
    bad = CliRunner().invoke(cli, [*args, "--goals", "all"])
    assert bad.exit_code != 0 and "'first', 'best'" in bad.output


def _bent_pair(folder: Path, hold: str = "") -> str:
    from tests.robots.cell.bent_pair import bent_pair

    return str(bent_pair(folder, "states = { home = [0.0, -1.2, 0.0] }\n" + hold))


def _one_error_line(result, *fragments: str) -> None:
    assert result.exit_code == 1, (result.output, result.exception)
    assert "Traceback" not in result.output and result.stderr.startswith("Error:") and result.stderr.count("\n") == 1
    for fragment in fragments:
        assert fragment in result.stderr, result.stderr


def test_motion_names_the_idle_arm_in_collision_at_once_and_hold_moves_it_clear(tmp_path):
    cell = _bent_pair(tmp_path)
    base = ["motion", cell, "--arm", "a", "--from-q", "0,-1,0", "--amax", "2"]
    inside_table = ["--to", "0.4", "-0.6", "0.53"]  # a goal inside the table: refused once b is clear
    _one_error_line(CliRunner().invoke(cli, [*base, "--to", "0.3", "0.6", "0.8"]),
                    "idle arm 'b' is in collision at its hold pose", "b_link2 – table", "--hold b=")
    for hold in ("b=0,-1.2,0", "b=home"):
        _one_error_line(CliRunner().invoke(cli, [*base, *inside_table, "--hold", hold]), "inside fixture 'table'")
    deg = ["motion", cell, "--arm", "a", "--from-q", "0,-57.3,0", "--amax", "2", "--deg", *inside_table]
    _one_error_line(CliRunner().invoke(cli, [*deg, "--hold", "b=0,-68.755,0"]), "inside fixture 'table'")
    _one_error_line(CliRunner().invoke(cli, [*deg, "--hold", "b=0,-1.2,0"]), "idle arm 'b'")  # -1.2 deg: in the table
    # a hold in the description does the same without the flag
    held = _bent_pair(tmp_path, 'hold = "home"\n')
    _one_error_line(CliRunner().invoke(cli, ["motion", held, "--arm", "a", "--from-q", "0,-1,0", "--amax", "2",
                                             *inside_table]), "inside fixture 'table'")


def test_motion_hold_errors_name_the_flag(tmp_path):
    cell = _bent_pair(tmp_path)
    base = ["motion", cell, "--arm", "a", "--to", "0.3", "0.6", "0.8", "--amax", "2"]
    _one_error_line(CliRunner().invoke(cli, [*base, "--hold", "b"]), "--hold", "ARM=Q1,Q2,...")
    _one_error_line(CliRunner().invoke(cli, [*base, "--hold", "c=0,0,0"]), "--hold", "no arm 'c'", "a, b")
    _one_error_line(CliRunner().invoke(cli, [*base, "--hold", "b=0,-1.2"]), "--hold b", "3 values", "j1, j2, finger_joint")
    _one_error_line(CliRunner().invoke(cli, [*base, "--hold", "b=0,2.5,0"]), "--hold b", "j2 = 2.5 outside [-2, 2]")
    _one_error_line(CliRunner().invoke(cli, [*base, "--hold", "b=rest"]), "--hold b", "no state 'rest'", "home")
    _one_error_line(CliRunner().invoke(cli, [*base, "--hold", "a=0,0,0"]), "--hold a", "the arm planned", "--from-q")


def test_the_help_example_plans_a_proven_move():
    from test_help_examples import EXAMPLES

    result = CliRunner().invoke(cli, EXAMPLES["motion"])  # once "unreachable": it had no --from
    assert result.exit_code == 0, (result.output, result.stderr)
    assert "smallest clearance" in result.output and "margin holds along the whole motion" in result.output


def test_motion_prints_one_true_minimum_and_whether_the_margin_held():
    """Issue 36 item 11: the report read "at least 10.0 mm (screening bound), proven lower bound 5.0 mm"."""
    result = CliRunner().invoke(cli, ["motion", WALL, "--from", "450", "200", "800", "--to", "450", "-200",
                                      "800", "--margin", "10", "--mm", "--time-limit", "30"])
    assert result.exit_code == 0, (result.output, result.exception)
    line = next(x for x in result.stdout.splitlines() if "smallest clearance" in x)
    assert "screening" not in result.stdout and " ↔ " in line and " at t = " in line
    assert "the 10 mm margin holds along the whole motion (proven on the path by the planner; re-checked by the " \
           "cell: no contact, no two shapes closer than" in line
    smallest = float(line.split("smallest clearance ")[1].split(" mm")[0])
    assert smallest >= 10.0
