"""Every built-in arm is a xacro macro (prefix, parent, xyz, rpy): several arms in one file."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinarms.robots.urdf_build import XACRO_DIR, build_file, source_names

from _descriptions import independent_joint_names, pin_frame, pin_model, random_q

# (macro, prefix, xyz, rpy): two SCARAs facing each other and one of every other arm
PLACED = [
    ("scara_mushroom", "left_", (0.0, 0.55, 0.0), (0.0, 0.0, -np.pi / 2)),
    ("scara_mushroom", "right_", (0.0, -0.55, 0.0), (0.0, 0.0, np.pi / 2)),
    ("aubo_i3", "aubo_", (2.0, 0.0, 0.75), (0.0, 0.0, 0.3)),
    ("gantry_flower", "gantry_", (4.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
    ("koji_turner", "koji_", (8.0, 0.0, 2.5), (0.0, 0.0, 1.0)),
    ("koji_turner_rail", "rail_", (12.0, 0.0, 3.0), (0.1, -0.2, 0.3)),
]


def _cell_xacro(placed) -> str:
    includes = "".join(f'  <xacro:include filename="{XACRO_DIR / m}.xacro"/>\n' for m in sorted({p[0] for p in placed}))
    calls = "".join(
        f'  <xacro:{m} prefix="{pre}" parent="world" xyz="{" ".join(map(repr, xyz))}" rpy="{" ".join(map(repr, rpy))}"/>\n'
        for m, pre, xyz, rpy in placed
    )
    return (
        '<?xml version="1.0"?>\n<robot name="all_arms" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        + includes
        + '  <xacro:pinarms_materials/>\n  <link name="world"/>\n'
        + calls
        + "</robot>\n"
    )


@pytest.fixture(scope="module")
def cell_model(tmp_path_factory):
    path = tmp_path_factory.mktemp("cell") / "all_arms.urdf.xacro"
    path.write_text(_cell_xacro(PLACED))
    text = build_file(path)
    return pin.buildModelFromXML(text, mimic=True), text


def test_every_built_in_arm_has_a_macro_file():
    for name in source_names():
        text = (XACRO_DIR / f"{name}.xacro").read_text()
        assert f'<xacro:macro name="{name}" params="prefix:=\'\' parent:=\'\' xyz:=\'0 0 0\' rpy:=\'0 0 0\'">' in text


def test_prefixed_arms_share_one_model_with_unique_names(cell_model):
    model, text = cell_model
    names = independent_joint_names(model)
    for macro, prefix, _, _ in PLACED:  # each arm's joints: contiguous, in the single arm's order
        own = [prefix + j for j in independent_joint_names(pin_model(macro))]
        start = names.index(own[0])
        assert names[start : start + len(own)] == own
    assert len(names) == len(set(names))
    assert text.count('<material name="pinarms_grey">') == 1  # materials emitted once, by the caller
    assert model.nq == sum(pin_model(m).nq for m, *_ in PLACED)


@pytest.mark.parametrize("macro, prefix, xyz, rpy", PLACED)
def test_each_placed_arm_is_the_single_arm_moved_to_its_mount(cell_model, macro, prefix, xyz, rpy):
    model, _ = cell_model
    single = pin_model(macro)
    mount = pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz)).homogeneous
    idx = [model.joints[model.getJointId(prefix + n)].idx_q for n in independent_joint_names(single)]
    rng = np.random.default_rng(5)
    for q_arm in random_q(single, 6, seed=11):
        q = rng.uniform(model.lowerPositionLimit, model.upperPositionLimit)  # other arms anywhere
        q[idx] = q_arm
        for frame in ("base_link", "flange", "tcp"):
            expected = mount @ pin_frame(single, q_arm, frame)
            np.testing.assert_allclose(pin_frame(model, q, prefix + frame), expected, atol=1e-12, err_msg=prefix + frame)
