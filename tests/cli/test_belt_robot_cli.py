"""`pinarms belt run|arms|size --robot URDF`: the user's own arm on the belt from the command line.

The finding (issue 36): the belt commands took only ``--preset``; a user's arm could go on the
belt from Python only. Each bad value is one ``Error:`` line naming the flag that fixes it.
"""

import json

import numpy as np
import pytest
from click.testing import CliRunner

from pinarms.cli import cli
from pinarms.cli.belt_robot import TOOL_LINK, load_belt_robot
from pinarms.robots.registry import builtin_urdf_path

GANTRY = str(builtin_urdf_path("gantry_flower"))
SCARA = str(builtin_urdf_path("scara_mushroom"))
#: seed 002's gantry as a user's arm: its base 0.2 m off the belt's centre line, 5 cm below it, its box beside
GANTRY_LINE = ["--robot", GANTRY, "--arms", "1", "--rate", "20", "--seeds", "1", "--duration", "60", "--speed", "0.3",
               "--map-grid", "4,3", "--base-offset", "-0.2", "--base-height", "-0.05", "--box", "0.6,0.5,0.25",
               "--descend", "0.2"]


def _error(args):
    r = CliRunner().invoke(cli, ["belt", *args])
    assert r.exit_code == 1 and r.output.startswith("Error: ") and r.output.count("\n") == 1, r.output
    assert "Traceback" not in r.output
    return r.output


@pytest.mark.parametrize("args, flag", [
    (["run", "--robot", SCARA, "--tcp", "no_such_link"], "--tcp"),
    (["run", "--robot", SCARA, "--tcp-offset", "0.1,0"], "--tcp-offset"),
    (["run", "--robot", SCARA, "--tcp", "no_such_link", "--tool-axis", "x"], "--tcp"),
    (["run", "--tcp", "link"], "--tcp"),
    (["run", "--tool-axis", "x"], "--tool-axis"),
    (["arms", "--package", "a=b"], "--package"),
    (["run", "--robot", SCARA, "--map-grid", "1,5"], "--map-grid"),
    (["run", "--robot", SCARA, "--box", "0.1,x,0"], "--box"),
    (["run", "--robot", SCARA, "--paper-limit"], "--paper-limit"),
    (["run", "--robot", "no_such_arm.urdf"], "--robot"),
    (["size", "--robot", SCARA, "--descend", "0"], "descend"),
])
def test_bad_robot_flags_are_one_error_line_naming_the_flag(args, flag):
    assert flag in _error(args)


def test_a_box_out_of_reach_names_box():
    assert "--box" in _error(["run", *GANTRY_LINE[:-4], "--box", "5,5,5"])


def test_tool_axis_and_offset_turn_and_move_the_tool_point():
    """--tool-axis x: the tool point's z axis is the link's x axis (tool down = the tcp z axis down);
    --tcp-offset: the tool point sits there in the link's frame."""
    plain = load_belt_robot(SCARA, (), None, None, "z")
    link = plain.tcp_frame
    turned = load_belt_robot(SCARA, (), link, "0.01,0.02,0.03", "x")
    assert turned.tcp_frame == TOOL_LINK
    q = plain.neutral
    T_link, T_tool = plain.fk(q), turned.fk(q)
    np.testing.assert_allclose(T_tool[:3, 2], T_link[:3, 0], atol=1e-12)
    np.testing.assert_allclose(T_tool[:3, 3], T_link[:3, 3] + T_link[:3, :3] @ [0.01, 0.02, 0.03], atol=1e-12)
    down = load_belt_robot(SCARA, (), link, None, "-z")
    np.testing.assert_allclose(down.fk(q)[:3, 2], -T_link[:3, 2], atol=1e-12)


@pytest.mark.slow
def test_belt_run_with_the_users_arm():
    r = CliRunner().invoke(cli, ["belt", "run", *GANTRY_LINE, "--map-error", "4", "--json"])
    assert r.exit_code == 0, (r.output, r.exception)
    data = json.loads(r.stdout)
    f = data["figures"]
    assert f["arms"] == ["arm 1"] and data["belt_speed_m_s"] == 0.3 and 0.0 < f["picks_per_minute"]
    assert data["map_warnings"] == []  # a gantry cannot turn its tool: its time cannot depend on yaw
    e = data["map_error"]  # the map against exact planning at 4 random picks (--map-error)
    assert 1 <= e["points"] <= 4 and not e["yaw_axis"] and e["target_p95"] == 0.01 and e["seconds"] > 0.0
    assert 0.0 <= e["mean"] <= e["max"] and e["p95"] <= e["max"] + 1e-15
    assert sum(row["points"] for row in e["by_yaw"]) == e["points"]
