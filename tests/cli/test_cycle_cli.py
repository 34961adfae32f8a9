"""`pinarms cycle`: the pick-and-place cycle from the command line (CliRunner)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from pinarms import robots
from pinarms.optim.cycle import PickPlace, plan_cycle
from pinarms.cli import cli

AUBO = ["aubo_i3", "--pick", "350", "200", "150", "--place", "-100", "400", "100", "--mm"]


def invoke(*args: str):
    return CliRunner().invoke(cli, ["cycle", *args])


def test_cycle_text_reports_moves_cycle_time_picks_and_straightness():
    result = invoke(*AUBO)
    assert result.exit_code == 0, (result.output, result.exception)
    api = plan_cycle(robots.load("aubo_i3"), PickPlace([0.35, 0.2, 0.15], [-0.1, 0.4, 0.1]))
    out = result.stdout
    assert f"move to place: {api.move_times[0]:.4f} s" in out
    assert f"move to pick:  {api.move_times[1]:.4f} s" in out
    assert f"cycle time {api.cycle_time:.4f} s, {api.picks_per_minute:.2f} picks per minute" in out
    assert "lift 50 mm" in out and "tcp off the vertical lines [mm]: lift from pick" in out
    assert f"lift from pick {api.line_deviation[0] * 1000:.4g}" in out


def test_cycle_json_in_si_with_limits_and_session(tmp_path):
    out = tmp_path / "cycle.pinarms"
    result = invoke("scara_mushroom", "--pick", "0.3", "0.25", "0.1", "--place", "-0.2", "0.35", "0.08",
                    "--lift", "0.04", "--dwell", "0.5", "--vmax", "1,1,0.2,2", "--amax", "10", "--json",
                    "--session", str(out))
    assert result.exit_code == 0, (result.output, result.exception)
    data = json.loads(result.stdout)
    assert data["limits"]["vmax"] == [1.0, 1.0, 0.2, 2.0] and data["limits"]["amax"] == [10.0] * 4
    assert data["limits"]["jmax"] is None
    assert data["cycle_time_s"] == pytest.approx(sum(data["move_times_s"]) + 2 * 0.5, rel=1e-12)
    assert data["picks_per_minute"] == pytest.approx(60.0 / data["cycle_time_s"], rel=1e-12)
    assert data["waypoints"][1]["position_m"] == pytest.approx([0.3, 0.25, 0.14], abs=1e-12)
    assert max(max(v) for v in data["limit_ratios"].values()) <= 1.0 + 1e-9
    assert data["one_branch"] is True
    from pinarms import viz

    session = viz.load_session(out)
    assert list(session.trajectories) == ["cycle"]
    assert session.trajectories["cycle"].t[-1] == pytest.approx(data["cycle_time_s"], rel=1e-12)
    np.testing.assert_allclose(session.point_sets["pick_place"].points, [[0.3, 0.25, 0.1], [-0.2, 0.35, 0.08]],
                               atol=1e-12)
    assert session.point_sets["cycle_via_points"].points.shape == (7, 3)


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--pick", "1500", "0", "100", "--place", "-100", "400", "100", "--mm"], "the pick point [1.5, 0.0, 0.1] m"),
        (["--pick", "350", "200", "150", "--place", "-100", "400", "100", "--lift", "0"], "lift [m] must be > 0"),
        (["--pick", "350", "200", "150", "--place", "-100", "400", "100", "--mm", "--dwell", "-1"], "dwell"),
        (["--pick", "350", "200", "150", "--place", "-100", "400", "100", "--mm", "--vmax", "0"], "vmax"),
    ],
)
def test_cycle_errors_are_one_line(args, fragment):
    result = invoke("aubo_i3", *args)
    assert result.exit_code == 1, (result.output, result.exception)
    assert "Traceback" not in result.output and "Error:" in result.stderr
    assert fragment in result.stderr, result.stderr
