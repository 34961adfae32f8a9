"""Controller files: JointTrajectory YAML and CSV at a chosen rate round-trip to 1e-9, stay within the
joint limits, and refuse bad rates and other robots' trajectories."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from pinarms import optim, robots
from pinarms.export import (
    InvalidRate,
    JointMismatch,
    controller_trajectory,
    read_trajectory_csv,
    read_trajectory_yaml,
    write_trajectory_csv,
    write_trajectory_yaml,
)
from pinarms.planning import multi_quintic
from pinarms.robots.errors import InvalidInput, LimitViolation

TOL = 1e-9


@pytest.fixture(scope="module")
def scara():
    return robots.load("scara_mushroom")


@pytest.fixture(scope="module")
def move(scara):
    q0 = np.zeros(scara.nq)
    q1 = 0.5 * (scara.lower + scara.upper) + 0.3 * (scara.upper - scara.lower)
    return multi_quintic([0.0, 1.1, 2.077], np.stack([q0, 0.5 * (q0 + q1) + 0.05, q1]), velocities="heuristic")


@pytest.mark.parametrize("rate", [125, 500, 333.3])
def test_round_trip_reproduces_the_trajectory(scara, move, rate, tmp_path):
    sampled = controller_trajectory(move, rate, robot=scara)
    step = 1.0 / rate
    assert sampled.times[0] == 0.0 and sampled.times[-1] == pytest.approx(move.duration, abs=1e-9)
    assert np.all(np.diff(sampled.times) <= step + 1e-9) and np.all(np.diff(sampled.times) > 0)
    assert len(sampled.times) == math.floor(move.duration * rate) + 1 + (move.duration * rate % 1 > 1e-9)
    assert np.all(sampled.positions >= scara.lower) and np.all(sampled.positions <= scara.upper)
    for write, read in ((write_trajectory_yaml, read_trajectory_yaml), (write_trajectory_csv, read_trajectory_csv)):
        path = tmp_path / f"move.{write.__name__[-4:]}"
        write(path, sampled)
        back = read(path, joint_names=scara.joint_names)
        assert back.joint_names == scara.joint_names
        np.testing.assert_array_equal(back.time_ns, sampled.time_ns)
        q, qd, qdd, _ = move.sample(move.start_time + back.times)
        np.testing.assert_allclose(back.positions, q, atol=TOL, rtol=0)
        np.testing.assert_allclose(back.velocities, qd, atol=TOL, rtol=0)
        np.testing.assert_allclose(back.accelerations, qdd, atol=TOL, rtol=0)


def test_yaml_is_a_joint_trajectory_message(scara, move, tmp_path):
    path = write_trajectory_yaml(tmp_path / "m.yaml", controller_trajectory(move, 125, robot=scara))
    doc = yaml.safe_load(path.read_text())
    assert set(doc) == {"header", "joint_names", "points"}
    assert doc["joint_names"] == list(scara.joint_names)
    point = doc["points"][1]
    assert set(point) == {"positions", "velocities", "accelerations", "effort", "time_from_start"}
    assert point["time_from_start"] == {"sec": 0, "nanosec": 8_000_000}
    assert all(isinstance(v, float) for v in point["positions"])


@pytest.mark.parametrize("rate", [0, -125, float("nan"), float("inf"), "500", True])
def test_bad_rate_is_a_named_error(scara, move, rate):
    with pytest.raises(InvalidRate, match="rate"):
        controller_trajectory(move, rate, robot=scara)


def test_another_robots_trajectory_is_refused(move, tmp_path):
    aubo = robots.load("aubo_i3")
    with pytest.raises(JointMismatch, match="aubo_i3"):
        controller_trajectory(move, 125, robot=aubo)
    path = write_trajectory_csv(tmp_path / "s.csv", controller_trajectory(move, 125, robot=robots.load("scara_mushroom")))
    with pytest.raises(JointMismatch, match="expected"):
        read_trajectory_csv(path, joint_names=aubo.joint_names)


def test_outside_the_limits_is_refused_not_clamped(scara):
    beyond = multi_quintic([0.0, 1.0], np.stack([np.zeros(scara.nq), scara.upper + 0.1]))
    with pytest.raises(LimitViolation, match="outside its limits"):
        controller_trajectory(beyond, 125, robot=scara)


def test_cycle_in_a_cell_uses_the_arms_prefixed_joints(tmp_path):
    from pinarms.robots.cell import load_cell

    cell = load_cell("aubo_food_station")
    arm = cell.arm("aubo")
    spec = optim.PickPlace(arm.to_base(np.array([0.36, 0.0, 0.75])), arm.to_base(np.array([0.0, -0.42, 0.77])),
                           lift=0.05, dwell=0.2)
    cycle = optim.plan_cycle(arm.robot, spec)
    sampled = controller_trajectory(cycle, 250, robot=cell, arm="aubo")
    assert sampled.joint_names == tuple("aubo_" + j for j in arm.robot.joint_names)
    back = read_trajectory_yaml(write_trajectory_yaml(tmp_path / "c.yaml", sampled))
    np.testing.assert_allclose(back.positions, cycle.trajectory(cycle.trajectory.start_time + back.times), atol=TOL, rtol=0)
    with pytest.raises(JointMismatch):
        controller_trajectory(cycle, 250, robot=robots.load("scara_mushroom"))
    with pytest.raises(InvalidInput, match="arm="):
        controller_trajectory(cycle, 250, robot=cell)


def test_unwritable_target_leaves_nothing(scara, move, tmp_path):
    sampled = controller_trajectory(move, 125, robot=scara)
    with pytest.raises(InvalidInput, match="does not exist"):
        write_trajectory_yaml(tmp_path / "missing" / "m.yaml", sampled)
    (tmp_path / "m.csv").write_text("old")
    write_trajectory_csv(tmp_path / "m.csv", sampled)
    assert (tmp_path / "m.csv").read_text().startswith("time_s,pos:")
    assert [p.name for p in tmp_path.iterdir()] == ["m.csv"]


def test_too_fast_is_refused(scara, move):
    fast = move.scaled(0.05)
    peak = float((fast.peaks().velocity / scara.velocity_limit).max())
    assert peak > 1.0
    with pytest.raises(LimitViolation, match="velocity limit"):
        controller_trajectory(fast, 125, robot=scara)


def test_accelerations_beyond_the_arms_limits_are_flagged(scara, move):
    """A move timed without acceleration limits (0.2 s for a small step: half the velocity limit, about twice
    the acceleration limit) is flagged by a warning naming the joint and by ``over_acceleration``; the slow
    move is not."""
    import warnings

    from pinarms.export.acceleration_check import AccelerationWarning

    q0 = np.zeros(scara.nq)
    step = 0.5 * scara.velocity_limit * 0.2 / 1.875  # a quintic's peak speed is 1.875 d / T
    jerky = multi_quintic([0.0, 0.2], np.stack([q0, q0 + step]))
    ratio = jerky.peaks().acceleration / scara.acceleration_limit
    assert np.all(jerky.peaks().velocity < scara.velocity_limit) and np.all(ratio > 1.5)
    with pytest.warns(AccelerationWarning, match=r"x its acceleration limit .* re-time it"):
        sampled = controller_trajectory(jerky, 500, robot=scara)
    assert sampled.over_acceleration == scara.joint_names
    assert np.all(move.peaks().acceleration < scara.acceleration_limit)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert controller_trajectory(move, 125, robot=scara).over_acceleration == ()
