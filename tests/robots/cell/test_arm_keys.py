"""Per-arm keys of a cell description: the tool point (tcp), frozen joints, named states, the hold pose; the crate."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pinarms import robots
from pinarms.robots import ArmPlacement, FixturePrimitive, ToolPoint, compose_cell, load_cell
from pinarms.errors import ArmStateError, CellError
from tests.robots.cell.bent_pair import bent_pair

DATA = Path(__file__).parent.parent / "data"

def _write(tmp_path: Path, b_keys: str = "") -> Path:
    return bent_pair(tmp_path, b_keys)


def _pose(xyz, rpy) -> np.ndarray:
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz, dtype=float)).homogeneous


# ------------------------------------------------------------------------- tcp
def test_without_a_tcp_key_the_last_link_is_the_tool_and_the_cell_says_so(tmp_path):
    cell = load_cell(_write(tmp_path))
    arm = cell.arm("b")
    assert arm.robot.tcp_frame == "finger"  # the moving finger: the deepest link
    assert arm.tcp_choice == "finger (the last link; no tcp given)"


def test_the_tcp_key_puts_the_tool_point_on_a_link_with_an_offset(tmp_path):
    cell = load_cell(_write(tmp_path, 'tcp = { link = "flange", xyz = [0.05, 0.0, 0.0], rpy = [0.0, 1.5707963267948966, 0.0] }'))
    arm = cell.arm("b")
    assert arm.tcp_choice == "flange + xyz (0.05, 0, 0) m, rpy (0, 1.5708, 0) rad"
    q = arm.robot.random_q(20, seed=3)
    flange = arm.robot.fk(q, "flange")
    np.testing.assert_allclose(arm.robot.fk(q), flange @ _pose([0.05, 0, 0], [0, np.pi / 2, 0]), atol=1e-12)
    qc = np.tile(cell.neutral, (20, 1))
    qc[:, arm.q_slice] = q
    np.testing.assert_allclose(cell.world_pose(qc, "b_tcp"), arm.base_to_world @ arm.robot.fk(q), atol=1e-12)
    # the tool down (docs/workspace.md): the tcp's z axis is the tool axis; here it is the flange's x axis
    np.testing.assert_allclose(arm.robot.fk(q)[:, :3, 2], flange[:, :3, 0], atol=1e-12)


def test_a_tcp_on_a_link_the_arm_does_not_have_is_a_named_error(tmp_path):
    with pytest.raises(CellError, match=r"arm 'b'.*tcp link 'flang'.*flange"):
        load_cell(_write(tmp_path, 'tcp = { link = "flang" }'))
    with pytest.raises(CellError, match="unknown key"):
        load_cell(_write(tmp_path, 'tcp = { link = "flange", xzy = [0, 0, 0] }'))


# ---------------------------------------------------------------------- freeze
def test_freeze_removes_the_gripper_joint_at_its_value_as_pinocchio_reduces_the_model(tmp_path):
    cell = load_cell(_write(tmp_path, "freeze = { finger_joint = 0.03 }"))
    arm = cell.arm("b")
    assert arm.robot.joint_names == ("j1", "j2") and cell.nq == 3 + 2
    assert dict(arm.frozen) == {"finger_joint": 0.03}
    full = pin.buildModelFromUrdf(str(DATA / "bent_arm.urdf"))
    q_lock = pin.neutral(full)
    q_lock[full.joints[full.getJointId("finger_joint")].idx_q] = 0.03
    reduced = pin.buildReducedModel(full, [full.getJointId("finger_joint")], q_lock)
    data = reduced.createData()
    for q in arm.robot.random_q(10, seed=5):
        pin.framesForwardKinematics(reduced, data, q)
        np.testing.assert_allclose(arm.robot.fk(q, "finger"), data.oMf[reduced.getFrameId("finger")].homogeneous,
                                   atol=1e-12)


def test_freeze_refuses_values_outside_the_limits_and_unknown_joints(tmp_path):
    with pytest.raises(ArmStateError, match=r"arm 'b'.*finger_joint = 0.05.*\[0, 0.04\]"):
        load_cell(_write(tmp_path, "freeze = { finger_joint = 0.05 }"))
    with pytest.raises(CellError, match=r"arm 'b'.*'thumb'.*finger_joint"):
        load_cell(_write(tmp_path, "freeze = { thumb = 0.0 }"))
    with pytest.raises(CellError, match=r"arm 'b'.*freeze finger_joint takes one value"):
        load_cell(_write(tmp_path, "freeze = { finger_joint = [0.0, 0.01] }"))


# ------------------------------------------------------------ states and hold
def test_the_hold_pose_is_the_idle_arms_configuration_and_clears_the_table(tmp_path):
    keys = 'hold = "home"\nstates = { home = [0.0, -1.2, 0.0], ready = [0.5, -1.0, 0.02] }'
    cell = load_cell(_write(tmp_path, keys))
    b = cell.arm("b")
    assert list(b.states) == ["home", "ready"]
    np.testing.assert_array_equal(b.hold, [0.0, -1.2, 0.0])
    np.testing.assert_array_equal(cell.hold[b.q_slice], [0.0, -1.2, 0.0])
    np.testing.assert_array_equal(cell.hold[cell.arm("a").q_slice], cell.neutral[cell.arm("a").q_slice])
    assert cell.in_collision(cell.neutral)  # b's upper arm in the table
    assert not cell.in_collision(cell.hold)
    np.testing.assert_array_equal(cell.q_from_arms({"a": [0.1, 0.2, 0.0]})[b.q_slice], b.hold)  # others at hold


def test_no_home_is_forced_and_a_hold_may_be_joint_values(tmp_path):
    cell = load_cell(_write(tmp_path, "hold = [0.3, -1.1, 0.01]"))
    assert dict(cell.arm("b").states) == {} and dict(cell.arm("a").states) == {}
    np.testing.assert_allclose(cell.arm("b").hold, [0.3, -1.1, 0.01])


@pytest.mark.parametrize("keys, match", [
    ("states = { home = [0.0, -2.5, 0.0] }", r"arm 'b'.*state 'home'.*j2 = -2.5.*\[-2, 2\]"),
    ("states = { home = [0.0, -1.2] }", r"arm 'b'.*state 'home'.*3 values.*j1, j2, finger_joint.*got 2"),
    ('hold = "rest"\nstates = { home = [0.0, -1.2, 0.0] }', r"arm 'b'.*hold 'rest'.*states: home"),
    ("hold = [0.0, 2.5, 0.0]", r"arm 'b'.*hold.*j2 = 2.5"),
])
def test_states_and_holds_outside_the_limits_or_miscounted_are_named_errors(tmp_path, keys, match):
    with pytest.raises(ArmStateError, match=match):
        load_cell(_write(tmp_path, keys))


def test_the_keys_from_python_and_a_moved_base_keep_them(tmp_path):
    shutil.copy(DATA / "bent_arm.urdf", tmp_path / "bent_arm.urdf")
    cell = compose_cell(
        [ArmPlacement("b", "bent_arm.urdf", (0.0, 0.0, 0.45), tcp=ToolPoint("flange", (0.05, 0.0, 0.0)),
                      freeze={"finger_joint": 0.0}, states={"home": (0.0, -1.2)}, hold="home")],
        [FixturePrimitive("table", "box", (0.4, 0.4, 0.06), (0.4, 0.0, 0.53))], base_dir=tmp_path)
    b = cell.arm("b")
    assert b.robot.joint_names == ("j1", "j2") and b.robot.tcp_frame == "tcp"
    np.testing.assert_array_equal(cell.hold, [0.0, -1.2])
    moved = cell.with_arm_base("b", _pose([0.0, 0.0, 0.40], [0, 0, 0]))
    np.testing.assert_array_equal(moved.hold, [0.0, -1.2])
    assert dict(moved.arm("b").frozen) == {"finger_joint": 0.0} and moved.arm("b").tcp_choice == b.tcp_choice


# ----------------------------------------------------------------------- crate
def test_a_crate_fixture_is_a_floor_and_four_walls_like_the_xacro_macro(tmp_path):
    shutil.copy(DATA / "bent_arm.urdf", tmp_path / "bent_arm.urdf")
    (tmp_path / "c.toml").write_text(
        'name = "c"\n[[arm]]\nname = "b"\nurdf = "bent_arm.urdf"\n'
        '[[fixture]]\nname = "crate"\ncrate = [0.30, 0.22, 0.16]\nwall = 0.01\nfloor = 0.012\nxyz = [0.3, 0.1, 0.7]\n'
        'rpy = [0.0, 0.0, 0.4]\n', encoding="utf-8")
    (tmp_path / "c.urdf.xacro").write_text(
        '<robot name="c" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:include filename="$(find pinarms)/fixtures.xacro"/>\n  <link name="world"/>\n'
        '  <xacro:fixture_crate name="crate" parent="world" size="0.30 0.22 0.16" wall="0.01" floor="0.012"'
        ' xyz="0.3 0.1 0.7" rpy="0 0 0.4"/>\n'
        '  <joint name="m" type="fixed"><parent link="world"/><child link="b_base_link"/></joint>\n'
        '  <link name="b_base_link"/>\n  <joint name="b_j1" type="revolute"><parent link="b_base_link"/>'
        '<child link="b_l1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>\n'
        '  <link name="b_l1"/>\n</robot>\n', encoding="utf-8")
    ours, theirs = load_cell(tmp_path / "c.toml"), load_cell(tmp_path / "c.urdf.xacro")
    names = ["crate", "crate_wall_xpos", "crate_wall_xneg", "crate_wall_ypos", "crate_wall_yneg"]
    assert [f.name for f in ours.fixtures] == names == [f.name for f in theirs.fixtures]
    for f in names:
        a, b = ours.fixture(f).shapes[0], theirs.fixture(f).shapes[0]
        assert a.kind == b.kind == "box"
        np.testing.assert_allclose(a.size, b.size, atol=1e-12)
        np.testing.assert_allclose(a.shape_to_world, b.shape_to_world, atol=1e-12)


@pytest.mark.parametrize("shape, match", [
    ("crate = [0.30, 0.22, 0.16]\nwall = [0.01, 0.02]", "one number each"),
    ("crate = [0.30, 0.22, 0.16]\nfloor = 0.2", "floor 0.2 m"),
    ("box = [0.1, 0.1, 0.1]\nwall = 0.01", "wall belong to a crate, not a box"),
])
def test_crate_keys_are_checked(tmp_path, shape, match):
    shutil.copy(DATA / "bent_arm.urdf", tmp_path / "bent_arm.urdf")
    (tmp_path / "c.toml").write_text(f'[[arm]]\nname = "b"\nurdf = "bent_arm.urdf"\n[[fixture]]\nname = "crate"\n{shape}\n',
                                     encoding="utf-8")
    with pytest.raises(CellError, match=match):
        robots.load_cell(tmp_path / "c.toml")


def test_a_crate_with_walls_thicker_than_half_its_width_is_refused(tmp_path):
    shutil.copy(DATA / "bent_arm.urdf", tmp_path / "bent_arm.urdf")
    (tmp_path / "c.toml").write_text('[[arm]]\nname = "b"\nurdf = "bent_arm.urdf"\n'
                                     '[[fixture]]\nname = "crate"\ncrate = [0.30, 0.22, 0.16]\nwall = 0.12\n',
                                     encoding="utf-8")
    with pytest.raises(CellError, match=r"fixture #1 \('crate'\).*wall 0.12.*floor"):
        robots.load_cell(tmp_path / "c.toml")


@pytest.mark.parametrize("edit", [('<origin xyz="0.02 0 0"/><axis xyz="0 1 0"/>', '<origin xyz="0.02 0"/><axis xyz="0 1 0"/>'),
                                  ('<origin xyz="0.02 0 0"/><axis xyz="0 1 0"/>', '<origin xyz="0.02 0 0"/><axis xyz="0 0 0"/>'),
                                  ('<origin xyz="0.02 0 0"/><axis xyz="0 1 0"/>', '<origin xyz="a b c"/><axis xyz="0 1 0"/>')])
def test_freezing_a_joint_with_a_malformed_origin_or_axis_is_a_named_error(tmp_path, edit):
    path = _write(tmp_path, "freeze = { finger_joint = 0.01 }")
    urdf = tmp_path / "bent_arm.urdf"
    text = urdf.read_text(encoding="utf-8")
    assert edit[0] in text
    urdf.write_text(text.replace(edit[0], edit[1]), encoding="utf-8")
    with pytest.raises(CellError, match=r"arm 'b'.*cannot apply freeze/tcp"):
        load_cell(path)
