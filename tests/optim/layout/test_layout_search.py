"""Layout search: failures named, cycles equal to plan_cycle's, ranking, refinement, Dask identity."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import optim, robots
from pinarms.optim.layout.search import (CandidateFailure, LayoutRequest, LayoutStatus, base_to_world, grid_candidates,
                                         random_candidates, search_layout)
from pinarms.errors import InvalidInput

#: The scheduler's HTTP endpoint (health and metrics; no dashboard) on a free loopback port, not on
#: the fixed 8787 that every other LocalCluster of a parallel run tries first.
LOOPBACK_HTTP = {"dashboard_address": "127.0.0.1:0"}

pytestmark = pytest.mark.filterwarnings("ignore:Port .* is already in use:UserWarning")


@pytest.fixture(scope="module")
def scara():
    return robots.load("scara_mushroom")


@pytest.fixture(scope="module")
def points(scara):
    """A pick and a place the SCARA reaches from its base at the origin (line frame = base frame there)."""
    q = scara.neutral.copy()
    q[1], q[2] = 0.5, 0.05
    pick = scara.fk(q)[:3, 3]
    q[0] = 0.8
    return pick, scara.fk(q)[:3, 3]


def test_grid_and_random_candidates():
    g = grid_candidates(x=(0.2, 0.4, 0.1), y=(-0.1, 0.1, 0.1), z=0.0, yaw=(0.0, np.pi / 2, np.pi / 2))
    assert g.shape == (3 * 3 * 2, 4)
    assert np.allclose(g[:3], [[0.2, -0.1, 0, 0], [0.2, -0.1, 0, np.pi / 2], [0.2, 0.0, 0, 0]])
    assert np.allclose(g[-1], [0.4, 0.1, 0.0, np.pi / 2])  # hi is included despite rounding
    r1 = random_candidates(50, x=(0, 1), y=(-1, 0), yaw=(0, 1), seed=3)
    assert np.array_equal(r1, random_candidates(50, x=(0, 1), y=(-1, 0), yaw=(0, 1), seed=3))
    assert np.all(r1[:, 2] == 0.0) and r1[:, 0].min() >= 0 and r1[:, 1].max() <= 0
    with pytest.raises(InvalidInput, match="step > 0"):
        grid_candidates(x=(0, 1, 0), y=0)
    with pytest.raises(InvalidInput, match="positive number"):
        random_candidates(0, x=(0, 1), y=0)


def test_failures_say_why_and_the_planned_cycle_is_plan_cycles(scara, points):
    pick, place = points
    # 0: base at the origin; 1: 2 m away (beyond reach); 2: turned 180° (the pick is behind it: j1 limit)
    cand = np.array([[0.0, 0.0, 0.0, 0.0], [2.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, np.pi]])
    res = search_layout(LayoutRequest(scara, pick, place, cand, lift=0.02, refine=0, workspace_samples=20_000))
    assert res.failure == (None, CandidateFailure.UNREACHABLE, CandidateFailure.JOINT_LIMIT)
    assert res.failure[1] == "unreachable" and f"{res.failure[2]}" == "joint limit"  # the words are kept
    assert res.status is LayoutStatus.FOUND and res.status_reason == ""
    assert "pick 1 (0.426, 0.096, 0.140) m" in res.reason[1] and "beyond the arm's reach" in res.reason[1]
    assert "j1" in res.reason[2] and "outside" in res.reason[2]
    assert res.failures() == {"unreachable": 1, "joint limit": 1}
    direct = optim.plan_cycle(optim.CycleRequest(scara, optim.PickPlace(pick, place, lift=0.02, dwell=0.2)))
    assert res.cycle_time[0] == direct.cycle_time
    assert res.picks_per_minute[0] == pytest.approx(60.0 / direct.cycle_time, rel=1e-15)
    assert res.picks_per_minute[1] == 0.0 and np.isnan(res.cycle_time[2])
    assert res.branch[0] == direct.branches[0]
    assert res.manipulability[0] == pytest.approx(
        min(scara.manipulability(direct.q_via[[0, 3]], part="position")), rel=1e-12)
    assert res.margin[0] > 0 and res.margin[1] == 0.0
    assert list(res.order) == [0, 1, 2] and res.best_index == 0
    assert np.array_equal(res.best_placement, cand[0]) and res.best_cycle.cycle_time == direct.cycle_time
    text = res.table()
    assert "3 placements, 1 planned, 1 unreachable, 1 joint limit" in text and "best placement" in text
    d = res.as_dict()
    assert d["candidates"][0]["ok"] and d["candidates"][2]["failure"] == "joint limit"


def test_a_placement_moves_the_points_into_the_base_frame(scara, points):
    pick, place = points
    placement = np.array([0.3, -0.2, -0.01, 0.7])
    T = base_to_world(placement)
    # the line points that sit where pick/place sit for a base at the origin
    pick_w, place_w = ((T @ np.append(p, 1.0))[:3] for p in (pick, place))
    res = search_layout(LayoutRequest(scara, pick_w, place_w, placement[None], lift=0.02, refine=0, workspace_samples=20_000))
    direct = optim.plan_cycle(optim.CycleRequest(scara, optim.PickPlace(pick, place, lift=0.02, dwell=0.2)))
    assert res.cycle_time[0] == pytest.approx(direct.cycle_time, rel=1e-9)


def test_ranking_and_refinement_gain(scara, points):
    pick, place = points
    cand = grid_candidates(x=(-0.1, 0.1, 0.1), y=(-0.1, 0.1, 0.1))
    res = search_layout(LayoutRequest(scara, pick, place, cand, lift=0.02, refine=1, refine_evaluations=10,
                        workspace_samples=20_000))
    ok = res.ok
    ppm = res.picks_per_minute[res.order]
    assert np.all(np.diff(ppm[ok[res.order]]) <= 1e-9 * ppm.max())  # descending
    r = res.refinement
    assert r is not None and r.free == ("x", "y") and r.starts[0] == res.best_index
    assert r.gain >= 0.0 and r.evaluations[0] <= 10
    # the refined placement's picks/min is what a fresh evaluation gives, and it stays in the bounds
    p = r.placements[0]
    assert np.all(p[:2] >= -0.1 - 1e-12) and np.all(p[:2] <= 0.1 + 1e-12)
    again = search_layout(LayoutRequest(scara, pick, place, p[None], lift=0.02, refine=0, workspace_samples=20_000))
    assert again.picks_per_minute[0] == pytest.approx(r.picks_per_minute[0], rel=1e-12)
    assert res.best_picks_per_minute >= res.picks_per_minute[res.best_index]


@pytest.mark.slow
def test_search_on_a_cluster_equals_serial(scara, points):
    distributed = pytest.importorskip("distributed")
    pick, place = points
    cand = np.array([[0.0, 0.0, 0.0, 0.0], [2.0, 0.0, 0.0, 0.0], [0.0, 0.05, 0.0, -0.1]])
    kw = dict(lift=0.02, refine=1, refine_evaluations=4, workspace_samples=20_000, chunk_size=1)
    serial = search_layout(LayoutRequest(scara, pick, place, cand, **kw))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None,
                                  scheduler_kwargs=LOOPBACK_HTTP) as cluster, distributed.Client(cluster) as client:
        remote = search_layout(LayoutRequest(scara, pick, place, cand, **kw), scheduler=client)
    assert serial.cycle_time.tobytes() == remote.cycle_time.tobytes()
    assert serial.failure == remote.failure and list(serial.order) == list(remote.order)
    assert serial.refinement.placements.tobytes() == remote.refinement.placements.tobytes()
    assert serial.best_placement.tobytes() == remote.best_placement.tobytes()


def test_bad_input(scara, points):
    pick, place = points
    with pytest.raises(InvalidInput, match="candidates must be"):
        LayoutRequest(scara, pick, place, np.zeros((2, 3)))
    with pytest.raises(InvalidInput, match="picks"):
        LayoutRequest(scara, [1, 2], place, np.zeros((1, 4)))
    with pytest.raises(InvalidInput, match="lift"):
        LayoutRequest(scara, pick, place, np.zeros((1, 4)), lift=0.0)
    with pytest.raises(InvalidInput, match="pass the cell as robot"):
        LayoutRequest(scara, pick, place, np.zeros((1, 4)), arm="scara")


@pytest.mark.slow
def test_in_a_cell_a_candidate_that_collides_fails_as_collision():
    from pinarms.robots.cell import load_cell

    station = load_cell("aubo_food_station")
    pick, place = np.array([0.36, 0.0, 0.75]), np.array([0.0, -0.42, 0.77])
    # the cell's own placement; 250 mm towards the crate (the shoulder in the crate wall); out of reach
    cand = np.array([[0.0, 0.0, 0.7, 0.0], [0.0, -0.25, 0.7, 0.0], [0.9, 0.0, 0.7, 0.0]])
    res = search_layout(LayoutRequest(station, pick, place, cand, refine=0, carry=("stand",), workspace_samples=20_000))
    assert res.failure == (None, "collision", "unreachable")
    assert "crate_wall" in res.reason[1] and "clearance 20.0 mm" in res.reason[1]
    arm = station.arm("aubo")
    direct = optim.plan_cycle(optim.CycleRequest(arm.robot, optim.PickPlace(arm.to_base(pick), arm.to_base(place)),
                                                 cell=optim.CellSettings(station, clearance=0.02)))
    assert res.cycle_time[0] == pytest.approx(direct.cycle_time, rel=1e-12) and direct.cell_report.extra_time > 0
    assert res.best_cycle.cell_report.lift == direct.cell_report.lift
    with pytest.raises(InvalidInput, match="carry"):
        LayoutRequest(robots.load("aubo_i3"), pick, place, cand, carry=("stand",))


def test_min_margin_rules_out_points_near_the_workspace_edge(scara, points):
    pick, place = points
    cand = np.array([[0.0, 0.0, 0.0, 0.0], [0.1, 0.0, 0.0, 0.0]])
    free = search_layout(LayoutRequest(scara, pick, place, cand, lift=0.02, refine=0, workspace_samples=20_000))
    limit = float(np.mean(free.margin))  # between the two candidates' margins
    assert free.margin.min() < limit < free.margin.max()
    res = search_layout(LayoutRequest(scara, pick, place, cand, lift=0.02, refine=0, workspace_samples=20_000, min_margin=limit))
    near = int(np.argmin(free.margin))
    assert res.failure[near] == "boundary" and "from the edge of the workspace" in res.reason[near]
    assert res.failure[1 - near] is None and res.best_index == 1 - near
    with pytest.raises(InvalidInput, match="min_margin"):
        LayoutRequest(scara, pick, place, cand, min_margin=-1.0)


def test_a_search_where_every_candidate_fails_is_a_status_with_the_reason(scara, points):
    import json

    pick, place = points
    cand = np.array([[2.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, np.pi], [2.5, 0.0, 0.0, 0.0]])
    request = LayoutRequest(scara, pick, place, cand, lift=0.02, refine=0, workspace_samples=20_000)
    cand[0, 0] = 0.0  # the request holds its own read-only copy
    assert request.candidates[0, 0] == 2.0 and not request.candidates.flags.writeable
    assert request.picks.shape == (1, 3)
    res = search_layout(request)
    assert res.status is LayoutStatus.NO_PLACEMENT and res.best_placement is None and res.best_index == -1
    assert res.status_reason == ("every one of the 3 candidates failed (2 unreachable, 1 joint limit): "
                                 "move the candidates nearer the points or relax the cycle")
    d = json.loads(json.dumps(res.as_dict()))
    assert d["status"] == "no placement" and d["candidates"][0]["failure"] in ("unreachable", "joint limit")
