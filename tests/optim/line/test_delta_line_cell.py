"""A delta above the belt in a cell: its task map refuses the picks whose path meets a fixture, proven."""

from dataclasses import replace

import numpy as np
import pytest

from pinarms.errors import InvalidInput
from pinarms.optim.line.delta_maps import build_delta_map
from pinarms.optim.line.map_request import DeltaMapRequest
from pinarms.optim.line.delta_pick_path import delta_pick_path
from pinarms.robots.cell import load_cell
from pinarms.robots.delta import forward_position
from pinarms.studies.delta_line import delta_line
from pinarms.studies.line import ENOKI

CELL = """name = "delta_over_belt"

[[arm]]
name = "delta1"
delta = "delta_flexpicker"
xyz = [1.0, 0.0, 1.9]

[[fixture]]
name = "belt"
box = [3.0, 0.3, 0.05]
xyz = [1.0, 0.0, 0.775]

[[fixture]]
name = "post"
box = [0.04, 0.04, 0.04]
xyz = [{x}, {y}, {z}]
"""


@pytest.fixture(scope="module")
def setting(tmp_path_factory):
    line = delta_line(2, 60.0, item=ENOKI, seeds=(0,), duration=10.0)
    station = replace(line.stations[0], name="delta1")
    kw = dict(mass=ENOKI.mass, item_height=ENOKI.size[2], nu=3, nw=2, n=12)   # the middle row feasible
    plain = build_delta_map(DeltaMapRequest(station, line.belt, line.tracking, **kw)).task_map
    # a small post where the tool passes on the approach to node (1, 0), or far from every path
    u0 = float(line.belt.to_belt(station.base_to_world[:3, 3])[0])
    path = delta_pick_path(station, line.belt, line.tracking, u0 + plain.du[1], plain.w[0], item_height=ENOKI.size[2])
    theta = path.sample(np.array([0.8]))[0][:, :3]
    on_path = forward_position(station.robot.delta.geometry, theta)[0] + station.robot.tcp_offset \
        + station.base_to_world[:3, 3]
    cells, maps = {}, {"none": plain}
    for name, xyz in (("blocked", on_path), ("clear", (1.0, -0.6, 1.0))):
        folder = tmp_path_factory.mktemp(name)
        (folder / "cell.toml").write_text(CELL.format(x=xyz[0], y=xyz[1], z=xyz[2]), encoding="utf-8")
        cells[name] = load_cell(folder / "cell.toml")
        result = build_delta_map(DeltaMapRequest(station, line.belt, line.tracking, cell=cells[name], **kw))
        assert result.blocked == result.task_map.fixture_infeasible
        maps[name] = result.task_map
    return line, station, cells, maps, path


def test_post_on_one_path_blocks_that_pick_only(setting):
    _, _, _, maps, _ = setting
    none, blocked = maps["none"], maps["blocked"]
    assert np.isfinite(none.approach[1, 0]) and np.isnan(blocked.approach[1, 0])
    assert 1 <= blocked.fixture_infeasible < int(np.isfinite(none.approach).sum())
    keep = np.isfinite(blocked.approach)
    assert np.array_equal(blocked.approach[keep], none.approach[keep])


def test_post_off_the_paths_blocks_none_and_changes_no_time(setting):
    _, _, _, maps, _ = setting
    assert maps["clear"].fixture_infeasible == 0
    assert np.array_equal(maps["clear"].approach, maps["none"].approach, equal_nan=True)


def test_pick_path_runs_box_to_belt_to_box_and_meets_the_post(setting):
    line, station, cells, _, path = setting
    theta = path.sample(np.array([0.0, 1.0, 3.0]))[0][:, :3]
    world = forward_position(station.robot.delta.geometry, theta) + station.robot.tcp_offset + station.base_to_world[:3, 3]
    assert np.allclose(world[0], station.place.position) and np.allclose(world[2], station.place.position)
    assert np.isclose(world[1, 2], line.belt.to_world(0, 0, 0)[2] + ENOKI.size[2] + line.tracking.lift)
    check = cells["blocked"].with_pairs("arm-fixture").check_motion({"delta1": path}, margin=0.01, clearance=0.01)
    assert check.first_contact is not None and "post" in check.first_contact.pair.bodies
    assert 0.6 < check.first_contact.time < 0.8


def test_station_must_be_a_delta_of_the_cell(setting):
    line, station, cells, _, _ = setting
    with pytest.raises(InvalidInput, match="not an arm"):
        build_delta_map(DeltaMapRequest(replace(station, name="other"), line.belt, line.tracking, cell=cells["clear"],
                                        nu=2, nw=2))


@pytest.fixture(scope="module")
def two_deltas(tmp_path_factory):
    from pinarms.optim.line import Station
    from pinarms.optim.line.neighbours import NeighbourGuard

    line = delta_line(2, 60.0, item=ENOKI, seeds=(0,), duration=10.0)
    st = [Station(f"delta{k + 1}", s.robot, s.base_to_world, s.place) for k, s in enumerate(line.stations)]
    text = 'name = "two_deltas"\n' + "".join(f'[[arm]]\nname = "{s.name}"\ndelta = "delta_flexpicker"\n'
                                              f'xyz = {[float(v) for v in s.base_to_world[:3, 3]]}\n' for s in st)
    folder = tmp_path_factory.mktemp("two_deltas")
    (folder / "cell.toml").write_text(text, encoding="utf-8")
    cell = load_cell(folder / "cell.toml")
    guard = NeighbourGuard(cell, st, line.belt, line.tracking, (ENOKI,), clearance=0.01, margin=0.05)
    mid = float(line.belt.to_belt((st[0].base_to_world[:3, 3] + st[1].base_to_world[:3, 3]) / 2)[0])
    return cell, guard, mid


def test_neighbour_guard_refuses_two_deltas_at_one_spot_and_passes_them_apart(two_deltas):
    from pinarms.robots.cell import ArmMotion

    cell, guard, mid = two_deltas
    a = ("delta1", 0, 0.0, 2.0, mid, 0.05, 0)
    b = ("delta2", 1, 0.0, 2.0, mid + 0.05, -0.05, 0)
    assert guard(a, b) is False
    apart = ("delta1", 2, 0.0, 2.0, mid - 0.7, 0.0, 0), ("delta2", 3, 0.0, 2.0, mid + 0.7, 0.0, 0)
    assert guard(*apart) is True
    # independently: the two picks on the clock, sampled densely, come closer than the clearance
    pa, pb = guard._plan(a), guard._plan(b)
    motions = [ArmMotion("delta1", pa.trajectory, 2.0 - pa.times[0]), ArmMotion("delta2", pb.trajectory, 2.0 - pb.times[0])]
    t = np.linspace(2.0 - pa.times[0], 2.0 + pa.times[1], 201)
    from pinarms.robots.cell.timeline import configurations

    Q = configurations(cell, motions, t, cell.hold)
    assert cell.with_pairs("arm-arm").clearance(Q).distance.min() < 0.01
