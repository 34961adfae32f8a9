"""Pick-and-place cycles that keep their clearance in a cell, and two arms scheduled on one belt."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import optim
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.robots.cell.motion import configurations
from pinarms.errors import CollisionError, InvalidInput

LINE_TASKS = {"left": ((-0.05, -0.03, 0.84), (0.22, 0.68, 0.84)), "right": ((0.05, 0.03, 0.84), (0.22, -0.68, 0.84))}


@pytest.fixture(scope="module")
def station():
    return load_cell("aubo_food_station")


@pytest.fixture(scope="module")
def line():
    return load_cell("mushroom_line")


def crate_spec(arm, lift=0.05):
    """Pick on the food table, place into the crate (world points, tool down)."""
    return optim.PickPlace(pick=arm.to_base(np.array([0.36, 0.0, 0.75])),
                           place=arm.to_base(np.array([0.0, -0.42, 0.77])), lift=lift, dwell=0.2)


@pytest.fixture(scope="module")
def station_cycles(station):
    arm = station.arm("aubo")
    spec = crate_spec(arm)
    free = optim.plan_cycle(optim.CycleRequest(arm.robot, spec))
    return spec, free, optim.plan_cycle(optim.CycleRequest(arm.robot, spec, cell=optim.CellSettings(station, clearance=0.02)))


def test_a_cycle_through_the_crate_wall_is_replanned_to_clear_it(station, station_cycles):
    spec, free, kept = station_cycles
    external = station.with_pairs("external")
    # planned without the cell, the transfer sweeps the gripper through the crate wall
    before = external.check_motion([ArmMotion("aubo", free.trajectory)], margin=0.005, clearance=0.02)
    assert not before.clear
    assert before.first_contact is not None and before.first_contact.pair.body_b.startswith("crate_wall")
    report = kept.cell_report
    assert report.attempts[0][1] is False and "crate_wall" in report.attempts[0][3]
    assert report.attempts[-1][1] is True
    assert report.lift > spec.lift
    assert kept.status is optim.CycleStatus.REPLANNED and free.status is optim.CycleStatus.OK
    assert kept.as_dict()["status"] == "re-planned"
    assert report.extra_time == pytest.approx(kept.cycle_time - free.cycle_time, abs=1e-12) and report.extra_time > 0
    assert report.min_clearance >= 0.02 and report.lower_bound >= 0.02
    # an independent dense look at the kept cycle: every external distance >= 20 mm
    t = np.arange(0.0, kept.trajectory.duration, 5e-4)
    Q = configurations(station, [ArmMotion("aubo", kept.trajectory)], t, station.neutral)
    assert external.clearance(Q).distance.min() >= 0.02
    assert not station.with_pairs("self").in_collision(Q).any()
    assert kept.as_dict()["cell"]["lift_m"] == pytest.approx(report.lift)


def test_a_place_too_close_to_a_wall_is_an_in_collision_status(station):
    arm = station.arm("aubo")
    spec = optim.PickPlace(pick=arm.to_base(np.array([0.36, 0.0, 0.75])),
                           place=arm.to_base(np.array([0.12, -0.42, 0.77])), lift=0.05, dwell=0.2)
    res = optim.plan_cycle(optim.CycleRequest(arm.robot, spec, cell=optim.CellSettings(station, clearance=0.02)))
    assert res.status is optim.CycleStatus.IN_COLLISION and res.cell_report is None
    with pytest.raises(CollisionError, match=r"place pose of arm 'aubo' is .* mm from crate_wall_xpos"):
        res.raise_for_status()


@pytest.mark.slow
def test_a_transfer_no_lift_can_clear_names_what_blocks(tmp_path):
    path = tmp_path / "walled.urdf.xacro"
    path.write_text("""<?xml version="1.0"?>
<robot name="walled" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find pinarms)/aubo_i3.xacro"/>
  <xacro:include filename="$(find pinarms)/fixtures.xacro"/>
  <xacro:pinarms_materials/>
  <link name="world"/>
  <xacro:aubo_i3 prefix="aubo_" parent="world" xyz="0 0 0.7"/>
  <xacro:fixture_box name="tall_wall" parent="world" size="0.65 0.02 2.4" xyz="0.41 -0.41 1.2" rpy="0 0 -0.785398"/>
</robot>
""")
    cell = load_cell(path)
    arm = cell.arm("aubo")
    spec = optim.PickPlace(pick=arm.to_base(np.array([0.40, 0.0, 0.78])),
                           place=arm.to_base(np.array([0.0, -0.40, 0.78])), lift=0.05, dwell=0.2)
    blocked = optim.CellSettings(cell, clearance=0.02, lift_step=0.15, plan_transfer=False)
    res = optim.plan_cycle(optim.CycleRequest(arm.robot, spec, cell=blocked))
    assert res.status is optim.CycleStatus.IN_COLLISION and "tall_wall blocks" in res.reason
    # the transfer planned round the wall's end (optim.motion) clears it
    around = optim.plan_cycle(optim.CycleRequest(arm.robot, spec, timing=optim.CycleTiming(amax=10.0),
                                                 cell=optim.CellSettings(cell, clearance=0.02, lift_step=0.15)))
    assert around.cell_report.planned_transfer and around.cell_report.min_clearance >= 0.02


def test_the_robot_must_be_an_arm_of_the_cell(station, line):
    with pytest.raises(InvalidInput, match="not an arm of cell"):
        optim.plan_cycle(optim.CycleRequest(line.arm("left").robot, crate_spec(station.arm("aubo")),
                                            cell=optim.CellSettings(station)))


@pytest.fixture(scope="module")
def line_schedule(line):
    cycles = {}
    for name, (pick, place) in LINE_TASKS.items():
        arm = line.arm(name)
        spec = optim.PickPlace(pick=arm.to_base(np.array(pick)), place=arm.to_base(np.array(place)), lift=0.09,
                               dwell=0.15)
        cycles[name] = optim.plan_cycle(optim.CycleRequest(arm.robot, spec,
                                                           cell=optim.CellSettings(line, clearance=0.02)))
    return cycles, optim.schedule_line(line, cycles, margin=0.01)


@pytest.mark.slow
def test_two_arm_schedule_never_collides_checked_densely(line, line_schedule):
    cycles, schedule = line_schedule
    assert schedule.offsets["left"] == 0.0
    assert schedule.check.collision_free
    motions = [ArmMotion(n, cycles[n].trajectory, schedule.offsets[n], schedule.period) for n in schedule.arms]
    t = np.arange(0.0, schedule.period, 1e-3)
    d = line.clearance(configurations(line, motions, t, line.neutral)).distance
    assert d.min() > 0.0
    # some offsets do collide: picking at once over the belt crosses the arms
    assert (~schedule.clear).any() and schedule.clear.any()
    blocked = schedule.scanned[~schedule.clear][0]
    motions[1] = ArmMotion("right", cycles["right"].trajectory, float(blocked), schedule.period)
    d_blocked = line.clearance(configurations(line, motions, t, line.neutral)).distance
    assert d_blocked.min() < 0.0


def test_line_rate_against_one_arm_alone(line_schedule):
    cycles, schedule = line_schedule
    assert schedule.period == pytest.approx(max(c.cycle_time for c in cycles.values()))
    assert schedule.picks_per_minute == pytest.approx(2 * 60.0 / schedule.period)
    for name, cycle in cycles.items():
        assert schedule.single_arm_picks_per_minute[name] == pytest.approx(cycle.picks_per_minute)
        assert schedule.picks_per_minute > 1.8 * schedule.single_arm_picks_per_minute[name]
        assert schedule.busy[name], name  # every arm spends time in the shared zone
    data = schedule.as_dict()
    assert data["collision_free"] is True and len(data["offsets_scanned_s"]) == 24
