"""`pinarms cell show|check|cycle` through click's CliRunner: output, --json, one-line errors."""

from __future__ import annotations

import json

from pinarms import viz


def user_error(result, *fragments: str) -> None:
    assert result.exit_code == 1, (result.output, result.exception)
    assert "Traceback" not in result.output
    err = result.stderr
    assert err.startswith("Error:") and err.count("\n") == 1, err
    for fragment in fragments:
        assert fragment in err, err


def test_cell_show_lists_arms_fixtures_and_pairs(run, tmp_path):
    data = json.loads(run("cell", "show", "mushroom_line", "--json").stdout)
    assert [a["name"] for a in data["arms"]] == ["left", "right"]
    assert data["arms"][0]["model"] == "scara_mushroom" and data["arms"][1]["q_slice"] == [4, 8]
    assert "left_box_wall_xpos" in [f["name"] for f in data["fixtures"]]
    assert set(data["pairs_checked"]) == {"self", "arm-arm", "arm-fixture"}
    assert data["pairs_allowed"]["rigid"] > 0
    text = run("cell", "show", "aubo_food_station", "--mm", "--arg", "stand_height=0.8",
               "--session", str(tmp_path / "s.pinarms")).stdout
    assert "aubo: aubo_i3" in text and "base at (0, 0, 800) mm" in text and "hopper: mesh meshes/hopper.stl" in text
    session = viz.load_session(tmp_path / "s.pinarms")
    assert session.cell_tcp_frames("aubo_food_station") == {"aubo": "aubo_tcp"}


def test_cell_check_configurations_and_random_batch(run):
    q_free = "0,0,0,0,0,0"
    q_wall = "-0.99,-0.35,1.67,-0.45,1.57,-0.58"  # gripper 5 mm inside the crate's +x wall
    out = run("cell", "check", "aubo_food_station", "--q", q_free, "--q", q_wall, "--random", "500", "--json")
    data = json.loads(out.stdout)
    first, second = data["configurations"]
    assert not first["colliding"] and first["clearance_m"] > 0
    assert second["colliding"] and ["aubo_wrist3_Link", "crate_wall_xpos"] in second["touching"]
    assert 0 < data["random"]["colliding"] < 500 and data["random"]["seed"] == 0
    text = run("cell", "check", "aubo_food_station", "--q", q_wall).stdout
    assert "TOUCHES aubo_wrist3_Link – crate_wall_xpos" in text


def test_cell_cycle_replans_one_arm_around_the_crate(run, tmp_path):
    out = run("cell", "cycle", "aubo_food_station", "--task", "aubo", "360", "0", "750", "0", "-420", "770", "--mm",
              "--plot-clearance", str(tmp_path / "c.png"), "--json")
    data = json.loads(out.stdout)
    report = data["arms"]["aubo"]["cycle"]["cell"]
    assert report["extra_time_s"] > 0 and report["lift_m"] > 0.05
    assert report["min_clearance_m"] >= 0.02
    assert report["attempts"][0]["clear"] is False and "crate_wall" in report["attempts"][0]["pair"]
    assert (tmp_path / "c.png").stat().st_size > 1000


def test_cell_errors_are_one_line(run):
    user_error(run("cell", "show", "packing_hall", ok=False), "unknown cell 'packing_hall'", "mushroom_line")
    user_error(run("cell", "show", "mushroom_line", "--arg", "belt_top=high", ok=False), "must be a number")
    user_error(run("cell", "show", "mushroom_line", "--arg", "belt_speed=1", ok=False), "unknown xacro argument")
    user_error(run("cell", "check", "mushroom_line", "--q", "0,0,0", ok=False), "needs 8 values")
    user_error(run("cell", "cycle", "mushroom_line", "--task", "middle", "0", "0", "0", "1", "1", "1", ok=False),
               "no arm 'middle'")
    user_error(run("cell", "cycle", "aubo_food_station", "--task", "aubo", "360", "0", "750", "120", "-420", "770",
                   "--mm", ok=False), "place pose of arm 'aubo'", "crate_wall_xpos")


def bent_pair_cell(folder) -> str:
    from tests.robots.cell.bent_pair import bent_pair

    return str(bent_pair(folder, 'tcp = { link = "flange", xyz = [0.05, 0.0, 0.0] }\nfreeze = { finger_joint = 0.02 }\n'
                                 'states = { home = [0.0, -1.2], ready = [0.5, -1.0] }\nhold = "home"'))


def test_cell_show_prints_each_arms_tool_point_frozen_joints_hold_and_states(run, tmp_path):
    path = bent_pair_cell(tmp_path)
    text = run("cell", "show", path).stdout
    assert "    tcp: finger (the last link; no tcp given)" in text
    assert "    hold: (0, 0, 0) rad/m (neutral)" in text
    assert "    tcp: flange + xyz (0.05, 0, 0) m, rpy (0, 0, 0) rad" in text
    assert "    frozen: finger_joint = 0.02" in text
    assert "    hold: (0, -1.2) rad/m (state home)" in text and "    states: home, ready" in text
    data = json.loads(run("cell", "show", path, "--json").stdout)
    a, b = data["arms"]
    assert a["tcp_frame"] == "finger" and a["states"] == {} and a["frozen"] == {} and a["hold"] == [0.0, 0.0, 0.0]
    assert b["tcp_frame"] == "tcp" and b["tcp"] == "flange + xyz (0.05, 0, 0) m, rpy (0, 0, 0) rad"
    assert b["frozen"] == {"finger_joint": 0.02} and b["hold"] == [0.0, -1.2]
    assert b["states"] == {"home": [0.0, -1.2], "ready": [0.5, -1.0]}


def test_cell_cycle_names_the_idle_arm_in_collision_and_takes_its_hold(run, tmp_path):
    from tests.robots.cell.bent_pair import bent_pair

    path = str(bent_pair(tmp_path, "states = { home = [0.0, -1.2, 0.0] }"))  # b at neutral: in the table
    cycle = ("cell", "cycle", path, "--task", "a", "0.3", "0.8", "0.8", "0.3", "0.5", "0.8")
    user_error(run(*cycle, ok=False), "idle arm 'b' is in collision at its hold pose: b_link2 – table")
    user_error(run(*cycle, "--hold", "b=0,2.5,0", ok=False), "--hold b", "j2 = 2.5 outside [-2, 2]")
    user_error(run(*cycle, "--hold", "a=home", ok=False), "--hold a", "it has a --task")
    held = run(*cycle, "--hold", "b=home", ok=False)  # b clear: the cycle itself is planned (this arm cannot reach it)
    user_error(held, "unreachable")
    assert "idle arm" not in held.stderr
