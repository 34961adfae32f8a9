"""URDF export: every robot's folder loads in PyBullet and yourdfpy with Pinocchio's link poses."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pybullet  # a test dependency (the project's [test] extra): an independent engine
import pytest
import yourdfpy

from pinarms import robots
from pinarms.export import export_urdf, mesh_references
from pinarms.errors import InvalidInput, PinarmsError, RobotNotFound

ALL = robots.names()
N_CONFIGS = 8
TOL_M = 1e-6  # PyBullet computes in double precision; 1 µm leaves room for its float32 paths


def _mimics(urdf_path: Path) -> dict[str, tuple[str, float, float]]:
    root = ET.parse(urdf_path).getroot()
    out = {}
    for j in root.iter("joint"):
        m = j.find("mimic")
        if m is not None:
            out[j.get("name")] = (m.get("joint"), float(m.get("multiplier", 1.0)), float(m.get("offset", 0.0)))
    return out


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    base = tmp_path_factory.mktemp("export")
    return {name: export_urdf(name, base / name) for name in ALL}


@pytest.mark.parametrize("name", ALL)
def test_export_is_self_contained(exported, name):
    result = exported[name]
    text = result.urdf.read_text(encoding="utf-8")
    refs = mesh_references(text)
    assert all("://" not in r and not r.startswith("/") for r in refs), refs
    for ref in refs:
        assert (result.folder / ref).is_file(), ref
    assert len(result.meshes) >= len(refs)
    # mimic joints survive the export unchanged
    robot = robots.load(name)
    assert text.count("<mimic") == robot.urdf_text.count("<mimic")


@pytest.mark.parametrize("name", ALL)
def test_pybullet_link_poses_match_pinocchio(exported, name):
    robot = robots.load(name)
    result = exported[name]
    mimics = _mimics(result.urdf)
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(result.urdf), useFixedBase=True, physicsClientId=client)
        joints = {}
        links = {}
        for i in range(pybullet.getNumJoints(body, physicsClientId=client)):
            info = pybullet.getJointInfo(body, i, physicsClientId=client)
            joints[info[1].decode()] = (i, info[2])
            links[info[12].decode()] = i
        # PyBullet does not honour <mimic>: every non-fixed joint is set explicitly
        moving = {n: v for n, v in joints.items() if v[1] != pybullet.JOINT_FIXED}
        assert set(moving) == set(robot.joint_names) | set(mimics)
        qs = robot.random_q(N_CONFIGS, seed=7)
        checked = 0
        for q in qs:
            values = dict(zip(robot.joint_names, q))
            for mimic, (master, mult, offset) in mimics.items():
                values[mimic] = mult * values[master] + offset
            for jname, (idx, _) in moving.items():
                pybullet.resetJointState(body, idx, float(values[jname]), physicsClientId=client)
            for link, idx in links.items():
                if link not in robot.frame_names:
                    continue
                state = pybullet.getLinkState(body, idx, computeForwardKinematics=True, physicsClientId=client)
                T = robot.fk(q, frame=link)
                np.testing.assert_allclose(state[4], T[:3, 3], atol=TOL_M, err_msg=f"{name}:{link}")
                R = np.array(pybullet.getMatrixFromQuaternion(state[5])).reshape(3, 3)
                np.testing.assert_allclose(R, T[:3, :3], atol=1e-6, err_msg=f"{name}:{link}")
                checked += 1
        assert checked >= N_CONFIGS * 2
    finally:
        pybullet.disconnect(client)


@pytest.mark.parametrize("name", ALL)
def test_yourdfpy_link_poses_match_pinocchio(exported, name):
    robot = robots.load(name)
    model = yourdfpy.URDF.load(str(exported[name].urdf), build_scene_graph=True, load_meshes=False)
    assert set(model.actuated_joint_names) == set(robot.joint_names)
    order = [robot.joint_names.index(j) for j in model.actuated_joint_names]
    root = model.base_link
    for q in robot.random_q(4, seed=3):
        model.update_cfg(q[order])
        for link in model.link_map:
            if link not in robot.frame_names:
                continue
            T_yd = model.get_transform(link, root)
            np.testing.assert_allclose(T_yd, robot.fk(q, frame=link), atol=1e-9, err_msg=f"{name}:{link}")


def test_export_refuses_non_empty_folder_and_overwrites_on_request(tmp_path):
    out = tmp_path / "ur5"
    out.mkdir()
    (out / "keep.txt").write_text("x")
    with pytest.raises(InvalidInput, match="not empty"):
        export_urdf("ur5", out)
    assert (out / "keep.txt").exists()
    result = export_urdf("ur5", out, overwrite=True)
    assert not (out / "keep.txt").exists()
    assert result.urdf == out / "ur5.urdf" and result.urdf.is_file()
    # no temporary folders left next to it
    assert [p.name for p in tmp_path.iterdir()] == ["ur5"]


def test_export_unknown_robot_names_the_known_ones(tmp_path):
    with pytest.raises(RobotNotFound, match="known robots"):
        export_urdf("no_such_arm", tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_export_missing_mesh_leaves_nothing(tmp_path):
    urdf = tmp_path / "src" / "arm.urdf"
    urdf.parent.mkdir()
    urdf.write_text(
        '<robot name="arm"><link name="base"/><link name="l1"><visual><geometry>'
        '<mesh filename="missing.stl"/></geometry></visual></link>'
        '<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    robot = robots.from_urdf(urdf)
    with pytest.raises(PinarmsError, match="missing.stl"):
        export_urdf(robot, tmp_path / "out")
    assert not (tmp_path / "out").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["src"]
