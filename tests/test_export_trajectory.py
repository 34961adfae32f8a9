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
from pinarms.errors import InvalidInput, LimitViolation

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
    cycle = optim.plan_cycle(optim.CycleRequest(arm.robot, spec))
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


def _renamed(sampled, names):
    from pinarms.export import ControllerTrajectory

    return ControllerTrajectory(tuple(names), sampled.time_ns, sampled.positions, sampled.velocities,
                                sampled.accelerations)


@pytest.mark.parametrize("name", ["x', 'y", 'a"b', "j: 1", "#j", "- j", "j\nk", "1joint", "", "joint-1", "a b"])
def test_a_joint_name_outside_the_ros_rule_is_refused(scara, move, name, tmp_path):
    from pinarms.export import InvalidJointName

    sampled = _renamed(controller_trajectory(move, 125, robot=scara), ("j1", name, "j3", "j4"))
    with pytest.raises(InvalidJointName, match="joint name"):
        write_trajectory_yaml(tmp_path / "m.yaml", sampled)
    assert list(tmp_path.iterdir()) == []


def test_names_and_frame_round_trip_through_the_yaml_emitter(scara, move, tmp_path):
    names = ("/left/j1", "left/j_2", "J3", "a/b/c4")
    sampled = _renamed(controller_trajectory(move, 125, robot=scara), names)
    path = write_trajectory_yaml(tmp_path / "m.yaml", sampled, frame_id="x', 'y: #z")
    doc = yaml.safe_load(path.read_text())
    assert doc["header"]["frame_id"] == "x', 'y: #z"
    assert read_trajectory_yaml(path).joint_names == names


def _yaml_file(tmp_path, text):
    path = tmp_path / "t.yaml"
    path.write_text(text)
    return path


GOOD = ("joint_names: [a, b]\npoints:\n- positions: [0.0, 1.0]\n  velocities: [0.0, 0.0]\n"
        "  accelerations: [0.0, 0.0]\n  time_from_start: {sec: 0, nanosec: 0}\n")


@pytest.mark.parametrize("text, what", [
    ("joint_names: ['x', 'y\n", "not valid YAML"),
    ("joint_names: [a, b]\npoints: 'x\"", "not valid YAML"),
    ("\x00", "not valid YAML"),
    (GOOD.replace("[0.0, 1.0]", "!!binary AAAA"), "binary"),
    (GOOD.replace("[a, b]", "!!python/tuple [a, b]"), "python/tuple"),
    (GOOD.replace("{sec: 0, nanosec: 0}", "!!timestamp 2001-12-14"), "timestamp"),
    ("joint_names: &n [a, b]\npoints:\n- positions: *n\n", "alias"),
    (GOOD.replace("[a, b]", "[1, 2]"), "joint_names"),
    (GOOD.replace("[0.0, 1.0]", "[0.0, .nan]"), "finite"),
    (GOOD.replace("[0.0, 1.0]", "[0.0, 1.0, 2.0]"), "positions"),
    (GOOD.replace("sec: 0,", "sec: -1,"), "time_from_start"),
    ("[1, 2]", "JointTrajectory"),
])
def test_a_malformed_yaml_file_is_a_named_error(tmp_path, text, what):
    from pinarms.export import TrajectoryFileError

    with pytest.raises(TrajectoryFileError, match=what) as info:
        read_trajectory_yaml(_yaml_file(tmp_path, text))
    assert "t.yaml" in str(info.value)


def test_a_well_formed_foreign_yaml_file_reads(tmp_path):
    back = read_trajectory_yaml(_yaml_file(tmp_path, GOOD))
    assert back.joint_names == ("a", "b") and back.positions.tolist() == [[0.0, 1.0]]


def test_trajectory_files_are_bounded_before_reading(tmp_path, monkeypatch):
    from pinarms.export import TrajectoryFileError, trajectory_read

    monkeypatch.setattr(trajectory_read, "MAX_FILE_BYTES", 100)
    big = _yaml_file(tmp_path, GOOD + "#" * 200)
    with pytest.raises(TrajectoryFileError, match="100 bytes"):
        read_trajectory_yaml(big)
    with pytest.raises(TrajectoryFileError, match="not a regular file"):
        read_trajectory_csv(tmp_path)


def test_a_csv_field_over_the_csv_limit_is_a_named_error(tmp_path):
    from pinarms.export import TrajectoryFileError

    path = tmp_path / "t.csv"
    path.write_text("time_s,pos:a,vel:a,acc:a\n0.0,\"" + "1" * (200 * 1024) + "\",0,0\n")
    with pytest.raises(TrajectoryFileError, match="t.csv"):
        read_trajectory_csv(path)
    path.write_text("time_s,pos:a,vel:a,acc:a\n0.0,x,0,0\n")
    with pytest.raises(TrajectoryFileError, match="row 1"):
        read_trajectory_csv(path)
