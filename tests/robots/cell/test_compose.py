"""Any URDF arm in a cell under a prefix: cell description files (TOML) and compose_cell."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pinarms import robots
from pinarms.robots import ArmPlacement, FixturePrimitive, compose_cell, load_cell
from pinarms.robots.cell.compose import compose_cell_urdf, read_cell_description
from pinarms.robots.cell.compose_file import MAX_DESCRIPTION_BYTES
from pinarms.errors import CellError, CellNotFound, XacroForbidden
from pinarms.robots.registry import builtin_urdf_path

DATA = Path(__file__).parent.parent / "data"

TWO_SCARAS = """\
name = "two_scaras"

[[arm]]
name = "left"
urdf = "user_scara.urdf"
xyz = [0.0, 0.55, 0.0]
rpy = [0.0, 0.0, -1.5707963267948966]

[[arm]]
name = "right"
urdf = "arms/user_scara.urdf"
xyz = [0.0, -0.55, 0.0]
rpy = [0.0, 0.0, 1.5707963267948966]

[[fixture]]
name = "belt"
box = [2.0, 0.30, 0.05]
xyz = [0.0, 0.0, 0.30]

[[fixture]]
name = "post"
cylinder = [0.03, 0.6]
xyz = [0.5, 0.0, 0.3]
"""


def _pose(xyz, rpy) -> np.ndarray:
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz, dtype=float)).homogeneous


def _same_motion(cell, arm_name: str, alone, base_to_world: np.ndarray, n: int = 30) -> None:
    """The arm's tcp in the cell = the arm alone moved by its base pose, at random configurations."""
    arm = cell.arm(arm_name)
    q_arm = alone.random_q(n, seed=11)
    q = np.tile(cell.neutral, (n, 1))
    q[:, arm.q_slice] = q_arm
    np.testing.assert_allclose(cell.world_pose(q, arm.prefix + "tcp"), base_to_world @ alone.fk(q_arm), atol=1e-12)
    np.testing.assert_allclose(arm.base_to_world, base_to_world, atol=1e-15)


@pytest.fixture()
def folder(tmp_path):
    (tmp_path / "arms").mkdir()
    shutil.copy(DATA / "user_scara.urdf", tmp_path / "user_scara.urdf")
    shutil.copy(DATA / "user_scara.urdf", tmp_path / "arms" / "user_scara.urdf")
    (tmp_path / "two.toml").write_text(TWO_SCARAS, encoding="utf-8")
    return tmp_path


def test_two_copies_of_a_users_scara_from_a_description_file(folder):
    cell = load_cell(folder / "two.toml")
    alone = robots.from_urdf(DATA / "user_scara.urdf")
    assert cell.name == "two_scaras" and [a.name for a in cell.arms] == ["left", "right"]
    assert cell.joint_names == tuple(f"{s}_j{k}" for s in ("left", "right") for k in range(1, 5))
    assert [f.name for f in cell.fixtures] == ["belt", "post"]
    others = {"universe", "root_joint", "world", "belt", "belt_joint", "post", "post_joint"}
    assert all(f.startswith(("left_", "right_")) for f in cell.robot.frame_names if f not in others)
    assert sum(f.startswith("left_") for f in cell.robot.frame_names) == len(alone.frame_names) - 1 + 1  # + mount joint
    for arm, y, yaw in zip(cell.arms, (0.55, -0.55), (-np.pi / 2, np.pi / 2)):
        assert arm.prefix == arm.name + "_" and arm.robot.name == arm.name  # the user's names, not a built-in's
        assert arm.model is None and arm.ik_family == "scara" and arm.robot.has_analytic_ik
        assert arm.robot.joint_names == ("j1", "j2", "j3", "j4")
        _same_motion(cell, arm.name, alone, _pose((0.0, y, 0.0), (0.0, 0.0, yaw)))
        q = arm.robot.random_q(5, seed=2)
        for k, sols in enumerate(arm.robot.ik_all(arm.robot.fk(q), q_ref=q)):
            assert np.abs(sols[0] - q[k]).max() < 1e-6


def test_compose_cell_in_python_with_a_scara_and_a_six_axis_arm():
    arms = [ArmPlacement("packer", "user_scara.urdf", (0.8, 0.0, 0.0), (0.0, 0.0, np.pi)),
            ArmPlacement("loader", "user_6r.urdf", (-0.4, 0.2, 0.1), (0.1, -0.2, 0.3))]
    cell = compose_cell(arms, [FixturePrimitive("table", "box", (0.6, 0.6, 0.02), (0.2, 0.0, 0.1))],
                        name="mixed", base_dir=DATA)
    assert cell.arm("packer").ik_family == "scara" and cell.arm("loader").ik_family == "ur_type"
    assert cell.arm("loader").robot.joint_names == tuple(f"a{k}" for k in range(1, 7))
    for arm in arms:
        alone = robots.from_urdf(DATA / arm.urdf)
        _same_motion(cell, arm.name, alone, _pose(arm.xyz, arm.rpy))
    assert cell.fixture("table").shapes[0].kind == "box"
    assert not cell.in_collision(cell.neutral)


def test_a_built_in_arm_composed_by_file_is_told_by_its_kinematics():
    path = builtin_urdf_path("scara_mushroom")
    cell = compose_cell([ArmPlacement("a", path.name)], base_dir=path.parent)
    assert cell.arm("a").model == "scara_mushroom" and cell.arm("a").ik_family == "scara"


def test_base_link_of_another_name_is_renamed_and_meshes_resolve_from_the_cell(tmp_path):
    text = (DATA / "user_scara.urdf").read_text(encoding="utf-8").replace('"base_link"', '"pedestal"')
    stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.05 0 0\nvertex 0 0.05 0\nendloop\nendfacet\nendsolid t\n"
    (tmp_path / "vendor" / "meshes").mkdir(parents=True)
    (tmp_path / "vendor" / "meshes" / "cap.stl").write_text(stl, encoding="utf-8")
    text = text.replace('<link name="tcp"/>', '<link name="tcp"><collision><geometry><mesh filename="meshes/cap.stl"/>'
                                              '</geometry></collision></link>')
    (tmp_path / "vendor" / "arm.urdf").write_text(text, encoding="utf-8")
    (tmp_path / "c.toml").write_text('[[arm]]\nname = "solo"\nurdf = "vendor/arm.urdf"\n', encoding="utf-8")
    cell = load_cell(tmp_path / "c.toml")
    assert cell.name == "c" and cell.arms[0].name == "solo" and cell.arms[0].robot.ik_family == "scara"
    assert "vendor/meshes/cap.stl" in cell.urdf_text and "solo_base_link" in cell.robot.frame_names


def test_package_arm_files(tmp_path):
    pkg = tmp_path / "vendor_pkg"
    pkg.mkdir()
    shutil.copy(DATA / "user_6r.urdf", pkg / "six.urdf")
    (tmp_path / "cell").mkdir()
    (tmp_path / "cell" / "c.toml").write_text('[[arm]]\nname = "r"\nurdf = "package://vendor/six.urdf"\n')
    cell = load_cell(tmp_path / "cell" / "c.toml", packages={"vendor": pkg})
    assert cell.arm("r").ik_family == "ur_type"
    with pytest.raises(XacroForbidden, match="vendor"):
        load_cell(tmp_path / "cell" / "c.toml")


# ---------------------------------------------------------------- hostile files
@pytest.mark.parametrize(
    "urdf, error, match",
    [("/etc/hostname", XacroForbidden, "relative path"), ("../user_scara.urdf", XacroForbidden, "relative path"),
     ("arms/../user_scara.urdf", XacroForbidden, "relative path"), ("missing.urdf", CellNotFound, "does not exist"),
     ("escape/user_scara.urdf", XacroForbidden, "outside")],
)
def test_arm_paths_stay_inside_the_allowed_folders(folder, urdf, error, match):
    outside = folder.parent / f"{folder.name}_outside"
    outside.mkdir()
    shutil.copy(DATA / "user_scara.urdf", outside / "user_scara.urdf")
    os.symlink(outside, folder / "escape")
    (folder / "bad.toml").write_text(f'[[arm]]\nname = "a"\nurdf = "{urdf}"\n', encoding="utf-8")
    with pytest.raises(error, match=match):
        load_cell(folder / "bad.toml")


@pytest.mark.parametrize(
    "body, match",
    [('[[arm]]\nname = "a"\nurdf = "user_scara.urdf"\ncolour = 1\n', "unknown key"),
     ('[[arm]]\nname = "a"\n', "missing key"),
     ('[[arm]]\nname = "a b"\nurdf = "user_scara.urdf"\n', "must start with a letter"),
     ('[[arm]]\nname = "a"\nurdf = "user_scara.urdf"\nxyz = [nan, 0, 0]\n', "finite"),
     ('[[arm]]\nname = "a"\nurdf = "user_scara.urdf"\nxyz = [0, 0]\n', "3 numbers"),
     ('[[arm]]\nname = "a"\nurdf = "user_scara.urdf"\n[[fixture]]\nname = "f"\nbox = [1, -1, 1]\n', "positive"),
     ('[[arm]]\nname = "a"\nurdf = "user_scara.urdf"\n[[arm]]\nname = "a"\nurdf = "user_scara.urdf"\n', "twice"),
     ('[[arm]]\nname = "a"\nurdf = "user_scara.urdf"\n[[fixture]]\nname = "a_post"\nsphere = 0.1\n', "clashes"),
     ('name = \n', "not valid TOML"), ('name = "x"\n', "missing key")],
)
def test_malformed_descriptions_raise_cell_errors_naming_the_problem(folder, body, match):
    (folder / "bad.toml").write_text(body, encoding="utf-8")
    with pytest.raises(CellError, match=match):
        load_cell(folder / "bad.toml")


def test_sizes_are_bounded_before_reading(folder):
    (folder / "big.toml").write_text("# " + "x" * MAX_DESCRIPTION_BYTES + "\n", encoding="utf-8")
    with pytest.raises(CellError, match="larger than"):
        read_cell_description(folder / "big.toml")


@pytest.mark.parametrize(
    "edit, match",
    [(lambda t: '<!DOCTYPE r [<!ENTITY x "y">]>\n' + t.split("?>", 1)[1], "DOCTYPE"),
     (lambda t: t.replace("</robot>", "<link"), "well-formed"),
     (lambda t: t.replace('<joint name="j2" type="revolute">', '<joint name="j2" type="revolute"><mimic joint="j1"/>'), None)],
)
def test_bad_arm_files_are_named(folder, edit, match):
    text = (DATA / "user_scara.urdf").read_text(encoding="utf-8")
    (folder / "user_scara.urdf").write_text(edit(text), encoding="utf-8")
    arm = ArmPlacement("a", "user_scara.urdf")
    if match is None:  # a mimic reference is prefixed with the rest
        assert '<mimic joint="a_j1"' in compose_cell_urdf([arm], base_dir=folder)
        return
    with pytest.raises(CellError, match=match) as info:
        compose_cell_urdf([arm], base_dir=folder)
    assert "user_scara.urdf" in str(info.value)


def test_an_arm_file_with_two_movable_subtrees_is_refused(folder):
    extra = ('<link name="aux"/><joint name="aux_fix" type="fixed"><parent link="base_link"/><child link="aux"/></joint>'
             '<link name="carriage"/><joint name="slide" type="prismatic"><parent link="aux"/><child link="carriage"/>'
             '<axis xyz="1 0 0"/><limit lower="0" upper="1" velocity="1" effort="1"/></joint></robot>')
    text = (DATA / "user_scara.urdf").read_text(encoding="utf-8").replace("</robot>", extra)
    (folder / "user_scara.urdf").write_text(text, encoding="utf-8")
    with pytest.raises(CellError, match="one base"):
        compose_cell_urdf([ArmPlacement("a", "user_scara.urdf")], base_dir=folder)


def test_deep_nesting_and_special_files_are_refused(folder):
    (folder / "deep.toml").write_text("a = " + "[" * 50000 + "]" * 50000 + "\n", encoding="utf-8")
    with pytest.raises(CellError, match="too deeply"):
        read_cell_description(folder / "deep.toml")
    os.mkfifo(folder / "pipe.urdf")
    with pytest.raises(CellError, match="not a regular file"):
        compose_cell_urdf([ArmPlacement("a", "pipe.urdf")], base_dir=folder)
