"""A user's own cell from the command line: `verify cell` (MuJoCo re-check), `cell show --html` with the
user's package meshes, errors naming the flag (never Python advice). The cell is built in ``tmp_path``:
a two-joint arm over a table whose mesh lives in a package folder apart from the cell file."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from pinarms.robots.cell import load_cell
from pinarms.export import compare_configurations_in_mujoco
from pinarms.errors import InvalidInput

# the table: a closed box 0.4 x 0.4 x 0.05 m as ASCII STL (two triangles per face)
_QUADS = (((-1, -1, -1), (-1, 1, -1), (1, 1, -1), (1, -1, -1)), ((-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)),
          ((-1, -1, -1), (1, -1, -1), (1, -1, 1), (-1, -1, 1)), ((-1, 1, -1), (-1, 1, 1), (1, 1, 1), (1, 1, -1)),
          ((-1, -1, -1), (-1, -1, 1), (-1, 1, 1), (-1, 1, -1)), ((1, -1, -1), (1, 1, -1), (1, 1, 1), (1, -1, 1)))
HALF = (0.2, 0.2, 0.025)


def _stl() -> str:
    out = ["solid table"]
    for a, b, c, d in _QUADS:
        for tri in ((a, b, c), (a, c, d)):
            out += ["facet normal 0 0 0", "outer loop",
                    *(f"vertex {p[0] * HALF[0]:g} {p[1] * HALF[1]:g} {p[2] * HALF[2]:g}" for p in tri),
                    "endloop", "endfacet"]
    return "\n".join([*out, "endsolid table", ""])


CELL = """<robot name="own"><link name="world"/>
<link name="arm_base_link"/><joint name="arm_mount" type="fixed"><parent link="world"/><child link="arm_base_link"/>
</joint>
<link name="arm_l1"><collision><origin xyz="0 0 0.1"/><geometry><box size="0.05 0.05 0.2"/></geometry></collision>
</link>
<joint name="arm_j1" type="revolute"><parent link="arm_base_link"/><child link="arm_l1"/><origin xyz="0 0 0.3"/>
<axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
<link name="arm_l2"><collision><origin xyz="0.15 0 0"/><geometry><box size="0.3 0.04 0.04"/></geometry></collision>
</link>
<joint name="arm_j2" type="revolute"><parent link="arm_l1"/><child link="arm_l2"/><origin xyz="0 0 0.2"/>
<axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="10" velocity="2"/></joint>
<link name="table"><visual><geometry><mesh filename="package://vendor/meshes/table.stl"/></geometry></visual>
<collision><geometry><mesh filename="package://vendor/meshes/table.stl"/></geometry></collision></link>
<joint name="table_mount" type="fixed"><parent link="world"/><child link="table"/><origin xyz="0.3 0 0.35"/></joint>
</robot>
"""


@pytest.fixture(scope="module")
def own(tmp_path_factory):
    """``(cell file, --package value)``: the cell in its folder, the package in another one (named otherwise)."""
    root = tmp_path_factory.mktemp("own")
    (root / "cell").mkdir()
    (root / "cell" / "own.urdf").write_text(CELL)
    vendor = root / "elsewhere" / "vendor_description"
    (vendor / "meshes").mkdir(parents=True)
    (vendor / "meshes" / "table.stl").write_text(_stl())
    return str(root / "cell" / "own.urdf"), f"vendor={vendor}"


def _one_error_line(result) -> str:
    assert result.exit_code == 1, (result.output, result.exception)
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.output
    return lines[0]


# --------------------------------------------------------------------------- verify cell
def test_verify_cell_compares_random_configurations_in_mujoco(run, own):
    cell, package = own
    result = run("verify", "cell", cell, "--package", package, "--samples", "12", "--json")
    data = json.loads(result.output)["configurations"]
    assert data["samples"] == 12 and data["pairs"] == 2 and data["sampled"] == "configurations"
    assert data["mujoco_only"] == 0 and data["agrees"] is True
    assert data["max_abs_difference"] <= data["tolerance"]
    text = run("verify", "cell", cell, "--package", package, "--samples", "12").output
    assert "12 random configurations (seed 0) in own: 12 configurations x 2 pairs" in text
    assert text.rstrip().endswith("-> agree")


def test_verify_cell_sees_the_contacts_pinarms_sees(own):
    """Configurations with the arm's link in the table mesh: both engines report the same contacts."""
    cell, package = own
    name, folder = package.split("=")
    c = load_cell(cell, packages={name: folder})
    qs = [[0.0, 0.0], [0.0, 0.6], [0.3, 0.6], [0.0, -1.0]]  # level; down into the table (twice); up
    result = compare_configurations_in_mujoco(c, qs, packages={name: folder})
    assert result.samples == 4 and result.contacts_pinarms == 2 and result.contacts_mujoco == 2
    assert result.mujoco_only == 0 and result.min_pinarms < 0 and result.min_mujoco < 0
    with pytest.raises(InvalidInput, match=r"\(N, 2\)"):
        compare_configurations_in_mujoco(c, [[0.0, 0.0, 0.0]])


@pytest.mark.slow
def test_verify_cell_replays_a_planned_move_between_named_states_and_values(run, own):
    cell, package = own
    result = run("verify", "cell", cell, "--package", package, "--samples", "10", "--plan", "neutral", "1.0,-0.3",
                 "--amax", "5", "--json")
    data = json.loads(result.output)
    assert data["plan"]["label"] == "planned move (arm)" and data["plan"]["samples"] == 10
    assert data["plan"]["agrees"] is True and data["plan"]["contacts_pinarms"] == 0
    assert data["plan"]["min_pinarms"] >= 0.01 - 1e-9  # the default --margin held


@pytest.mark.parametrize("args, flag", [
    (("--plan", "neutral", "1.0"), "--plan TO"),
    (("--plan", "park", "neutral"), "--plan FROM"),
    (("--plan", "neutral", "1.0,-0.3", "--arm", "left"), "--arm"),
    (("--amax", "5"), "--plan"),
    (("--samples", "1"), "--samples"),
    (("--plan", "neutral", "1.0,-0.3", "--amax", "-1"), "--amax"),  # a negative acceleration limit: --amax named
])
def test_verify_cell_errors_name_the_flag(run, own, args, flag):
    cell, package = own
    result = run("verify", "cell", cell, "--package", package, "--samples", "4", *args, ok=False)
    assert flag in _one_error_line(result)


# --------------------------------------------------------------------------- cell show --html
def _page_meshes(html: str) -> dict[str, bytes]:
    """``{scene path: mesh file bytes}`` of a MeshCat page (its scene commands are base64 msgpack)."""
    import base64

    import umsgpack

    out = {}
    for blob in re.findall(r"data:application/octet-binary;base64,([A-Za-z0-9+/=]+)", html):
        command = umsgpack.unpackb(base64.b64decode(blob))
        if command.get("type") == "set_object":
            for geometry in command["object"].get("geometries", []):
                if geometry.get("type") == "_meshfile":
                    out[command["path"]] = geometry["data"].data
    return out


def test_cell_show_html_draws_the_mesh_of_a_package_apart_from_the_cell(run, own, tmp_path):
    """The page holds the table mesh from the --package folder (named otherwise than the package)."""
    cell, package = own
    out = tmp_path / "own.html"
    result = run("cell", "show", cell, "--package", package, "--html", str(out))
    assert f"page written: {out}" in result.output
    meshes = _page_meshes(out.read_text())
    assert meshes == {"/meshcat/pinarms/robots/own/visuals/table_0": _stl().encode()}, list(meshes)


# --------------------------------------------------------------------------- errors name the flag
ARM = ('<robot name="vendor_arm"><link name="base"/><link name="l1"><collision><geometry><box size="0.1 0.1 0.1"/>'
       '</geometry></collision></link><joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>'
       '<axis xyz="0 0 1"/><origin xyz="0 0 0.2"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
       '</robot>')


@pytest.mark.parametrize("command", [("verify", "cell"), ("cell", "show"), ("cell", "check")])
def test_a_missing_package_names_the_flag(run, own, command):
    """A package:// mesh of a cell loaded without its --package: the line names the flag to add."""
    cell, _ = own
    extra = ("--random", "3") if command[1] == "check" else ("--samples", "4") if command[0] == "verify" else ()
    line = _one_error_line(run(*command, cell, *extra, ok=False))
    assert "(on the command line --package vendor=FOLDER)" in line, line


def test_a_toml_arm_in_a_package_names_the_flag(run, tmp_path):
    (tmp_path / "cell.toml").write_text('name = "t"\n[[arm]]\nname = "a"\nurdf = "package://vendor/arm.urdf"\n')
    line = _one_error_line(run("cell", "show", str(tmp_path / "cell.toml"), ok=False))
    assert "(on the command line --package vendor=FOLDER)" in line, line


def test_a_xacro_find_names_the_flag(run, tmp_path):
    (tmp_path / "cell.urdf.xacro").write_text(
        '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:include filename="$(find vendor)/arm.xacro"/><link name="world"/></robot>')
    line = _one_error_line(run("cell", "show", str(tmp_path / "cell.urdf.xacro"), ok=False))
    assert "(on the command line --package vendor=FOLDER)" in line, line


def test_an_export_into_a_full_folder_names_overwrite(run, tmp_path):
    (tmp_path / "arm.urdf").write_text(ARM)
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "keep.txt").write_text("mine")
    line = _one_error_line(run("urdf", "export", str(tmp_path / "arm.urdf"), str(tmp_path / "out"), ok=False))
    assert "(on the command line --overwrite)" in line, line


def test_an_srdf_home_is_given_with_state_the_note_names_it(run, tmp_path):
    """An arm whose limits exclude 0 has no home of zeros: the note names --state, which gives one."""
    (tmp_path / "arm.urdf").write_text(ARM.replace('lower="-1"', 'lower="0.5"'))
    result = run("urdf", "export", str(tmp_path / "arm.urdf"), str(tmp_path / "a"), "--srdf")
    assert "on the command line --state home=V1,V2,..." in result.output, result.output
    run("urdf", "export", str(tmp_path / "arm.urdf"), str(tmp_path / "b"), "--srdf", "--state", "home=0.7",
        "--state", "park=0.9")
    srdf = (tmp_path / "b" / "vendor_arm.srdf").read_text()
    assert re.search(r'<group_state name="home" group="[^"]+">\s*<joint name="j1" value="0.7"', srdf), srdf
    assert re.search(r'<group_state name="park" group="[^"]+">\s*<joint name="j1" value="0.9"', srdf), srdf
    line = _one_error_line(run("urdf", "export", str(tmp_path / "arm.urdf"), str(tmp_path / "c"), "--srdf",
                               "--state", "home=0.1", ok=False))
    assert "home" in line and "0.1" in line, line
    line = _one_error_line(run("urdf", "export", str(tmp_path / "arm.urdf"), str(tmp_path / "c"), "--srdf",
                               "--state", "home", ok=False))
    assert "--state" in line, line


def test_a_cell_state_names_its_arm(run, own, tmp_path):
    cell, package = own
    run("urdf", "export", cell, str(tmp_path / "o"), "--cell", "--srdf", "--package", package,
        "--state", "reach=arm:0.2,0.3")
    srdf = (tmp_path / "o" / "own.srdf").read_text()
    assert re.search(r'<group_state name="reach" group="arm">\s*<joint name="arm_j1" value="0.2"', srdf), srdf
    line = _one_error_line(run("urdf", "export", cell, str(tmp_path / "p"), "--cell", "--srdf", "--package", package,
                               "--state", "reach=left:0.2,0.3", ok=False))
    assert "--state reach" in line and "left" in line, line


def test_motion_loads_a_cell_with_its_packages(run, own):
    """`pinarms motion` takes --package as `cell` and `verify cell` do: the cell loads, the goal is judged."""
    cell, package = own
    line = _one_error_line(run("motion", cell, "--to", "3", "0", "0.5", ok=False))  # no --package: named
    assert "(on the command line --package vendor=FOLDER)" in line, line
    line = _one_error_line(run("motion", cell, "--package", package, "--to", "3", "0", "0.5", "--amax", "5",
                               ok=False))
    assert "vendor" not in line and "3" in line, line  # out of reach (3 m): the cell loaded, the goal refused
