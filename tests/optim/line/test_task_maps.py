"""Task-time maps against exact re-planning on random items; saved and read back."""

import numpy as np
import pytest

from pinarms.optim.line.map_refine import bent_lines
from pinarms.optim.line.map_request import MapRequest
from pinarms.optim.line.task_map_build import build_task_map
from pinarms.optim.line.task_map_error import MapError, map_error
from pinarms.optim.line.task_maps import TaskMap
from pinarms.optim.line.tracking import TrackingSpec, plan_pick
from pinarms.optim.line.windows import window_of


@pytest.fixture(scope="module")
def small_map(scara_line):
    belt, station = scara_line
    # part of the window (0.04 m grid along, 0.05 m across): a few seconds to build
    # yaw="none": the SCARA's independence of yaw is measured in test_yaw_maps.py
    return build_task_map(MapRequest(station, belt, TrackingSpec(), nu=6, nw=3, du_range=(0.0, 0.2), margin=0.075,
                                     yaw="none")).task_map


def test_map_nodes_are_exact_plans(scara_line, small_map):
    belt, station = scara_line
    i, j = 2, 1
    assert small_map.branches == (0, 1)  # the SCARA's two elbows, each tabled
    for b, label in enumerate(small_map.branches):
        plan = plan_pick(station, belt, TrackingSpec(), 1.0 + small_map.du[i], small_map.w[j], mass=small_map.mass,
                         branch=label)
        assert small_map.branch_approach[b, i, j] == pytest.approx(plan.times[0], rel=1e-12)
        assert small_map.branch_leave[b, i, j] == pytest.approx(plan.times[2], rel=1e-12)
    tot = small_map.branch_approach[:, i, j] + small_map.branch_leave[:, i, j]
    assert small_map.approach[i, j] + small_map.leave[i, j] == pytest.approx(np.nanmin(tot), rel=1e-12)


def test_map_error_against_exact_planning(scara_line, small_map):
    belt, station = scara_line
    err = map_error(small_map, station, belt, TrackingSpec(), n=6, seed=1)
    assert err.relative.size == 6
    # a coarse test map; docs/line.md reports the full map (24 x 7)
    assert err.max < 0.01


def test_no_interpolation_across_ik_branches(scara_line, small_map):
    """Where the fastest elbow changes between grid cells, the exact task time jumps (the other elbow
    is 0.3 s slower): the map keeps each cell on one branch and the simulator's grid repeats that
    node, so both sides agree with exact planning on the branch the map names."""
    belt, station = scara_line
    cells = small_map._cell
    n = next(k for k in range(1, cells.shape[0]) if np.any(cells[k - 1] != cells[k]))  # this map straddles one
    du_grid, node, _ = small_map.sim_grid()
    assert du_grid.size > small_map.du.size and np.count_nonzero(node == n) == 2 and np.all(np.diff(du_grid) >= 0)
    j = int(np.flatnonzero(cells[n - 1] != cells[n])[0])
    w = 0.5 * (small_map.w[j] + small_map.w[j + 1])
    for du in (small_map.du[n] - 0.004, small_map.du[n] + 0.004):  # either side of the node
        tA, tC = small_map.times(du, w)
        label = small_map.branch_at(du, w)
        plan = plan_pick(station, belt, TrackingSpec(), 1.0 + du, w, mass=small_map.mass, branch=label)
        assert float(tA + tC) + plan.times[1] + plan.times[3] == pytest.approx(plan.duration, rel=0.01)
    assert small_map.branch_at(small_map.du[n] - 0.004, w) != small_map.branch_at(small_map.du[n] + 0.004, w)


def test_map_round_trip_and_window(tmp_path, scara_line, small_map):
    belt, station = scara_line
    back = TaskMap.load(small_map.save(tmp_path / "m.npz"))
    assert np.array_equal(back.approach, small_map.approach, equal_nan=True) and back.speed == small_map.speed
    win = window_of(station, belt, small_map)
    assert win.u_base == pytest.approx(1.0) and 1.0 <= win.u_min < win.u_max <= 1.2 + 1e-9
    tA, tC = small_map.times(0.1, 0.0)
    assert np.isfinite(tA) and np.isfinite(tC)
    assert np.isnan(small_map.times(0.5, 0.0)[0])  # outside the grid: infeasible, never extrapolated


def test_refinement_marks_a_kink_between_nodes_only():
    """A V-shaped valley of the leave time at one node (slope -1 to +1 s/m on a 0.05 m grid, a
    second difference of 0.1 s on a 3.1 s task, above 4 x 0.5 %) marks the two intervals beside it;
    a straight or gently bent table marks none; an infeasible node hides nothing it cannot see."""
    du = np.linspace(0.0, 0.3, 7)
    A = np.full((1, 7, 2), 1.5)
    C = np.tile(1.0 + np.abs(du - 0.15)[None, :, None], (1, 1, 2))
    assert np.allclose(bent_lines(du, A, C, 0.6, 0.005, 1), [0.125, 0.175])
    assert bent_lines(du, A, A.copy() + 0.1 * du[None, :, None], 0.6, 0.005, 1).size == 0
    assert bent_lines(np.array([-0.1, 0.1]), A, C, 0.6, 0.005, 2).size == 0
    C[0, 3, 0] = np.nan
    assert bent_lines(du, A, C, 0.6, 0.005, 1).size == 2  # still seen on the other row


def test_reprs_are_short_and_give_the_figures():
    du, w = np.linspace(0.0, 0.6, 31), np.linspace(-0.2, 0.2, 21)
    a = np.full((31, 21), 0.4)
    a[0, 0] = np.nan
    m = TaskMap("a", du, w, a, a + 0.1, 0.5, 0.1, 0.2, 0.25, branches=(0, 1),
                branch_approach=np.stack([a, a + 0.2]), branch_leave=np.stack([a + 0.1, a + 0.3]))
    text = repr(m)
    assert len(text) < 300 and "array" not in text and "\n" not in text
    for part in ("'a'", "31 x 21", "du 0..0.6 m", "w -0.2..0.2 m", "approach 0.4..0.4 s", "leave 0.5..0.5 s",
                 "2 branches", "1 infeasible", "speed 0.2 m/s", "mass 0.25 kg"):
        assert part in text, (part, text)
    e = MapError(np.linspace(0.0, 0.02, 50), np.zeros((50, 2)), 3.25)
    text = repr(e)
    assert len(text) < 200 and "array" not in text
    for part in ("50 points", "max 2.00 %", "mean 1.00 %", "p95 1.90 %", "3.2 s"):
        assert part in text, (part, text)
    assert "0 points" in repr(MapError(np.zeros(0), np.zeros((0, 2)), 0.0))
