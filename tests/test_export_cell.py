"""Whole cells and arms out: URDF + SRDF load in plain Pinocchio (which then checks exactly the pairs
pinarms checks at contact), the MJCF loads in plain MuJoCo, the SRDF has MoveIt's elements, bad input."""

from __future__ import annotations

import shutil
import xml.etree.ElementTree as ET

import mujoco  # a test dependency (the project's [test] extra): an independent engine
import numpy as np
import pinocchio as pin
import pytest

from pinarms.export import MeshNotFound, contact_pairs, export_cell, export_urdf
from pinarms.robots.cell import Cell, cell_names, load_cell
from pinarms.errors import InvalidInput, MissingMesh

ARMS = ["aubo_i3", "scara_mushroom", "koji_turner", "gantry_flower", "koji_turner_rail"]


def _pinocchio_pairs(urdf, srdf, folder):
    """Link pairs plain Pinocchio checks after reading the SRDF, and its reference configurations."""
    model = pin.buildModelFromUrdf(str(urdf), mimic=True)
    gm = pin.buildGeomFromUrdf(model, str(urdf), pin.COLLISION, package_dirs=[str(folder)])
    gm.addAllCollisionPairs()
    pin.removeCollisionPairs(model, gm, str(srdf), False)
    pin.loadReferenceConfigurations(model, str(srdf), False)
    link = lambda k: model.frames[gm.geometryObjects[k].parentFrame].name  # noqa: E731
    pairs = {frozenset((link(p.first), link(p.second))) for p in gm.collisionPairs}
    return model, pairs


@pytest.fixture(scope="module", params=cell_names())
def exported(request, tmp_path_factory):
    cell = load_cell(request.param)
    return cell, export_cell(cell, tmp_path_factory.mktemp(request.param) / "out")


def test_cell_urdf_and_srdf_in_pinocchio_check_exactly_pinarms_pairs(exported):
    cell, out = exported
    model, got = _pinocchio_pairs(out.urdf, out.srdf, out.folder)
    want = {frozenset((out.geometry_links[p.geometry_a], out.geometry_links[p.geometry_b])) for p in contact_pairs(cell)}
    assert len(want) == len(contact_pairs(cell))  # one link per geometry: no two pairs merge
    assert got == want
    assert model.nq == cell.model.nq
    home = model.referenceConfigurations["home"]
    np.testing.assert_allclose(home, pin.neutral(model) * 0.0 + cell.robot.q_to_pinocchio(np.zeros(cell.nq)), atol=0)


def test_cell_srdf_follows_moveit_format(exported):
    cell, out = exported
    root = ET.parse(out.srdf).getroot()
    assert root.tag == "robot" and root.get("name") == cell.name
    links = {el.get("name") for el in ET.parse(out.urdf).getroot().iter("link")}
    joints = {el.get("name") for el in ET.parse(out.urdf).getroot().iter("joint")}
    for arm in cell.arms:
        chain = root.find(f"group[@name='{arm.name}']/chain")
        assert chain.get("base_link") in links and chain.get("tip_link") == arm.prefix + "tcp"
        ee = root.find(f"end_effector[@name='{arm.name}_tool']")
        assert ee.get("parent_link") == arm.prefix + "tcp" and ee.get("parent_group") == arm.name
        assert root.find(f"group[@name='{ee.get('group')}']/link").get("name") in links
    for state in root.iter("group_state"):
        assert root.find(f"group[@name='{state.get('group')}']") is not None
        assert {j.get("name") for j in state.iter("joint")} <= joints
    reasons = [d.get("reason") for d in root.iter("disable_collisions")]
    assert set(reasons) <= {"Adjacent", "Never", "Default"} and "Never" in reasons
    assert len(reasons) == len(cell.allowed)
    for d in root.iter("disable_collisions"):
        assert d.get("link1") in links and d.get("link2") in links
    comments = [c for c in ET.parse(out.srdf, ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))).getroot()
                if c.tag is ET.Comment and "pinarms:" in c.text]
    assert len(comments) == len(reasons)
    assert sum("out of reach" in c.text for c in comments) == reasons.count("Never")


def test_cell_mjcf_loads_in_mujoco_with_sites_and_named_geoms(exported):
    cell, out = exported
    model = mujoco.MjModel.from_xml_path(str(out.mjcf))
    data = mujoco.MjData(model)
    for arm in cell.arms:
        for joint in arm.robot.joint_names:
            data.qpos[model.jnt_qposadr[model.joint(arm.prefix + joint).id]] = 0.0
    mujoco.mj_kinematics(model, data)
    for arm in cell.arms:
        np.testing.assert_allclose(data.site(arm.prefix + "tcp").xpos, cell.world_pose(cell.neutral, arm.prefix + "tcp")[:3, 3],
                                   atol=1e-9)
    for fixture in cell.fixtures:
        for shape in fixture.shapes:
            if shape.kind == "mesh":  # MuJoCo moves a mesh's frame to its centroid
                continue
            np.testing.assert_allclose(data.geom(shape.geometry).xpos, shape.shape_to_world[:3, 3], atol=1e-9)
    for mesh in out.meshes:
        assert (out.folder / mesh).is_file()
    for el in ET.parse(out.mjcf).getroot().iter("mesh"):
        assert not el.get("file").startswith("/")


def test_cell_folder_moves_and_still_loads(exported, tmp_path):
    cell, out = exported
    moved = tmp_path / "elsewhere"
    shutil.copytree(out.folder, moved)
    reloaded = Cell((moved / out.urdf.name).read_text(), source="moved", base_dir=moved)
    assert reloaded.nq == cell.nq
    assert mujoco.MjModel.from_xml_path(str(moved / out.mjcf.name)).nbody > len(cell.fixtures)


@pytest.mark.parametrize("name", ARMS)
def test_arm_srdf_in_pinocchio_checks_exactly_pinarms_pairs(name, tmp_path):
    out = export_urdf(name, tmp_path / name, srdf=True)
    model, got = _pinocchio_pairs(out.urdf, out.srdf, out.folder)
    cell = Cell(out.urdf.read_text(), source=name, base_dir=out.folder)  # pinarms' own classification of the arm
    want = {frozenset((cell.model.frames[cell.collision_model.geometryObjects[p.index_a].parentFrame].name,
                       cell.model.frames[cell.collision_model.geometryObjects[p.index_b].parentFrame].name))
            for p in contact_pairs(cell)}
    assert got == want and len(got) == len(contact_pairs(cell))
    assert model.referenceConfigurations["home"].shape == (model.nq,)


def test_arm_srdf_states(tmp_path):
    q = np.array([0.1, -0.2, 0.3, 0.0, 0.5, -0.6])
    out = export_urdf("aubo_i3", tmp_path / "a", srdf=True, states={"pick": q})
    model, _ = _pinocchio_pairs(out.urdf, out.srdf, out.folder)
    np.testing.assert_allclose(model.referenceConfigurations["pick"], q, atol=0)
    with pytest.raises(InvalidInput, match="outside its limits"):
        export_urdf("aubo_i3", tmp_path / "b", srdf=True, states={"pick": q * 100})
    assert not (tmp_path / "b").exists()


def test_cell_with_missing_mesh_is_a_named_error(tmp_path):
    folder = tmp_path / "cell"
    folder.mkdir()
    (folder / "meshes").mkdir()
    src = load_cell("aubo_food_station")
    shutil.copy(src.robot.package_dirs[0] + "/meshes/hopper.stl", folder / "meshes" / "hopper.stl")
    (folder / "station.urdf").write_text(src.urdf_text)
    cell = load_cell(str(folder / "station.urdf"))
    (folder / "meshes" / "hopper.stl").unlink()
    with pytest.raises(MeshNotFound, match="hopper.stl") as info:
        export_cell(cell, tmp_path / "out")
    assert isinstance(info.value, MissingMesh)
    assert not (tmp_path / "out").exists()


def test_export_cell_refuses_non_empty_folder(tmp_path):
    (tmp_path / "x").mkdir()
    (tmp_path / "x" / "keep.txt").write_text("mine")
    with pytest.raises(InvalidInput, match="not empty"):
        export_cell("mushroom_line", tmp_path / "x", mjcf=False)
    assert (tmp_path / "x" / "keep.txt").read_text() == "mine"


def test_cell_states_reach_pinocchio(tmp_path):
    cell = load_cell("mushroom_line")
    q_left, q_right = np.array([0.3, -0.4, 0.05, 0.2]), np.array([-0.3, 0.4, 0.1, -0.2])
    out = export_cell(cell, tmp_path / "s", mjcf=False, states={"pick": {"left": q_left},
                                                                 "both": {"left": q_left, "right": q_right}})
    model, _ = _pinocchio_pairs(out.urdf, out.srdf, out.folder)
    pick = model.referenceConfigurations["pick"]
    np.testing.assert_allclose(pick, cell.robot.q_to_pinocchio(cell.q_from_arms({"left": q_left})), atol=0)
    both = model.referenceConfigurations["both"]
    np.testing.assert_allclose(both, cell.robot.q_to_pinocchio(cell.q_from_arms({"left": q_left, "right": q_right})),
                               atol=0)
    root = ET.parse(out.srdf).getroot()
    assert root.find("group_state[@name='both']").get("group") == "cell"
    assert root.find("group_state[@name='left_home']").get("group") == "left"
    with pytest.raises(InvalidInput, match="no arm"):
        export_cell(cell, tmp_path / "t", mjcf=False, states={"pick": {"middle": q_left}})


def test_cli_exports_a_cell(tmp_path):
    import json

    from click.testing import CliRunner

    from pinarms.cli import cli

    run = CliRunner().invoke(cli, ["urdf", "export", "aubo_food_station", str(tmp_path / "c"), "--srdf", "--mjcf",
                                   "--study-poses", "--json"])
    assert run.exit_code == 0, run.output
    doc = json.loads(run.output)
    assert doc["meshes"] == ["meshes/hopper.stl"] and doc["sites"] == ["aubo_flange", "aubo_tcp"]
    assert mujoco.MjModel.from_xml_path(doc["mjcf"]).nsite == 2
    model, pairs = _pinocchio_pairs(doc["urdf"], doc["srdf"], doc["folder"])
    assert len(pairs) == len(contact_pairs(load_cell("aubo_food_station")))
    pick, place = model.referenceConfigurations["pick"], model.referenceConfigurations["place"]
    assert np.abs(pick - place).max() > 0.5  # the demo's pick and place poses, not home
    run = CliRunner().invoke(cli, ["urdf", "export", "aubo_i3", str(tmp_path / "p"), "--study-poses", "--srdf"])
    assert run.exit_code == 2 and "built-in cells" in run.output
    run = CliRunner().invoke(cli, ["urdf", "export", "scara_mushroom", str(tmp_path / "a"), "--srdf"])
    assert run.exit_code == 0 and (tmp_path / "a" / "scara_mushroom.srdf").is_file()


def test_cell_with_a_linkage_keeps_mimic_as_equalities(tmp_path):
    """The koji turner's parallelogram (two <mimic> joints) as a one-arm cell: MuJoCo equalities, tcp site at FK."""
    from pinarms import robots
    from pinarms.export.cell import cell_of_urdf_folder

    robot = robots.load("koji_turner")
    cell = cell_of_urdf_folder(robot, export_urdf(robot, tmp_path / "u").folder)
    out = export_cell(cell, tmp_path / "c")
    model = mujoco.MjModel.from_xml_path(str(out.mjcf))
    assert model.neq == 2
    data = mujoco.MjData(model)
    q = np.array([0.3, 0.4, -0.5, 0.2])
    for name, value in zip(cell.joint_names, q):
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = value
    for k in range(model.neq):
        dep, lead = model.jnt_qposadr[model.eq_obj1id[k]], model.jnt_qposadr[model.eq_obj2id[k]]
        data.qpos[dep] = np.polyval(model.eq_data[k, :5][::-1], data.qpos[lead])
    mujoco.mj_kinematics(model, data)
    np.testing.assert_allclose(data.site("tcp").xpos, cell.world_pose(q, "tcp")[:3, 3], atol=1e-9)
