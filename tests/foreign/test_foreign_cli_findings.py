"""Small command-line findings of the foreign-arm path (issue 36): each error names what is wrong and the flag."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from pinarms.cli import cli

CELLS = Path(__file__).parent / "cells"


def _fails(*args: str) -> str:
    result = CliRunner().invoke(cli, list(args))
    assert result.exit_code != 0, result.output
    return result.output


@pytest.mark.parametrize("flag, value", [("--population", "2"), ("--population", "0"), ("--generations", "0")])
def test_belt_size_names_the_flag_not_the_ga_settings(flag, value):
    """``belt size --population 2`` said ``GASettings.population=2`` after building the maps."""
    out = _fails("belt", "size", flag, value)
    assert f"Error: {flag} = {value} is outside" in out and "GASettings" not in out, out


def test_map_error_needs_a_robot_arm():
    out = _fails("belt", "run", "--map-error", "5", "--seeds", "1", "--duration", "10")
    assert "Error: --map-error measures the task map of --robot URDF" in out, out
    assert "Error: --map-error = -1 is outside" in _fails("belt", "run", "--map-error", "-1")


@pytest.mark.slow
def test_a_five_axis_arm_told_the_position_is_reachable_but_not_the_start_orientation(monkeypatch):
    """``pinarms motion --to X Y Z`` on the SO-101 said "unreachable" where the position is within reach and
    only the tool's start orientation (kept without ROLL PITCH YAW) is not: the error says so and names the
    flag's angles. The planner is replaced by its answer for that goal (goal unreachable: minutes of set-up)."""
    from pinarms.optim import motion
    from pinarms.optim.motion.result import MotionStatus
    from pinarms.errors import UnreachableTarget
    from pinarms.optim.motion.arm_macros import example_packages

    class Unreachable:
        status = MotionStatus.GOAL_UNREACHABLE

        def raise_for_status(self):
            raise UnreachableTarget("the goal pose is unreachable")

    asked = []
    monkeypatch.setattr(motion, "plan_motion", lambda request, progress=None: asked.append(request) or Unreachable())
    package = f"example-robot-data={example_packages()['example-robot-data']}"
    cell = str(CELLS / "so101_table.toml")
    out = _fails("motion", cell, "--package", package, "--to", "0.1192", "0.2066", "0.8729")
    assert asked and "reaches that position, but not with the tool's orientation at the start" in out, out
    assert "--to X Y Z ROLL PITCH YAW" in out and "5 joints" in out
    assert np.allclose(asked[0].goal[:3, 3], [0.1192, 0.2066, 0.8729])
