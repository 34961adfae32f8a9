"""`pinarms reach`: reachability maps from the command line (CliRunner)."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

from pinarms import robots, viz
from pinarms.cli import cli
from pinarms.robots.reach.reach_io import load_reachability
from pinarms.robots.reach.reachability import ReachabilityRequest, reachability_map


def invoke(*args: str):
    return CliRunner().invoke(cli, ["reach", *args])


def test_tool_down_map_text_file_and_session(tmp_path):
    h5, sess = tmp_path / "aubo.h5", tmp_path / "aubo.pinarms"
    result = invoke("aubo_i3", "--resolution", "150mm", "--tool-down", "15deg", "--orientations", "4",
                    "--roll-steps", "4", "--out", str(h5), "--session", str(sess))
    assert result.exit_code == 0, (result.output, result.exception)
    api = reachability_map(ReachabilityRequest(robots.load("aubo_i3"), 0.15, 4, tool_down=np.radians(15), roll_steps=4))
    assert f"computed {api.n_voxels} voxels, {api.n_poses} poses; reached {api.n_reached} poses" in result.stdout
    assert "4 tool-axis directions" in result.stdout and "15° cone" in result.stdout
    m = load_reachability(h5)
    assert np.array_equal(m.index, api.index) and np.array_equal(m.reached, api.reached)
    assert len(m.solutions) == m.n_reached
    assert "tool down" in viz.load_session(sess).reachability


def test_json_is_one_document_in_si():
    result = invoke("aubo_i3", "--resolution", "0.2", "--orientations", "6", "--json")
    assert result.exit_code == 0, (result.output, result.exception)
    data = json.loads(result.stdout)
    assert data["resolution_m"] == 0.2 and data["poses_per_voxel"] == 6 and data["solver"] == "analytic"
    assert data["poses"] == data["voxels_computed"] * 6
    assert 0 < data["voxels_reachable"] <= data["voxels_computed"]


def test_a_four_axis_arm_with_an_so3_set_says_to_use_tool_down():
    result = invoke("scara_mushroom", "--resolution", "0.2", "--orientations", "5")
    assert result.exit_code == 0, (result.output, result.exception)
    assert "use --tool-down" in result.stdout


def test_bad_units_are_one_line_errors():
    result = invoke("aubo_i3", "--tool-down", "15furlong")
    assert result.exit_code == 1 and "--tool-down must be a number with an optional unit" in result.output
    result = invoke("aubo_i3", "--resolution", "-1mm")
    assert result.exit_code == 1 and "resolution" in result.output
