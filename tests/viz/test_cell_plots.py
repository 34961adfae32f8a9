"""Plots of cells: clearance over time and a multi-arm schedule."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.optim.line import LineSchedule
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.errors import InvalidInput
from pinarms.viz.plots import plot_clearance, plot_schedule


def test_clearance_plot_marks_contacts(tmp_path):
    cell = load_cell("mushroom_line")
    arm = cell.arm("left")
    q0 = arm.robot.ik(arm.to_base(np.array([-0.05, -0.03, 0.84])), position_only=True)
    q1 = arm.robot.ik(arm.to_base(np.array([0.22, 0.68, 0.84])), position_only=True)
    check = cell.check_motion([ArmMotion("left", planning.multi_quintic([0.0, 1.0], np.array([q0, q1])))],
                              margin=0.01, clearance=0.02, curve=True)
    assert check.in_contact.any()
    out = plot_clearance(tmp_path / "clearance.svg", check)
    text = out.read_text()
    assert "#d62728" in text  # contact samples in red
    assert "left_box_wall" in text  # the closest pair is named
    with pytest.raises(InvalidInput, match="png or .svg"):
        plot_clearance(tmp_path / "clearance.pdf", check)


def test_clearance_plot_draws_the_moving_arm_against_everything_else(tmp_path):
    """Issue 36 item 11: the idle arm's own links (a flat line) hid the moving arm's distance."""
    cell = load_cell("mushroom_line")
    arm = cell.arm("left")
    q0 = arm.robot.ik(arm.to_base(np.array([-0.05, -0.03, 0.90])), position_only=True)
    q1 = arm.robot.ik(arm.to_base(np.array([0.22, 0.68, 0.90])), position_only=True)
    check = cell.check_motion([ArmMotion("left", planning.multi_quintic([0.0, 1.0], np.array([q0, q1])))],
                              margin=0.01, curve=True)
    text = plot_clearance(tmp_path / "clearance.svg", check).read_text()
    for group in check.curves:
        assert group.replace("↔", "") in text.replace("↔", "")  # each group is a curve of the legend
    assert "left ↔ fixtures" in check.curves and "left ↔ right" in check.curves
    assert not any(name.startswith("right") for name in check.curves) and "right: own links" not in text
    lowest = min(check.curves, key=lambda n: check.curves[n].min())
    assert f"{check.curves[lowest].min() * 1e3:.1f} mm: {check.curve_pairs[lowest].body_a}" in text


def test_schedule_plot_draws_every_arm(tmp_path):
    schedule = LineSchedule(
        cell="demo", arms=("a", "b"), cycle_times={"a": 2.0, "b": 1.5}, period=2.0, offsets={"a": 0.0, "b": 1.0},
        picks_per_minute=60.0, single_arm_picks_per_minute={"a": 30.0, "b": 40.0}, scanned=np.zeros(2),
        clear=np.ones(2, bool), min_clearance=np.zeros(2), check=None, busy={"a": [(0.0, 0.5)], "b": [(1.2, 1.6)]},
    )
    out = plot_schedule(tmp_path / "schedule.svg", schedule, periods=3)
    text = out.read_text()
    assert "a (2.00 s)" in text and "b (1.50 s)" in text and "60.0 picks/min" in text
    with pytest.raises(InvalidInput, match="periods"):
        plot_schedule(tmp_path / "s.png", schedule, periods=0)


def test_clearance_plot_of_a_planned_motion_draws_the_arm_to_the_rest_and_its_own_links(tmp_path):
    from pinarms.optim.motion import ClearanceProfile

    cell = load_cell("mushroom_line")
    pairs = tuple(p for p in cell.pairs_for(float("inf")) if "left" in (p.owner_a, p.owner_b))
    env_k = next(k for k, p in enumerate(pairs) if p.kind == "arm-fixture")
    t = np.linspace(0.0, 1.0, 11)
    profile = ClearanceProfile(t, 0.05 + 0.01 * t, np.full(11, env_k), np.full(11, 0.08), pairs, 0.01)
    assert list(profile.curves) == ["left ↔ fixtures, other arms", "left: own links"]
    text = plot_clearance(tmp_path / "plan.svg", profile).read_text()
    assert "left ↔ fixtures, other arms" in text and "left: own links" in text
    assert f"50.0 mm: {pairs[env_k].body_a} ↔ {pairs[env_k].body_b}" in text
