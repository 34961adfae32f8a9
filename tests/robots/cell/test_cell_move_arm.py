"""Moving one arm's base in a cell (cell/move_arm.py behind Cell.with_arm_base)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from pinarms.robots.cell import load_cell
from pinarms.robots.cell.move_arm import urdf_with_arm_base
from pinarms.errors import InvalidInput


def turn_and_shift(yaw: float, xyz: tuple[float, float, float]) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    T = np.eye(4)
    T[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    T[:3, 3] = xyz
    return T


@pytest.fixture(scope="module")
def line():
    return load_cell("mushroom_line")


@pytest.fixture(scope="module")
def moved(line):
    shift = turn_and_shift(0.3, (0.04, -0.03, 0.0))
    target = shift @ line.arm("left").base_to_world
    return shift, target, line.with_arm_base("left", target, carry=("left_pedestal",))


def test_the_base_its_tcp_and_the_carried_fixture_move_the_rest_stays(line, moved):
    shift, target, cell = moved
    np.testing.assert_allclose(cell.arm("left").base_to_world, target, atol=1e-12)
    np.testing.assert_allclose(cell.arm("right").base_to_world, line.arm("right").base_to_world, atol=1e-12)
    q = line.random_q(5, seed=4)
    np.testing.assert_allclose(cell.world_pose(q, "left_tcp"), shift @ line.world_pose(q, "left_tcp"), atol=1e-12)
    np.testing.assert_allclose(cell.world_pose(q, "right_tcp"), line.world_pose(q, "right_tcp"), atol=1e-12)
    pedestal = cell.fixture("left_pedestal").shapes[0].shape_to_world
    np.testing.assert_allclose(pedestal, shift @ line.fixture("left_pedestal").shapes[0].shape_to_world, atol=1e-12)
    table = cell.fixture("left_table").shapes[0].shape_to_world
    np.testing.assert_allclose(table, line.fixture("left_table").shapes[0].shape_to_world, atol=1e-12)
    assert "(arm 'left' moved)" in cell.source
    assert not np.allclose(line.arm("left").base_to_world, target)  # the original cell is unchanged


def test_moving_an_arm_to_where_it_stands_keeps_its_mount(line):
    text = urdf_with_arm_base(line, "right", line.arm("right").base_to_world)

    def origin(urdf: str) -> np.ndarray:
        joint = next(j for j in ET.fromstring(urdf).iter("joint") if j.get("name") == "right_base_mount")
        element = joint.find("origin")
        return np.array([float(v) for v in (element.get("xyz") + " " + element.get("rpy")).split()])

    np.testing.assert_allclose(origin(text), origin(line.urdf_text), atol=1e-12)


@pytest.mark.parametrize(
    "arm, pose, carry, needle",
    [
        ("middle", np.eye(4), (), "arms: left, right"),
        ("left", np.diag([2.0, 1.0, 1.0, 1.0]), (), "rigid transform"),
        ("left", np.diag([1.0, 1.0, -1.0, 1.0]), (), "rigid transform"),
        ("left", np.eye(4), ("nowhere",), "no fixture 'nowhere'"),
    ],
)
def test_bad_moves_are_refused_before_anything_is_built(line, arm, pose, carry, needle):
    with pytest.raises(InvalidInput, match=needle):
        line.with_arm_base(arm, pose, carry=carry)
