"""Cells as data: arms at their bases, fixtures, collisions and clearance (Pinocchio + coal)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinarms import robots
from pinarms.robots.cell import cell_names, load_cell, stale_cells
from pinarms.robots.collision_requests import cold_start
from pinarms.robots.self_collision import SelfCollision
from pinarms.errors import (
    CellError,
    CellNotFound,
    CollisionGeometryError,
    InvalidInput,
    MissingMesh,
    XacroArgError,
    XacroError,
)

DOWN = np.diag([1.0, -1.0, -1.0])  # tool z pointing down (world)


def pose(p, R=DOWN):
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


@pytest.fixture(scope="module")
def line():
    return load_cell("mushroom_line")


@pytest.fixture(scope="module")
def station():
    return load_cell("aubo_food_station")


def arm_q(cell, arm, point):
    a = cell.arm(arm)
    return a.robot.ik(a.to_base(np.asarray(point, dtype=float)), position_only=True)


# ------------------------------------------------------------------ the model
def test_built_in_cells_and_their_committed_urdfs_are_fresh():
    assert cell_names() == ["aubo_food_station", "mushroom_line"]
    assert stale_cells() == [], "regenerate with `pinarms urdf build`"


def test_mushroom_line_has_two_scaras_at_their_bases(line):
    assert [a.name for a in line.arms] == ["left", "right"]
    assert line.nq == 8
    assert line.joint_names == tuple(f"{s}_j{k}" for s in ("left", "right") for k in range(1, 5))
    for arm, y in zip(line.arms, (0.36, -0.36)):
        assert arm.model == "scara_mushroom" and arm.robot.has_analytic_ik
        assert arm.robot.joint_names == ("j1", "j2", "j3", "j4")
        np.testing.assert_allclose(arm.base_to_world[:3, 3], [0.0, y, 0.78], atol=1e-12)
        assert line.joint_names[arm.q_slice] == tuple(arm.prefix + j for j in arm.robot.joint_names)
    names = [f.name for f in line.fixtures]
    for expected in ("conveyor_belt", "left_box_wall_xpos", "right_table", "conveyor_leg_1"):
        assert expected in names
    kinds = {s.kind for f in line.fixtures for s in f.shapes}
    assert kinds == {"box", "cylinder"}


def test_aubo_station_has_a_mesh_fixture_and_the_table_in_the_recommended_band(station):
    (arm,) = station.arms
    assert arm.name == "aubo" and arm.model == "aubo_i3"
    hopper = station.fixture("hopper")
    assert hopper.shapes[0].kind == "mesh" and hopper.shapes[0].mesh.endswith("hopper.stl")
    # the pick on the food table and the place in the crate: z > 0 and 0.2 < r < 0.5 m from
    # the workspace centre (0, 0, 0.16) m of the base frame (seed 001's recommended band)
    for point in ((0.36, 0.0, 0.75), (0.0, -0.42, 0.77)):
        local = arm.to_base(np.array(point)) - np.array([0.0, 0.0, 0.16])
        assert arm.to_base(np.array(point))[2] > 0.0
        assert 0.2 < np.linalg.norm(local) < 0.5


def test_each_arm_of_the_cell_is_its_robot_moved_to_the_base(line):
    q = line.random_q(20, seed=3)
    for arm in line.arms:
        expected = arm.tcp_to_world(q[:, arm.q_slice])
        np.testing.assert_allclose(line.world_pose(q, arm.prefix + "tcp"), expected, atol=1e-12)
    single = robots.load("scara_mushroom")
    np.testing.assert_allclose(line.arms[0].robot.fk(q[:, :4]), single.fk(q[:, :4]), atol=1e-12)


def test_q_from_arms_and_back(line):
    q = line.q_from_arms({"right": [0.1, 0.2, 0.03, 0.4]})
    np.testing.assert_allclose(q, [0, 0, 0, 0, 0.1, 0.2, 0.03, 0.4])
    np.testing.assert_allclose(line.arm_q(q, "right"), [0.1, 0.2, 0.03, 0.4])
    with pytest.raises(InvalidInput, match="arms: left, right"):
        line.arm("middle")


def test_batched_geometry_placements_match_pinocchio(line):
    q = line.random_q(30, seed=8)
    R, p = line.geometry_placements(q)
    gd = pin.GeometryData(line.collision_model)
    data = line.model.createData()
    for i in range(q.shape[0]):
        pin.updateGeometryPlacements(line.model, data, line.collision_model, gd, line.robot.q_to_pinocchio(q[i]))
        for k, M in enumerate(gd.oMg):
            np.testing.assert_allclose(R[i, k], M.rotation, atol=1e-12)
            np.testing.assert_allclose(p[i, k], M.translation, atol=1e-12)


# ------------------------------------------------------------------ pairs
def test_every_pair_is_checked_or_allowed_with_a_reason(line):
    G = len(line.collision_model.geometryObjects)
    assert len(line.pairs) + len(line.allowed) == G * (G - 1) // 2
    assert len(line.collision_model.collisionPairs) == len(line.pairs)
    reasons = {a.reason for a in line.allowed}
    assert reasons <= {"same link", "rigid", "coaxial", "adjacent", "declared", "out of reach", "constant"}
    allowed = {(a.body_a, a.body_b): a.reason for a in line.allowed}
    assert allowed[("left_base_link", "left_upper_arm_link")] == "adjacent"
    assert allowed.get(("conveyor_belt", "left_pedestal"), allowed.get(("left_pedestal", "conveyor_belt"))) == "rigid"
    checked = {p.bodies for p in line.pairs}
    assert ("left_hand_link", "left_box_wall_xpos") in checked
    assert ("left_hand_link", "right_hand_link") in checked
    assert {p.kind for p in line.pairs} == {"arm-fixture", "arm-arm", "self"}
    # no pair of two bodies fixed to the world is ever checked
    static = {g.name for g in line.collision_model.geometryObjects if g.parentJoint == 0}
    assert not any(p.geometry_a in static and p.geometry_b in static for p in line.pairs)


def test_out_of_reach_pairs_are_really_out_of_reach(line):
    """The bound behind "out of reach": no random configuration brings such a pair closer than 0."""
    reach = [a for a in line.allowed if a.reason == "out of reach"]
    assert len(reach) > 50
    names = [g.name for g in line.collision_model.geometryObjects]
    probe = pin.GeometryModel()
    for g in line.collision_model.geometryObjects:
        probe.addGeometryObject(g)
    for a in reach:
        probe.addCollisionPair(pin.CollisionPair(names.index(a.geometry_a), names.index(a.geometry_b)))
    gd = pin.GeometryData(probe)
    data = line.model.createData()
    for q in line.robot.q_to_pinocchio(line.random_q(300, seed=11)):
        pin.updateGeometryPlacements(line.model, data, probe, gd, q)
        pin.computeDistances(probe, gd)
        assert min(r.min_distance for r in gd.distanceResults) > 0.0


# ------------------------------------------------------------------ collisions
def test_a_gripper_in_the_crate_wall_is_reported_with_the_right_pair(station):
    (arm,) = station.arms
    # tcp 5 mm inside the crate's +x wall (the wall spans x = 0.14 ... 0.15 m)
    q = arm.robot.ik(arm.to_base(pose((0.135, -0.42, 0.80))), q_seed=np.array([-1.0, -0.35, 1.67, -0.45, 1.57, -0.6]))
    assert station.in_collision(q)
    assert station.collisions(q).bodies_at() == [("aubo_wrist3_Link", "crate_wall_xpos")]
    cl = station.clearance(q)
    assert cl.pair_of().bodies == ("aubo_wrist3_Link", "crate_wall_xpos")
    assert -0.03 < cl.distance < 0.0  # the 0.05 m gripper overlaps the wall by 0.02 m
    # 3 cm above the rim it is free
    q_up = arm.robot.ik(arm.to_base(pose((0.135, -0.42, 0.89))), q_seed=q)
    assert not station.in_collision(q_up)
    assert station.clearance(q_up).distance > 0.0


def test_two_arms_swapped_into_each_others_zone_collide(line):
    own_l, own_r = (-0.05, 0.08, 0.84), (-0.05, -0.08, 0.84)
    q_own = line.q_from_arms({"left": arm_q(line, "left", own_l), "right": arm_q(line, "right", own_r)})
    assert not line.in_collision(q_own)
    q_swap = line.q_from_arms({"left": arm_q(line, "left", own_r), "right": arm_q(line, "right", own_l)})
    hits = line.collisions(q_swap)
    assert hits.colliding[0] and bool(hits)
    assert all(p.kind == "arm-arm" for p in hits.pairs_at())
    assert line.clearance(q_swap).distance < 0.0


def test_batched_single_and_plain_pinocchio_loops_agree(line):
    q = line.random_q(400, seed=5)
    gm = line.collision_model
    for margin in (0.0, 0.02):
        gd = cold_start(pin.GeometryData(gm))
        for req in gd.collisionRequests:
            req.security_margin = margin
        data = line.model.createData()
        plain = []
        for qp in line.robot.q_to_pinocchio(q):
            pin.updateGeometryPlacements(line.model, data, gm, gd, qp)
            plain.append(pin.computeCollisions(gm, gd, True))
        plain = np.array(plain)
        assert 0.02 < plain.mean() < 0.98  # the sample holds both verdicts
        np.testing.assert_array_equal(line.in_collision(q, margin=margin), plain)
        np.testing.assert_array_equal([line.in_collision(x, margin=margin) for x in q], plain)
    hits = line.collisions(q[:60])
    gd = cold_start(pin.GeometryData(gm))
    data = line.model.createData()
    for i, qp in enumerate(line.robot.q_to_pinocchio(q[:60])):
        pin.updateGeometryPlacements(line.model, data, gm, gd, qp)
        pin.computeCollisions(gm, gd, False)
        assert hits.touching[i] == tuple(k for k, r in enumerate(gd.collisionResults) if r.isCollision())


def test_checks_match_a_fresh_geometry_data_per_configuration(station):
    """The ground truth: coal from scratch for every configuration (no warm-started GJK)."""
    q = station.random_q(600, seed=9)
    gm = station.collision_model
    data = station.model.createData()
    truth = []
    for qp in station.robot.q_to_pinocchio(q):
        gd = pin.GeometryData(gm)
        pin.updateGeometryPlacements(station.model, data, gm, gd, qp)
        truth.append(pin.computeCollisions(gm, gd, True))
    truth = np.array(truth)
    assert 0.1 < truth.mean() < 0.9
    np.testing.assert_array_equal(station.in_collision(q), truth)
    np.testing.assert_array_equal([station.in_collision(x) for x in q], truth)
    arm = robots.load("aubo_i3")
    sc = SelfCollision(arm)
    qa = arm.random_q(600, seed=9)
    truth = []
    for qp in arm.q_to_pinocchio(qa):
        gd = pin.GeometryData(sc._gm)
        pin.updateGeometryPlacements(arm.model, arm.model.createData(), sc._gm, gd, qp)
        truth.append(pin.computeCollisions(sc._gm, gd, True))
    np.testing.assert_array_equal(sc.in_collision(qa), truth)
    np.testing.assert_array_equal([sc.in_collision(x) for x in qa], truth)


def test_clearance_is_the_exact_minimum_over_the_pairs_not_allowed_by_design(line, station):
    """The checked pairs and the proven-apart ones (out of reach, constant: the AUBO's base and upper-arm housing
    stay 3 mm apart, so the station's clearance is never above 3 mm)."""
    for cell in (line, station):
        q = cell.random_q(80, seed=2)
        cl = cell.clearance(q)
        gm = cell.collision_model.copy()
        gm.removeAllCollisionPairs()
        for p in cell.pairs_for(float("inf")):
            gm.addCollisionPair(pin.CollisionPair(p.index_a, p.index_b))
        gd = cold_start(pin.GeometryData(gm), distance_tolerance=1e-10)
        data = cell.model.createData()
        for i, qp in enumerate(cell.robot.q_to_pinocchio(q)):
            pin.updateGeometryPlacements(cell.model, data, gm, gd, qp)
            pin.computeDistances(gm, gd)
            d = np.array([r.min_distance for r in gd.distanceResults])
            tol = 1e-9 if d.min() > 0 else 1e-6  # a penetration depth is EPA's estimate (1e-6 m)
            assert cl.distance[i] == pytest.approx(d.min(), abs=tol)
            assert d[cl.pair[i]] == pytest.approx(d.min(), abs=tol)
        assert cl.ok.dtype == bool and cl.ok.shape == (80,)


def test_clearance_agrees_with_pybullet_on_the_same_primitives(line):
    """coal's distance against PyBullet's getClosestPoints, pair by pair, at random configurations.

    Boxes (and spheres) agree within 1e-6 m. Bullet's GJK stops early on curved shapes:
    against a closed form (sphere–cylinder) coal is exact to 1e-12 m while Bullet is off by
    up to a few 1e-6 m, so pairs with a cylinder are compared within 2e-5 m.
    """
    import pybullet as pb

    client = pb.connect(pb.DIRECT)
    try:
        gm = line.collision_model
        gd = pin.GeometryData(gm)
        for req in gd.distanceRequests:
            req.gjk_tolerance = 1e-12
        data = line.model.createData()
        shapes = {}
        for k, g in enumerate(gm.geometryObjects):
            kind, size = _primitive(g.geometry)
            if kind == "box":
                shapes[k] = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[s / 2 for s in size], physicsClientId=client)
            else:
                shapes[k] = pb.createCollisionShape(pb.GEOM_CYLINDER, radius=size[0], height=size[1], physicsClientId=client)
        bodies = {k: pb.createMultiBody(0, s, physicsClientId=client) for k, s in shapes.items()}
        for b in bodies.values():
            pb.changeDynamics(b, -1, collisionMargin=0.0, physicsClientId=client)
        compared = {"box": 0, "cylinder": 0}
        for qp in line.robot.q_to_pinocchio(line.random_q(25, seed=21)):
            pin.updateGeometryPlacements(line.model, data, gm, gd, qp)
            pin.computeDistances(gm, gd)
            for k, b in bodies.items():
                M = gd.oMg[k]
                quat = pin.Quaternion(M.rotation)
                pb.resetBasePositionAndOrientation(b, M.translation.tolist(), [quat.x, quat.y, quat.z, quat.w],
                                                   physicsClientId=client)
            for pair, res in zip(gm.collisionPairs, gd.distanceResults):
                d = res.min_distance
                if d <= 1e-4:
                    continue  # penetration depths are estimated differently by the two engines
                points = pb.getClosestPoints(bodies[pair.first], bodies[pair.second], 10.0, physicsClientId=client)
                d_bullet = min(p[8] for p in points)
                curved = "cylinder" in (_primitive(gm.geometryObjects[pair.first].geometry)[0],
                                        _primitive(gm.geometryObjects[pair.second].geometry)[0])
                assert d_bullet == pytest.approx(d, abs=2e-5 if curved else 1e-6)
                compared["cylinder" if curved else "box"] += 1
        assert compared["box"] > 500 and compared["cylinder"] > 100
    finally:
        pb.disconnect(client)


def test_coal_is_exact_against_a_closed_form_sphere_cylinder_distance():
    import coal

    rng = np.random.default_rng(4)
    req = coal.DistanceRequest()
    req.gjk_tolerance = 1e-12
    for _ in range(200):
        rs, r, half = rng.uniform(0.01, 0.1), rng.uniform(0.02, 0.1), rng.uniform(0.03, 0.2)
        R = pin.rpy.rpyToMatrix(*rng.uniform(-3, 3, 3))
        t, c = rng.uniform(-0.3, 0.3, 3), rng.uniform(-0.3, 0.3, 3) + np.array([0.6, 0.0, 0.0])
        local = R.T @ (c - t)
        exact = np.hypot(max(np.hypot(local[0], local[1]) - r, 0.0), max(abs(local[2]) - half, 0.0)) - rs
        d = coal.distance(coal.Sphere(rs), coal.Transform3s(np.eye(3), c), coal.Cylinder(r, 2 * half),
                          coal.Transform3s(R, t), req, coal.DistanceResult())
        assert d == pytest.approx(exact, abs=1e-12)


def _primitive(geometry):
    import coal

    if isinstance(geometry, coal.Box):
        return "box", tuple(2 * np.asarray(geometry.halfSide))
    assert isinstance(geometry, coal.Cylinder), type(geometry)
    return "cylinder", (geometry.radius, 2 * geometry.halfLength)


# ------------------------------------------------------------------ bad files
CELL_HEAD = '<?xml version="1.0"?>\n<robot name="bad_cell" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
ARM = """
  <xacro:include filename="$(find pinarms)/scara_mushroom.xacro"/>
  <xacro:include filename="$(find pinarms)/fixtures.xacro"/>
  <xacro:pinarms_materials/>
  <link name="world"/>
  <xacro:scara_mushroom prefix="a_" parent="world" xyz="0 0 0.8"/>
"""


@pytest.mark.parametrize(
    "body, error, needle",
    [
        ('<xacro:scara_arm prefix="b_" parent="world"/>', XacroError, "unknown macro name: xacro:scara_arm"),
        ('<xacro:scara_mushroom prefix="a_" parent="world" xyz="1 0 0.8"/>', CellError, "duplicate link name 'a_base_link'"),
        ('<xacro:fixture_box name="a_base_link" parent="world" size="0.1 0.1 0.1"/>', CellError, "duplicate link name"),
        ('<xacro:fixture_mesh name="tray" parent="world" filename="meshes/tray.stl"/>', MissingMesh, "tray.stl"),
        ('<link name="empty"><collision><geometry/></collision></link><joint name="e" type="fixed">'
         '<parent link="world"/><child link="empty"/></joint>', CollisionGeometryError, "empty"),
        ('<link name="loose"/>', CellError, "one root link"),
    ],
)
def test_bad_cell_files_give_named_errors(tmp_path, body, error, needle):
    path = tmp_path / "bad_cell.urdf.xacro"
    path.write_text(CELL_HEAD + ARM + body + "\n</robot>\n")
    with pytest.raises(error, match=needle):
        load_cell(path)


def test_cell_arguments_are_checked(tmp_path):
    with pytest.raises(XacroArgError, match="'belt_top'.*must be a number"):
        load_cell("mushroom_line", belt_top="high")
    with pytest.raises(XacroArgError, match="unknown xacro argument.*belt_speed"):
        load_cell("mushroom_line", belt_speed=1.0)
    with pytest.raises(CellNotFound, match="aubo_food_station, mushroom_line"):
        load_cell("packing_hall")
    lower = load_cell("mushroom_line", belt_top=0.70)
    assert lower.args == {"belt_top": "0.7", "arm_gap": "0.72"}
    np.testing.assert_allclose(lower.arms[0].base_to_world[:3, 3], [0.0, 0.36, 0.68], atol=1e-12)


def test_a_cell_without_arms_is_refused(tmp_path):
    path = tmp_path / "empty.urdf"
    path.write_text('<robot name="e"><link name="world"/><link name="t"><collision><geometry><box size="1 1 1"/>'
                    '</geometry></collision></link><joint name="j" type="fixed"><parent link="world"/>'
                    '<child link="t"/></joint></robot>')
    with pytest.raises(CellError, match="no arm"):
        load_cell(path)
