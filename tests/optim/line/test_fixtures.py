"""The maps' clearance to the cell's fixtures: a block on part of the belt makes exactly the nodes
whose planned pick enters it infeasible, and a simulation never picks there.

Independent route: the coal distance between the arm's geometry and the block at FK of the planned
joint trajectory sampled every 2 ms (points move at most a few mm in 2 ms: nodes whose sampled
distance lies within ``BAND`` of the clearance are not judged)."""

import numpy as np
import pinocchio as pin
import pytest

from pinarms.optim.line import Belt, ItemType, LineSpec, PlaceBox, Station, Stream, TrackingSpec, run_line
from pinarms.optim.line.fixtures import FixtureCheck, chord_polyline
from pinarms.optim.line.map_request import MapRequest
from pinarms.optim.line.task_map_build import build_task_map
from pinarms.optim.line.tracking import plan_pick
from pinarms.robots.cell import load_cell
from pinarms.robots.cell.cell import Cell
from pinarms.errors import InvalidInput

ENOKI = ItemType("enoki bunch", 0.15, (0.12, 0.06, 0.04))
CLEARANCE = 0.01
BAND = 0.004
GRID = dict(mass=0.15, item_height=0.04, nu=6, nw=3, du_range=(-0.2, 0.3), yaw="none")  # the SCARA: test_yaw_maps.py
#: a 10 × 15 × 5 cm block standing on the far half of the belt (w < 0) just downstream of the left arm
BLOCK = """  <link name="block"><collision><origin rpy="0 0 0" xyz="0 0 0"/>
    <geometry><box size="0.10 0.15 0.05"/></geometry></collision></link>
  <joint name="block_joint" type="fixed"><parent link="world"/><child link="block"/>
    <origin rpy="0 0 0" xyz="0.1 -0.075 0.825"/></joint>
</robot>"""


@pytest.fixture(scope="module")
def blocked_line():
    cell = load_cell("mushroom_line")
    with_block = Cell(cell.urdf_text.replace("</robot>", BLOCK), source="mushroom_line with a block",
                      base_dir=cell._base_dir)
    belt = Belt((-1.0, 0.0, 0.80), speed=0.1, width=0.30, length=2.0)
    st = Station("left", cell.arm("left").robot, cell.arm("left").base_to_world, PlaceBox((0.22, 0.68, 0.93), "box"))
    before = build_task_map(MapRequest(st, belt, TrackingSpec(), cell=cell, clearance=CLEARANCE, **GRID)).task_map
    after = build_task_map(MapRequest(st, belt, TrackingSpec(), cell=with_block, clearance=CLEARANCE, **GRID)).task_map
    return with_block, belt, st, before, after


def _block_distance(cell: Cell, trajectory, dt: float = 0.002) -> float:
    """Smallest coal distance [m] between the left arm's geometry and the block over the samples."""
    gm = cell.collision_model.copy()
    gm.removeAllCollisionPairs()
    block = gm.getGeometryId("block_0")
    arm = {p.index_a for p in cell.pairs_for(1.0) if p.owner_a == "left"}
    for g in arm:
        gm.addCollisionPair(pin.CollisionPair(g, block))
    gd, data = pin.GeometryData(gm), cell.model.createData()
    t = np.arange(trajectory.start_time, trajectory.end_time, dt)
    best = np.inf
    for q in np.asarray(trajectory.sample(t)[0]):
        pin.computeDistances(cell.model, data, gm, gd, cell.q_from_arms({"left": q}))
        best = min(best, min(r.min_distance for r in gd.distanceResults))
    return best


@pytest.mark.slow
def test_exactly_the_nodes_whose_pick_enters_the_block_are_infeasible(blocked_line):
    cell, belt, st, before, after = blocked_line
    was, now = np.isfinite(before.branch_approach), np.isfinite(after.branch_approach)
    assert not np.any(now & ~was)  # the block only takes nodes away
    assert after.fixture_infeasible - before.fixture_infeasible == int(np.sum(was & ~now))
    judged = newly = 0
    for b, i, j in zip(*np.nonzero(was)):
        plan = plan_pick(st, belt, TrackingSpec(), 1.0 + before.du[i], before.w[j], item_height=0.04, mass=0.15,
                         branch=None if before.branches[b] < 0 else int(before.branches[b]))
        d = _block_distance(cell, plan.trajectory)
        if CLEARANCE - BAND < d < CLEARANCE + BAND:
            continue
        judged += 1
        newly += d < CLEARANCE
        assert now[b, i, j] == (d >= CLEARANCE), (b, i, j, d)
    assert newly >= 2 and judged - newly >= 4 and judged >= int(was.sum()) - 2


@pytest.mark.slow
def test_the_simulation_never_picks_where_the_block_is(blocked_line):
    cell, belt, st, before, after = blocked_line
    gone = np.isfinite(before.branch_approach) & ~np.isfinite(after.branch_approach)
    gone = gone.any(axis=0)  # (nu, nw): a node lost on some branch
    spec = LineSpec(belt, (st,), Stream("poisson", rate_per_s=40.0 / 60.0, duration=60.0, types=(ENOKI,)), seeds=(0,),
                    map_grid=(6, 3))
    for maps, expect_inside in (({"left": (before,)}, True), ({"left": (after,)}, False)):
        run = run_line(spec, maps=maps).runs[0]
        got = run.picked_by >= 0
        du, w = run.u_meet[got] - 1.0, run.w[got]
        i = np.clip(np.searchsorted(after.du, du, side="right") - 1, 0, after.du.size - 2)
        j = np.clip(np.searchsorted(after.w, w, side="right") - 1, 0, after.w.size - 2)
        touches = gone[i, j] | gone[i + 1, j] | gone[i, j + 1] | gone[i + 1, j + 1]
        assert got.sum() >= 5
        assert bool(touches.any()) == expect_inside  # before: some picks there; after: none


def test_fast_route_agrees_with_the_exact_check_and_bad_clearance_is_named():
    cell = load_cell("mushroom_line")
    belt = Belt((-1.0, 0.0, 0.80), speed=0.1, width=0.30, length=2.0)
    st = Station("left", cell.arm("left").robot, cell.arm("left").base_to_world, PlaceBox((0.22, 0.68, 0.93), "box"))
    plan = plan_pick(st, belt, TrackingSpec(), 1.05, 0.0, item_height=0.04, mass=0.15)
    for clearance in (0.005, 0.02):
        check = FixtureCheck(cell, "left", clearance)
        assert check.clear(plan.trajectory) == bool(check.exact.trajectory_valid(plan.trajectory, 0.0).ok)
    # the polyline stays within the chord: its samples include every knot and lie on the trajectory
    P, t = chord_polyline([plan.trajectory], check._wide.levers, times=True)
    assert np.all(np.isin(plan.trajectory.knot_times, t))
    np.testing.assert_allclose(P, plan.trajectory.sample(t)[0], atol=1e-12)
    with pytest.raises(InvalidInput, match="clearance"):
        FixtureCheck(cell, "left", 0.0)
    with pytest.raises(InvalidInput, match="not an arm of cell"):
        MapRequest(Station("middle", st.robot, st.base_to_world, st.place), belt, cell=cell, **GRID)


@pytest.mark.slow
def test_run_line_with_a_cell_builds_maps_against_it_and_reports_the_count(blocked_line):
    cell, belt, st, before, after = blocked_line
    spec = LineSpec(belt, (st,), Stream("poisson", rate_per_s=20.0 / 60.0, duration=30.0, types=(ENOKI,)), seeds=(0,),
                    map_grid=(6, 3), cell=cell, clearance=CLEARANCE, map_yaw="none")
    result = run_line(spec)
    (m,) = result.maps["left"]
    assert result.fixture_infeasible == {"left": m.fixture_infeasible}
    assert m.fixture_infeasible >= 1  # the block takes nodes of this grid too
    assert result.as_dict()["fixture_infeasible"] == {"left": m.fixture_infeasible}
    assert run_line(LineSpec(belt, (st,), spec.stream, seeds=(0,)), maps=result.maps).fixture_infeasible == {}
