"""`pinarms cycle`: the pick-and-place cycle from the command line (CliRunner)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from pinarms import robots
from pinarms.optim.cycle import CycleRequest, PickPlace, plan_cycle
from pinarms.cli import cli

AUBO = ["aubo_i3", "--pick", "350", "200", "150", "--place", "-100", "400", "100", "--mm"]


def invoke(*args: str):
    return CliRunner().invoke(cli, ["cycle", *args])


def test_cycle_text_reports_moves_cycle_time_picks_and_straightness():
    result = invoke(*AUBO)
    assert result.exit_code == 0, (result.output, result.exception)
    api = plan_cycle(CycleRequest(robots.load("aubo_i3"), PickPlace([0.35, 0.2, 0.15], [-0.1, 0.4, 0.1])))
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


def test_cycle_with_a_payload_times_torques_too():
    base = ["cycle", "aubo_i3", "--pick", "450", "-100", "20", "--place", "-100", "450", "20", "--mm",
            "--lift", "80", "--dwell", "0.3", "--json"]
    free = CliRunner().invoke(cli, base)
    loaded = CliRunner().invoke(cli, base + ["--payload", "3kg"])
    assert free.exit_code == 0 and loaded.exit_code == 0, (free.output, loaded.output)
    a, b = json.loads(free.stdout), json.loads(loaded.stdout)
    assert a["payload"] is None and b["payload"]["mass_kg"] == 3.0
    assert max(b["torque_ratios"]) <= 1.0 + 1e-9 and max(b["torque_ratios"]) > 0.999  # the shoulder binds
    assert b["cycle_time_s"] > a["cycle_time_s"] * 1.01  # 5.647 s against 5.536 s
    assert b["move_times_s"][0] > b["move_times_s"][1]  # loaded there, empty back
    text = CliRunner().invoke(cli, base[:-1] + ["--payload", "1500g"]).stdout
    assert "torque / limit (carrying 1.5 kg to the place, empty back): shoulder_joint" in text


def test_payload_options_are_checked():
    bad = CliRunner().invoke(cli, ["cycle", "aubo_i3", "--pick", "0.45", "-0.1", "0.02", "--place", "-0.1", "0.45",
                                   "0.02", "--payload", "3lb"])
    assert bad.exit_code != 0 and "a mass must be a number of kg" in bad.output
    no_robot = CliRunner().invoke(cli, ["optimize", "--kind", "multi-quintic", "--via", "0,0", "--via", "1,1",
                                        "--vmax", "1", "--payload", "3kg"])
    assert no_robot.exit_code == 2 and "need --robot" in no_robot.output


def test_mass_units_at_the_edge():
    from pinarms.errors import InvalidInput
    from pinarms.units import mass_kg

    assert mass_kg("3kg") == 3.0 and mass_kg(" 1.5 KG ") == 1.5 and mass_kg("800g") == pytest.approx(0.8)
    assert mass_kg("2") == 2.0
    for text in ("-1kg", "nan", "3 lb", ""):
        with pytest.raises(InvalidInput):
            mass_kg(text)


def test_cycle_straight_reports_the_joint_space_cycle_beside_it():
    result = invoke("scara_mushroom", "--pick", "0.3", "0.25", "0.1", "--place", "-0.2", "0.35", "0.08",
                    "--amax", "10", "--straight", "--vtool", "0.3", "--json")
    assert result.exit_code == 0, (result.output, result.exception)
    data = json.loads(result.stdout)
    assert data["approach"] == "straight"
    assert data["joint_cycle_time_s"] > 0.0 and data["line_cost_s"] == pytest.approx(0.0, abs=1e-6)
    assert max(data["line_deviation_m"].values()) < 1e-6  # the SCARA's z axis: straight anyway
    bad = invoke("scara_mushroom", "--pick", "0.3", "0.25", "0.1", "--place", "-0.2", "0.35", "0.08", "--straight")
    assert bad.exit_code == 1 and "amax" in bad.output
