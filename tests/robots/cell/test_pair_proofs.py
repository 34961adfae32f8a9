"""A pair is skipped without a check only by a proof, never because a sample found one distance (issue 35).

The pairs ``constant`` (relative placement invariant: robots/pair_proofs.py) and ``out of reach`` by an
``axial gap`` keep a proven bound; coal, called directly on seeded random configurations, never finds them
closer than that bound, and a check at a clearance above the bound looks at them again.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pinarms.optim.motion.scenes import load_scene, scene_names
from pinarms.robots.cell import Cell, load_cell
from pinarms.robots.cell.pairs import AXIAL_GAP, PairReason
from pinarms.robots.collision_requests import cold_start


def _proven(cell) -> list:
    """The pairs skipped by a proof of invariance or of an axial gap."""
    return [a for a in cell.allowed if a.reason == PairReason.CONSTANT or a.note == AXIAL_GAP]


def _distances(cell, pairs, samples: int, seed: int) -> np.ndarray:
    """``(samples, P)`` coal distances [m] of ``pairs`` at seeded random configurations (plain Pinocchio + coal)."""
    gm = cell.collision_model.copy()
    gm.removeAllCollisionPairs()
    for a in pairs:
        gm.addCollisionPair(pin.CollisionPair(a.index_a, a.index_b))
    gd = cold_start(pin.GeometryData(gm), distance_tolerance=1e-12)
    data = cell.model.createData()
    out = np.empty((samples, len(pairs)))
    for i, q in enumerate(cell.robot.q_to_pinocchio(cell.random_q(samples, seed=seed))):
        pin.updateGeometryPlacements(cell.model, data, gm, gd, q)
        pin.computeDistances(gm, gd)
        out[i] = [r.min_distance for r in gd.distanceResults]
    return out


def _check_bounds(cell) -> list:
    proven = _proven(cell)
    if not proven:
        return proven
    bounds = np.array([a.distance_bound for a in proven])
    assert np.all(np.isfinite(bounds)) and np.all(bounds > 0.0)
    d = _distances(cell, proven, 500, seed=35)
    worst = int(np.argmin(d.min(axis=0) - bounds))
    assert np.all(d >= bounds - 1e-9), (proven[worst], d[:, worst].min())
    constant = np.array([a.reason == PairReason.CONSTANT for a in proven])
    # proven constant: one distance in every configuration (the bound is it, less 1e-9 m)
    np.testing.assert_allclose(d[:, constant], np.broadcast_to(bounds[constant], d[:, constant].shape), atol=1e-8)
    # brought back at a clearance above the bound, left out below it
    for a in proven:
        key = {a.index_a, a.index_b}
        assert any({p.index_a, p.index_b} == key for p in cell.pairs_for(a.distance_bound))
        assert not any({p.index_a, p.index_b} == key for p in cell.pairs_for(a.distance_bound * 0.999))
    return proven


def _reasons(cell) -> dict:
    return {(a.geometry_a, a.geometry_b): (str(a.reason), a.note, round(a.distance_bound * 1e3, 3)) for a in cell.allowed}


def test_the_shipped_cells_skip_a_pair_only_with_a_bound_coal_confirms():
    line, station = load_cell("mushroom_line"), load_cell("aubo_food_station")
    _check_bounds(line)
    _check_bounds(station)
    got = _reasons(line)
    for side in ("left", "right"):  # the upper arm turns about joint 1 above its pedestal: 240 mm along the axis
        assert got[(f"{side}_upper_arm_link_0", f"{side}_pedestal_0")] == ("out of reach", AXIAL_GAP, 240.0)
        # the quill slides (prismatic): no proof, checked although 200 samples find one distance
        assert (f"{side}_quill_link_0", f"{side}_j2_drive_0") not in got
        assert any({p.geometry_a, p.geometry_b} == {f"{side}_quill_link_0", f"{side}_j2_drive_0"} for p in line.pairs)
    got = _reasons(station)
    assert got[("aubo_base_link_0", "aubo_upperArm_Link_1")] == ("constant", "", 3.0)
    assert got[("aubo_upperArm_Link_2", "aubo_wrist1_Link_0")] == ("constant", "", 164.5)
    assert got[("aubo_wrist1_Link_1", "aubo_wrist3_Link_0")] == ("constant", "", 32.0)
    assert got[("aubo_shoulder_Link_0", "stand_0")] == ("out of reach", AXIAL_GAP, 97.0)
    assert got[("aubo_upperArm_Link_1", "stand_0")] == ("out of reach", AXIAL_GAP, 99.0)
    assert got[("aubo_wrist1_Link_1", "aubo_wrist3_Link_1")] == ("out of reach", AXIAL_GAP, 52.0)
    # a margin above the 3 mm constant gap of the base and the upper arm's housing reports it
    q = station.random_q(1, seed=1)[0]
    assert station.clearance(q).distance <= 0.003
    hit = station.collisions(q, margin=0.004)
    assert any({p.geometry_a, p.geometry_b} == {"aubo_base_link_0", "aubo_upperArm_Link_1"} for p in hit.pairs_at(0))


@pytest.mark.slow
@pytest.mark.parametrize("name", scene_names())
def test_the_planning_scenes_skip_a_pair_only_with_a_bound_coal_confirms(name):
    _check_bounds(load_scene(name))


def _slide_text(rail_top: float) -> str:
    """A slider (cylinder r 50 mm, 0.2 m long) on a prismatic joint of stroke ±1 m beside a rail (r 50 mm) 0.2 m away,
    from z = -1.0 m up to ``rail_top``: their distance is 0.1 m while the slider faces the rail, more past its top."""
    half, centre = (rail_top + 1.0) / 2.0, (rail_top - 1.0) / 2.0
    inertia = '<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'
    return f'''<robot name="slide"><link name="world"/>
<joint name="mount" type="fixed"><parent link="world"/><child link="base"/></joint>
<link name="base"><collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision></link>
<joint name="slide" type="prismatic"><parent link="base"/><child link="slider"/><axis xyz="0 0 1"/>
<limit lower="-1.0" upper="1.0" effort="1" velocity="1"/></joint>
<link name="slider">{inertia}<collision><geometry><cylinder radius="0.05" length="0.2"/></geometry></collision></link>
<joint name="rail_mount" type="fixed"><parent link="world"/><child link="rail"/><origin xyz="0.2 0 {centre}"/></joint>
<link name="rail"><collision><geometry><cylinder radius="0.05" length="{2 * half}"/></geometry></collision></link>
</robot>'''


def test_a_pair_at_one_distance_in_every_sample_but_not_in_every_configuration_is_checked():
    """Past z = 0.995 m (the last 0.25 % of the stroke) the slider leaves the rail's side: the 200 seeded samples of
    the classification (largest z 0.9944 m) see one distance, the pair is still checked, and a check finds the change."""
    cell = Cell(_slide_text(0.895), source="test:slide", base_dir=Path(__file__).parent)
    (pair,) = cell.pairs
    assert pair.bodies == ("slider", "rail")
    assert not any({a.body_a, a.body_b} == {"slider", "rail"} for a in cell.allowed)
    sampled = _distances(cell, [pair], 200, seed=0)
    assert np.ptp(sampled) < 1e-9  # what the samples show: one distance
    top = np.array([1.0])
    assert cell.clearance(top).distance == pytest.approx(np.hypot(0.1, 0.005), abs=1e-7)
    assert cell.clearance(np.array([0.0])).distance == pytest.approx(0.1, abs=1e-7)
    assert cell.in_collision(np.array([0.0]), margin=0.1001) and not cell.in_collision(top, margin=0.1001)


def test_a_motion_check_leaves_out_a_constant_pair_only_while_it_keeps_its_margin():
    from pinarms.robots.cell.cover import motion_pairs

    station = load_cell("aubo_food_station")
    (arm,) = (a.name for a in station.arms)
    key = {"aubo_base_link_0", "aubo_upperArm_Link_1"}  # 3 mm apart in every configuration
    assert any({p.geometry_a, p.geometry_b} == key for p in station.pairs_for(0.05))
    kept = motion_pairs(station, 0.05, {arm}, 0.0, 0.01)
    assert not any({p.geometry_a, p.geometry_b} == key for p in kept)
    assert any({p.geometry_a, p.geometry_b} == key for p in motion_pairs(station, 0.05, {arm}, 0.004, 0.01))
