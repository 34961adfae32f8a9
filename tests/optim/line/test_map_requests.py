"""The map builds' one shape: a frozen request checked before any planning, a result with a status."""

import numpy as np
import pytest

from pinarms.errors import InvalidInput
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.delta_maps import build_delta_map
from pinarms.optim.line.map_request import (DeltaMapRequest, MapRequest, MapResult, MapStatus, TrayMapRequest)
from pinarms.optim.line.task_map_build import build_task_map
from pinarms.optim.line.task_maps import TaskMap
from pinarms.optim.line.tray_map import TrayMap
from pinarms.optim.line.tray_maps import build_tray_map
from pinarms.optim.line.trays import TrayBelt


@pytest.mark.parametrize("field, value, words", [
    ("nu", 1, "nu must be an integer >= 2"),
    ("nw", 2.0, "nw must be an integer >= 2"),
    ("yaw", "sometimes", "yaw must be one of"),
    ("yaw_nodes", 4, "yaw_nodes must be an odd integer >= 3"),
    ("yaw_refine", -1, "yaw_refine must be an integer >= 0"),
    ("du_range", (0.2, 0.1), "du_range must be two finite numbers, low < high"),
    ("du_range", (0.0, float("nan")), "du_range must be two finite numbers"),
    ("margin", 0.2, "leaves no belt width"),
    ("mass", -0.1, "mass \\[kg\\] must be a finite number >= 0"),
    ("tolerance", 0.0, "tolerance must be a finite number > 0"),
    ("refine", True, "refine must be an integer >= 0"),
])
def test_a_bad_field_is_named_before_any_planning(scara_line, field, value, words):
    belt, station = scara_line
    with pytest.raises(InvalidInput, match=words):
        MapRequest(station, belt, **{field: value})


def test_the_builds_take_only_their_request(scara_line):
    belt, station = scara_line
    with pytest.raises(InvalidInput, match="build_task_map takes a MapRequest"):
        build_task_map(station)
    trays = TrayBelt(Belt((0.0, 0.52, 0.82), speed=0.1, width=0.2))
    with pytest.raises(InvalidInput, match="build_tray_map takes a TrayMapRequest"):
        build_tray_map(MapRequest(station, belt))
    with pytest.raises(InvalidInput, match="yaw of a tray map must be one of"):
        TrayMapRequest(station, belt, trays, yaw="axis")
    with pytest.raises(InvalidInput, match="trays must be a TrayBelt"):
        TrayMapRequest(station, belt, belt)
    with pytest.raises(InvalidInput, match="holds no delta"):
        DeltaMapRequest(station, belt)
    with pytest.raises(InvalidInput, match="build_delta_map takes a DeltaMapRequest"):
        build_delta_map(MapRequest(station, belt))
    with pytest.raises(InvalidInput, match="station must be a Station"):
        MapRequest("scara 1", belt)
    rq = MapRequest(station, belt, nu=3)
    with pytest.raises(AttributeError):
        rq.nu = 4  # frozen


def test_a_result_says_its_status_in_words():
    m = TaskMap("a", np.array([0.0, 0.1]), np.array([-0.1, 0.1]), np.ones((2, 2)), np.ones((2, 2)), 0.5, 0.1, 0.2,
                0.1)
    res = MapResult(MapStatus.REFINE_LEFT, "times still bend in 3 yaw intervals", m, 12, 1, 2.5, 1.25)
    text = repr(res)
    assert res.status == "refine left" and f"{res.status}" == "refine left"
    for part in ("refine left (times still bend in 3 yaw intervals)", "12 plans", "1 blocked", "2.5 s wall",
                 "1.2 s CPU", "TaskMap('a'"):
        assert part in text, (part, text)


def test_a_tray_map_warns_about_the_yaw_it_ignores():
    du, w, dv = np.array([0.0, 0.1]), np.array([-0.1, 0.1]), np.array([0.0, 0.2])
    one = np.ones((1, 2, 2, 2))
    args = ("t", du, w, dv, np.ones((2, 2)), one, one, 0.5, 0.5, 0.2, 0.1, 0.1)
    assert "never measured" in TrayMap(*args).warnings()[0]
    assert TrayMap(*args, yaw_spread=0.001).warnings() == ()
    high = TrayMap(*args, yaw_spread=0.12)
    assert "changes by 12.0 %" in high.warnings()[0] and "tray map 't'" in high.warnings()[0]
    assert high.pick_map.yaw_spread == 0.12  # the simulator's pick part carries the measure
