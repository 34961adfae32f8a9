"""SRDF ``home``: written from the user's home, or from the all-zero pose only where it lies inside the limits;
an arm whose zero pose is outside its limits exports without a forced home, and the export says so."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from click.testing import CliRunner

from pinarms import robots
from pinarms.cli import cli
from pinarms.export import export_cell, export_urdf
from pinarms.robots.cell import load_cell
from pinarms.errors import InvalidInput


def _arm(lower: float, upper: float) -> str:
    """A two-joint arm whose second joint has the limits [lower, upper] rad."""
    limit = '<limit lower="{}" upper="{}" effort="1" velocity="1"/>'
    return ('<robot name="offset_arm"><link name="base"/>'
            '<link name="l1"><collision><geometry><box size="0.05 0.05 0.3"/></geometry>'
            '<origin xyz="0 0 0.15"/></collision></link>'
            '<link name="l2"><collision><geometry><box size="0.05 0.05 0.3"/></geometry>'
            '<origin xyz="0 0 0.15"/></collision></link>'
            '<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>'
            f'<origin xyz="0 0 0.1"/>{limit.format(-1, 1)}</joint>'
            '<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><axis xyz="0 1 0"/>'
            f'<origin xyz="0 0 0.3"/>{limit.format(lower, upper)}</joint></robot>')


@pytest.fixture
def offset_arm(tmp_path):
    path = tmp_path / "src" / "offset_arm.urdf"
    path.parent.mkdir()
    path.write_text(_arm(0.82, 5.46))  # zero is outside j2's range, as on the Kinova Jaco2
    return robots.from_urdf(path)


def _states(srdf) -> dict[str, dict[str, float]]:
    root = ET.parse(srdf).getroot()
    return {s.get("name"): {j.get("name"): float(j.get("value")) for j in s.iter("joint")}
            for s in root.iter("group_state")}


def test_an_arm_whose_zero_pose_is_outside_its_limits_exports_without_a_forced_home(tmp_path, offset_arm):
    out = export_urdf(offset_arm, tmp_path / "out", srdf=True)
    assert "home" not in _states(out.srdf)
    assert any("home" in n and "j2" in n and "states=" in n for n in out.notes), out.notes
    assert "no home state" in out.srdf.read_text()
    model = pin.buildModelFromUrdf(str(out.urdf))
    pin.loadReferenceConfigurations(model, str(out.srdf), False)
    assert "home" not in model.referenceConfigurations


def test_the_users_home_is_written(tmp_path, offset_arm):
    home = np.array([0.2, 1.5])
    out = export_urdf(offset_arm, tmp_path / "out", srdf=True, states={"home": home})
    assert _states(out.srdf)["home"] == {"j1": 0.2, "j2": 1.5}
    assert out.notes == ()
    with pytest.raises(InvalidInput, match="outside its limits"):
        export_urdf(offset_arm, tmp_path / "bad", srdf=True, states={"home": np.zeros(2)})


def test_a_zero_pose_inside_the_limits_stays_the_home(tmp_path):
    out = export_urdf("aubo_i3", tmp_path / "out", srdf=True)
    home = _states(out.srdf)["home"]
    assert len(home) == 6 and set(home.values()) == {0.0}
    assert out.notes == ()


def test_a_cell_home_replaces_the_zero_homes(tmp_path):
    cell = load_cell("mushroom_line")
    q_left = np.array([0.3, -0.4, 0.05, 0.2])
    out = export_cell(cell, tmp_path / "c", mjcf=False, states={"left_home": {"left": q_left}})
    states = _states(out.srdf)
    assert list(states["left_home"].values()) == pytest.approx(list(q_left))
    assert set(states["right_home"].values()) == {0.0} and "home" in states


def test_cli_says_when_no_home_is_written(tmp_path, offset_arm):
    run = CliRunner().invoke(cli, ["urdf", "export", str(offset_arm.urdf_path), str(tmp_path / "out"), "--srdf"])
    assert run.exit_code == 0, run.output
    assert "no home state" in run.output and "j2" in run.output


def test_the_states_of_a_cell_description_are_its_srdf_states(tmp_path):
    """Issue 36: the cell description's own ``home`` (and other states) go into the SRDF; no note that the arm has
    no home (the Jaco2's zero pose lies outside its joint 2 range)."""
    from pinarms.export.srdf import home_notes, srdf_text
    from pinarms.optim.motion.arm_macros import example_packages

    cells = Path(__file__).parent / "foreign" / "cells"
    cell = load_cell(cells / "jaco2_table.toml", packages={"example-robot-data": example_packages()["example-robot-data"]})
    path = tmp_path / "jaco.srdf"
    path.write_text(srdf_text(cell))
    states = _states(path)
    arm = cell.arm("arm")
    for name in ("home", "place"):
        assert list(states[name].values()) == pytest.approx(list(arm.states[name]), abs=1e-12)
        assert list(states[name]) == [f"arm_{j}" for j in arm.robot.joint_names]
    assert home_notes(cell) == ()
    given = np.array(arm.states["place"])
    path.write_text(srdf_text(cell, states={"home": {"arm": given}}))  # a state given on export wins
    assert list(_states(path)["home"].values()) == pytest.approx(list(given), abs=1e-12)
