"""optim.motion.request: one MotionRequest, checked when built; nothing is planned here (fast)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from pinarms import robots
from pinarms.optim import InvalidLimits, InvalidSettings
from pinarms.optim.motion import MotionLimits, MotionOptions, MotionRequest, load_scene
from pinarms.errors import InvalidInput

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def wall():
    return robots.load_cell(DATA / "aubo_wall.urdf.xacro")


def test_options_and_limits_are_frozen_and_normalised():
    o = MotionOptions(margin=np.float32(0.02), planner="RRTConnect", time_limit=2, seed=np.int64(3))
    assert (o.margin, o.planner, o.time_limit, o.seed) == (pytest.approx(0.02), "rrtconnect", 2.0, 3)
    assert type(o.time_limit) is float and type(o.seed) is int
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.margin = 0.05
    lim = MotionLimits(vmax=2.0, amax=[1.0, 2.0], torque=None)
    np.testing.assert_array_equal(lim.vmax, [2.0])
    np.testing.assert_array_equal(lim.amax, [1.0, 2.0])
    assert lim.torque is False and MotionLimits(amax=False).amax is False
    for bad in (0.0, -1.0, np.nan, [1.0, np.inf], "fast"):
        with pytest.raises(InvalidLimits, match="vmax must be one positive number"):
            MotionLimits(vmax=bad)
    for bad in (0, -2.0, True, np.nan):
        with pytest.raises(InvalidSettings, match="time_limit must be a positive number"):
            MotionOptions(time_limit=bad)
    with pytest.raises(InvalidInput, match="self_margin must be a finite number >= 0"):
        MotionOptions(self_margin=-0.001)


def test_the_request_resolves_the_arm_the_ends_and_the_limits(wall):
    arm = wall.arm("aubo")
    q0 = np.array(arm.hold, dtype=float)
    request = MotionRequest(wall, "aubo", list(q0), q0 + 0.1, limits=MotionLimits(vmax=1.5, torque=False))
    assert request.arms == ("aubo",) and not request.pose_goal
    assert request.start.shape == (arm.nq,) and not request.start.flags.writeable
    np.testing.assert_array_equal(request.limit_values["vmax"], np.full(arm.nq, 1.5))
    assert request.limit_values["torque"] is None and len(request.constraints) == 2  # velocity, acceleration
    assert request.limit_values["amax_source"] == arm.robot.acceleration_source
    T = arm.tcp_to_world(q0 + 0.1)
    assert MotionRequest(wall, "aubo", q0, T).pose_goal
    with pytest.raises(InvalidInput, match="goal pose must be a finite homogeneous transform"):
        MotionRequest(wall, "aubo", q0, T * 2.0)
    with pytest.raises(InvalidInput, match="frame 'flange': pose goals are for the arm's tcp"):
        MotionRequest(wall, "aubo", q0, T, frame="flange")
    with pytest.raises(InvalidLimits, match="amax must be one positive number or 6"):
        MotionRequest(wall, "aubo", q0, q0 + 0.1, limits=MotionLimits(amax=[1.0, 2.0]))
    with pytest.raises(InvalidInput, match="cell must be a robots.Cell, got Robot"):
        MotionRequest(arm.robot, "aubo", q0, q0 + 0.1)
    with pytest.raises(InvalidInput, match=r"hold \(the cell configuration of the arms not planned\): .* got \(2,\)"):
        MotionRequest(wall, "aubo", q0, q0 + 0.1, hold=[0.0, 1.0])


def test_two_arms_take_their_joints_by_name_and_no_pose_goal():
    cell = load_scene("aubo_two_belt")
    a, b = (arm.name for arm in cell.arms)
    qa, qb = (np.array(cell.arm(n).hold, dtype=float) for n in (a, b))
    request = MotionRequest(cell, (a, b), {a: qa, b: qb}, {a: qa + 0.1, b: qb - 0.1})
    np.testing.assert_array_equal(request.start, np.concatenate([qa, qb]))
    np.testing.assert_array_equal(request.goal, np.concatenate([qa + 0.1, qb - 0.1]))
    with pytest.raises(InvalidInput, match="start gives no joints for arm"):
        MotionRequest(cell, (a, b), {a: qa}, {a: qa, b: qb})
    with pytest.raises(InvalidInput, match="a pose goal needs one planned arm"):
        MotionRequest(cell, (a, b), {a: qa, b: qb}, np.eye(4))
