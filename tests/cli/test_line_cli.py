"""`pinarms line`: straight tcp lines from the command line (CliRunner)."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

from pinarms import optim, planning, robots, viz
from pinarms.cli import cli
from pinarms.robots.reach.layout import default_orientation


def invoke(*args: str):
    return CliRunner().invoke(cli, ["line", *args])


def test_line_text_matches_the_api():
    result = invoke("aubo_i3", "--from", "350", "200", "0", "--to", "350", "200", "300", "--mm", "--amax", "7",
                    "--vtool", "500")
    assert result.exit_code == 0, (result.output, result.exception)
    arm = robots.load("aubo_i3")
    R = default_orientation(arm)
    poses = np.stack([np.eye(4), np.eye(4)])
    poses[:, :3, :3] = R
    poses[0, :3, 3], poses[1, :3, 3] = [0.35, 0.2, 0.0], [0.35, 0.2, 0.3]
    path = planning.cartesian_path(arm, poses)
    timing = optim.time_optimal(path, [planning.JointVelocityConstraint(arm.velocity_limit),
                                       planning.JointAccelerationConstraint(7.0), planning.ToolSpeedConstraint(0.5)])
    out = result.stdout
    assert "300 mm of weighted arc length" in out
    assert f"time-optimal (TOPP-RA): {timing.duration:.6g} s" in out
    assert "tool speed 100.0 %" in out and "tolerance 0.1 mm" in out


def test_line_json_with_orientation_vias_blend_and_session(tmp_path):
    out = tmp_path / "line.pinarms"
    result = invoke("ur5", "--from", "0.4", "0.2", "0.1", "--via", "0.4", "0.2", "0.3", "--to", "0.2", "0.45", "0.3",
                    "3.14159", "0", "-1.0", "--blend", "0.05", "--amax", "5", "--json", "--session", str(out))
    assert result.exit_code == 0, (result.output, result.exception)
    data = json.loads(result.stdout)
    assert data["blend_radii_m"] == [0.05] and data["stops_m"] == []
    assert data["max_deviation_m"] < 1e-4
    assert data["time_law"] == "time-optimal (TOPP-RA)"
    assert data["peak_ratios"]["joint acceleration"] <= 1.0 + 1e-9
    session = viz.load_session(out)
    traj = session.trajectories["line"].rebuild()
    assert abs(traj.duration - data["duration_s"]) < 1e-9
    T_end = robots.load("ur5").fk(traj(traj.duration))
    assert np.abs(T_end[:3, 3] - [0.2, 0.45, 0.3]).max() < 1e-9
    assert abs(np.arctan2(T_end[1, 0], T_end[0, 0]) + 1.0) < 1e-9  # the orientation given last: yaw -1 rad


def test_line_without_amax_uses_the_quintic_law_and_errors_are_one_line():
    result = invoke("scara_mushroom", "--from", "0.3", "0.25", "0.06", "--to", "0.3", "0.25", "0.16", "--json")
    assert result.exit_code == 0, (result.output, result.exception)
    assert json.loads(result.stdout)["time_law"] == "quintic time law"
    bad = invoke("aubo_i3", "--from", "0.35", "0.2", "0.0", "--to", "0.35", "0.2", "0.9")
    assert bad.exit_code == 1
    assert "leaves the workspace" in bad.output and "s = 0.40" in bad.output
    assert "Traceback" not in bad.output
    short = invoke("aubo_i3", "--from", "0.35", "0.2", "--to", "0.35", "0.2", "0.3")
    assert short.exit_code == 1 and "3 or 6 numbers" in short.output
    jerk = invoke("aubo_i3", "--from", "0.35", "0.2", "0.0", "--to", "0.35", "0.2", "0.1", "--jmax", "50")
    assert jerk.exit_code == 1 and "--amax" in jerk.output
