"""Bad input: named errors that say what to do; nothing half-built."""

import math

import numpy as np
import pytest

from pinarms import robots
from pinarms.optim.line.belt import Belt, PlaceBox
from pinarms.optim.line.errors import ArrivalsFileError, BeltOutOfReach
from pinarms.optim.line.items import ItemType, poisson_items, read_arrivals, regular_items
from pinarms.optim.line.simulate import SimArm, simulate
from pinarms.optim.line.station import Station, base_pose
from pinarms.optim.line.map_request import MapRequest
from pinarms.optim.line.task_map_build import build_task_map
from pinarms.optim.line.task_maps import TaskMap
from pinarms.errors import InvalidInput

BELT = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)
TYPES = (ItemType("enoki", 0.15, (0.10, 0.06, 0.04)),)


@pytest.mark.parametrize("speed", [0.0, -0.1, math.nan, math.inf, "fast", True])
def test_belt_speed_must_be_positive_and_finite(speed):
    with pytest.raises(InvalidInput, match="belt speed"):
        Belt((0.0, 0.0, 0.8), speed=speed)


def test_belt_direction_horizontal():
    with pytest.raises(InvalidInput, match="horizontal"):
        Belt((0.0, 0.0, 0.8), direction=(1.0, 0.0, 0.5))


def test_items_off_the_belt():
    with pytest.raises(InvalidInput, match="off the belt"):
        regular_items(BELT, 1.0, 10.0, w=0.14, types=TYPES)  # 0.14 + 0.03 > 0.15


def test_stream_is_seeded():
    a, b = poisson_items(BELT, 1.0, 100.0, seed=4), poisson_items(BELT, 1.0, 100.0, seed=4)
    assert np.array_equal(a.t0, b.t0) and np.array_equal(a.w, b.w)
    assert not np.array_equal(a.t0[:5], poisson_items(BELT, 1.0, 100.0, seed=5).t0[:5])


def test_arm_that_cannot_reach_the_belt_is_named():
    far = Station("far scara", robots.load("scara_mushroom"), base_pose(1.0, 1.5, 0.78), PlaceBox((1.0, 1.6, 0.93)))
    with pytest.raises(BeltOutOfReach, match=r"'far scara'.*nearest to its reach is u = 1\.\d+ m along, w = 0\.150 m"):
        build_task_map(MapRequest(far, BELT, nu=2, nw=2))


@pytest.mark.parametrize("text, row, column", [
    ("time,across,type\n0.5,0.0,enoki\n0.7,abc,enoki\n", "row 2", "'across'"),
    ("time,across,type\n0.5,0.0,enoki\n0.4,0.0,enoki\n", "row 2", "'time'"),
    ("time,across,type\n0.5,0.0,tulip\n", "row 1", "'type'"),
    ("time,across,type\n0.5,0.2,enoki\n", "row 1", "'across'"),
    ("time,across,type,yaw\n0.5,0.0,enoki,nan\n", "row 1", "'yaw'"),
])
def test_malformed_arrivals_file_names_row_and_column(tmp_path, text, row, column):
    p = tmp_path / "arrivals.csv"
    p.write_text(text)
    with pytest.raises(ArrivalsFileError) as e:
        read_arrivals(p, BELT, TYPES)
    assert row in str(e.value) and column in str(e.value)


def test_arrivals_file_missing_column_and_good_file(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("time,type\n0.5,enoki\n")
    with pytest.raises(ArrivalsFileError, match="'across'"):
        read_arrivals(p, BELT, TYPES)
    p.write_text("time,across,type,yaw\n0.5,0.01,enoki,0.3\n1.5,-0.02,enoki,0\n")
    items = read_arrivals(p, BELT, TYPES)
    assert items.t0.tolist() == [0.5, 1.5] and items.w.tolist() == [0.01, -0.02] and items.yaw[0] == 0.3


def test_simulate_rejects_bad_speed():
    items = regular_items(BELT, 1.0, 10.0, w=0.0)
    with pytest.raises(InvalidInput, match="at least one arm"):
        simulate([], items, 0.2)
    m = TaskMap("a", np.array([0.0, 0.1]), np.array([-0.15, 0.15]), np.ones((2, 2)), np.ones((2, 2)), 0.5, 0.1, 0.2, 0.1)
    for speed in (float("nan"), 0.0, -1.0):
        with pytest.raises(InvalidInput, match="belt speed"):
            simulate([SimArm("a", 1.0, (m,))], items, speed)
    with pytest.raises(InvalidInput, match="built for 0.2 m/s"):
        simulate([SimArm("a", 1.0, (m,))], items, 0.3)
