"""Five arms pinarms does not ship (example-robot-data: Kinova Jaco2 j2s6s200, Unitree Z1, UFactory xArm7, SO-100,
SO-101), each taken from the command line alone through the user's path (issue 36): a cell description
(tests/foreign/cells/*.toml: the arm by package URL, its tcp, frozen gripper, named states, hold pose, a table and
a crate) -> ``cell show`` -> ``cell check`` -> ``urdf export --srdf --mjcf --package`` -> ``verify cell --plan``
(a planned move between the description's states, re-checked in MuJoCo) -> ``cell show --html`` (the page with
the package's meshes). The CLI runs in-process (click's runner); one export per arm is shared by its tests.

Which arms run which steps (the whole suite has 10 minutes on two cores):

- by default, **every arm** through the steps that broke for a user's arm (``cell show``, ``cell check``,
  ``urdf export --srdf --mjcf``: the SRDF's home, Collada meshes for MuJoCo, continuous joints), a few seconds of
  CPU per arm with the pair-sampling and mesh-cover caches cold; and **the SO-101** (the quickest path) through
  the planned move's MuJoCo re-check and the page;
- with ``PINARMS_FOREIGN_ARMS=all``, all five through every step.

The belt step (``pinarms belt run --robot URDF --tcp LINK ... --map-error N``: the arm's task maps, their error
against exact planning at random yaw, a line run and its page) is measured per arm by benchmarks/own_arm.py, not
here: a 6-axis arm's maps take minutes (docs/own-arm.md, "The belt"), and the SO-100/SO-101 cannot hold their
tool exactly vertical at a chosen yaw (five joints, calibrated pitch axes not exactly parallel).

The MuJoCo re-check computes coal's exact distance only where a figure depends on it (pinarms/export/
pair_distances.py, tests/foreign/test_pair_distances.py); the planned move itself (the planner's set-up: sphere
cover, pair tables, the final check) is most of what is left of ``verify --plan``."""

from __future__ import annotations

import json
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from click.testing import CliRunner

from pinarms.cli import cli
from pinarms.optim.motion.arm_macros import example_packages

CELLS = Path(__file__).parent / "cells"
#: cell description -> (tcp line printed by ``cell show``, planned joints)
ARMS = {
    "jaco2_table": ("tcp: j2s6s200_end_effector", 6),
    "z1_table": ("tcp: gripperStator + xyz (0.12, 0, 0) m", 6),
    "xarm7_table": ("tcp: link_eef", 7),
    "so100_table": ("tcp: gripper", 5),
    "so101_table": ("tcp: gripper_frame_link", 5),
}
ALL = os.environ.get("PINARMS_FOREIGN_ARMS") == "all"
#: every arm through the cheap steps (show, check, export); the planned move's re-check and the page for the arm
#: whose path is quickest, all five with PINARMS_FOREIGN_ARMS=all (module doc)
RUN, FULL = sorted(ARMS), (sorted(ARMS) if ALL else ["so101_table"])
pytestmark = pytest.mark.slow


def _run(*args: str) -> str:
    result = CliRunner().invoke(cli, list(args))
    assert result.exit_code == 0, (args, result.output, result.exception)
    return result.stdout


@pytest.fixture(scope="module")
def package() -> str:
    return f"example-robot-data={example_packages()['example-robot-data']}"


@pytest.fixture(scope="module", params=RUN)
def exported(request, package, tmp_path_factory):
    """``(name, cell file, export folder)``: the arm's cell exported once as URDF, SRDF and MJCF."""
    name = request.param
    out = tmp_path_factory.mktemp(name) / "export"
    _run("urdf", "export", str(CELLS / f"{name}.toml"), str(out), "--cell", "--srdf", "--mjcf", "--package", package)
    return name, CELLS / f"{name}.toml", out


def test_cell_show_prints_the_chosen_tcp_the_frozen_gripper_and_the_hold(exported, package):
    name, cell, _ = exported
    text = _run("cell", "show", str(cell), "--package", package)
    tcp, joints = ARMS[name]
    assert tcp in text
    assert f"arm: arm, joints 0-{joints - 1} " in text
    assert "(state home)" in text and "states: home, place" in text


def test_cell_check_finds_the_hold_and_the_place_clear(exported, package):
    name, cell, _ = exported
    from pinarms.robots.cell import load_cell

    arm = load_cell(cell, packages=dict([package.split("=", 1)])).arm("arm")
    qs = [",".join(repr(float(v)) for v in arm.states[s]) for s in ("home", "place")]
    data = json.loads(_run("cell", "check", str(cell), "--package", package, "--q", qs[0], "--q", qs[1], "--json"))
    rows = data["configurations"]
    assert len(rows) == 2 and not any(r["colliding"] for r in rows) and min(r["clearance_m"] for r in rows) > 0.01


def test_the_export_holds_urdf_srdf_mjcf_and_the_descriptions_states(exported):
    name, _, out = exported
    for suffix in (".urdf", ".srdf", ".xml"):
        assert (out / f"{name}{suffix}").is_file()
    srdf = ET.parse(out / f"{name}.srdf").getroot()
    states = {s.get("name"): len(list(s.iter("joint"))) for s in srdf.iter("group_state")}
    assert states == {"home": ARMS[name][1], "place": ARMS[name][1]}, states
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(out / f"{name}.xml"))
    assert model.njnt == ARMS[name][1]


@pytest.mark.parametrize("name", FULL)
def test_verify_replays_a_planned_move_between_the_states_in_mujoco(name, package):
    cell = CELLS / f"{name}.toml"
    data = json.loads(_run("verify", "cell", str(cell), "--package", package, "--samples", "6", "--plan", "home",
                           "place", "--time-limit", "5", "--json"))
    assert data["configurations"]["samples"] == 6
    plan = data["plan"]
    assert plan["agrees"] is True and plan["contacts_pinarms"] == 0, plan
    assert plan["min_pinarms"] >= 0.01 - 1e-9  # the default --margin held along the move


@pytest.mark.parametrize("name", FULL)
def test_the_page_draws_the_arms_package_meshes(name, package, tmp_path):
    cell = CELLS / f"{name}.toml"
    page = tmp_path / f"{name}.html"
    assert f"page written: {page}" in _run("cell", "show", str(cell), "--package", package, "--html", str(page))
    import base64
    import re

    import umsgpack

    drawn = []  # scene paths of the mesh files on the page (MeshCat commands: base64 msgpack)
    for blob in re.findall(r"data:application/octet-binary;base64,([A-Za-z0-9+/=]+)", page.read_text()):
        command = umsgpack.unpackb(base64.b64decode(blob))
        if command.get("type") == "set_object" and any(
                g.get("type") == "_meshfile" for g in command["object"].get("geometries", [])):
            drawn.append(command["path"])
    assert sum("/arm_" in path for path in drawn) >= 3, drawn  # the arm's links, from example-robot-data's meshes


def test_cell_check_counts_each_pair_of_links_once_per_configuration(package):
    """The SO-101's links carry several collision meshes each: a pair of links in contact through two of them was
    counted twice ("4 of the first 2 colliding")."""
    data = json.loads(_run("cell", "check", str(CELLS / "so101_table.toml"), "--package", package, "--random", "4",
                           "--json"))["random"]
    shown = min(data["colliding"], 500)
    assert shown >= 1 and data["most_frequent"]
    assert all(1 <= row["count"] <= shown for row in data["most_frequent"]), data
