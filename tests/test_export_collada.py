"""MJCF export of COLLADA (.dae) collision meshes: MuJoCo cannot read them, the export converts them to OBJ,
and MuJoCo's mesh then has coal's vertices."""

from __future__ import annotations

import struct
import sys

import mujoco  # a test dependency (the project's [test] extra)
import numpy as np
import pytest
from click.testing import CliRunner

from pinarms import robots
from pinarms.export import export_cell, export_mjcf
from pinarms.cli import cli
from pinarms.robots.cell import load_cell
from pinarms.errors import ModelError

# an asymmetric tetrahedron [m]: MuJoCo's convex hull of it is itself
VERTICES = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.1]])
DAE = ('<?xml version="1.0" encoding="utf-8"?>'
       '<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">'
       '<asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset><library_geometries>'
       '<geometry id="tet"><mesh><source id="pos"><float_array id="pos-array" count="12">'
       + " ".join(f"{v:g}" for v in VERTICES.ravel()) +
       '</float_array><technique_common><accessor source="#pos-array" count="4" stride="3">'
       '<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>'
       '</accessor></technique_common></source><vertices id="vtx"><input semantic="POSITION" source="#pos"/>'
       '</vertices><triangles count="4"><input semantic="VERTEX" source="#vtx" offset="0"/>'
       '<p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles></mesh></geometry></library_geometries>'
       '<library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#tet"/></node>'
       '</visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>')


def _urdf(name: str) -> str:
    return (f'<robot name="{name}"><link name="base_link"><collision><geometry><mesh filename="box.stl"/>'
            '</geometry></collision></link><link name="l1">'
            '<visual><geometry><mesh filename="tet.dae"/></geometry></visual>'
            '<collision><geometry><mesh filename="tet.dae"/></geometry></collision>'
            '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
            '</inertial></link>'
            '<joint name="j1" type="revolute"><parent link="base_link"/><child link="l1"/><axis xyz="0 0 1"/>'
            '<origin xyz="0 0 0.5"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')


def _world_vertices(model: mujoco.MjModel, data: mujoco.MjData, geom: int) -> np.ndarray:
    mesh = model.geom_dataid[geom]
    start, n = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
    local = model.mesh_vert[start:start + n]
    return data.geom_xpos[geom] + local @ data.geom_xmat[geom].reshape(3, 3).T


@pytest.fixture
def received(tmp_path):
    folder = tmp_path / "recv"
    folder.mkdir()
    (folder / "tet.dae").write_text(DAE)
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]  # the tetrahedron again, as binary STL
    body = b"".join(np.vstack([np.zeros(3), VERTICES[list(f)]]).astype("<f4").tobytes() + b"\0\0" for f in faces)
    (folder / "box.stl").write_bytes(b"binary".ljust(80) + struct.pack("<I", len(faces)) + body)
    (folder / "arm.urdf").write_text(_urdf("arm"))
    return folder


def test_an_arm_with_a_collada_collision_mesh_exports_to_mujoco(tmp_path, received):
    robot = robots.from_urdf(received / "arm.urdf")
    out = export_mjcf(robot, tmp_path / "out")
    model = mujoco.MjModel.from_xml_path(str(out.mjcf))
    data = mujoco.MjData(model)
    data.qpos[:] = 0.4
    mujoco.mj_kinematics(model, data)
    meshes = [g for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH
              and model.geom_bodyid[g] == model.body("l1").id]
    assert len(meshes) == 1
    expected = VERTICES @ robot.fk(np.array([0.4]), "l1")[:3, :3].T + robot.fk(np.array([0.4]), "l1")[:3, 3]
    got = _world_vertices(model, data, meshes[0])
    # MuJoCo stores mesh vertices as float32 (mesh_vert): 1e-7 m at this size
    order = lambda v: v[np.lexsort(np.round(v, 6).T)]  # noqa: E731
    np.testing.assert_allclose(order(got), order(expected), atol=1e-7)
    assert "meshes/tet_collada.obj" in out.meshes


def test_a_cell_with_a_collada_collision_mesh_exports_to_mujoco(tmp_path, received):
    text = _urdf("c").replace('<link name="base_link">',
                              '<link name="world"/><joint name="mount" type="fixed"><parent link="world"/>'
                              '<child link="arm_base_link"/></joint><link name="arm_base_link">')
    text = text.replace('<parent link="base_link"/>', '<parent link="arm_base_link"/>')
    (received / "cell.urdf").write_text(text)
    cell = load_cell(str(received / "cell.urdf"))
    out = export_cell(cell, tmp_path / "out", srdf=False)
    model = mujoco.MjModel.from_xml_path(str(out.mjcf))
    assert sum(model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH for g in range(model.ngeom)) == 2
    assert (out.folder / "meshes" / "tet.dae").is_file()  # the URDF keeps the COLLADA mesh


def test_without_pycollada_the_error_says_what_to_do(tmp_path, received, monkeypatch):
    monkeypatch.setitem(sys.modules, "collada", None)  # as if pycollada were not installed
    with pytest.raises(ModelError, match="pip install pycollada"):
        export_mjcf(robots.from_urdf(received / "arm.urdf"), tmp_path / "out")
    assert not (tmp_path / "out").exists()
    run = CliRunner().invoke(cli, ["urdf", "export", str(received / "arm.urdf"), str(tmp_path / "out"), "--mjcf"])
    assert run.exit_code == 1 and run.output.startswith("Error: ") and len(run.output.splitlines()) == 1, run.output
    assert "STL or OBJ" in run.output


def test_an_arm_with_an_ascii_stl_mesh_exports_to_mujoco(tmp_path, received):
    """MuJoCo reads binary STL only; the cell export already wrote ASCII STL as binary, the arm export now too."""
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    facets = "".join("facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x:g} {y:g} {z:g}\n" for x, y, z in
                                                                 VERTICES[list(f)]) + "endloop\nendfacet\n"
                     for f in faces)
    (received / "box.stl").write_text(f"solid tet\n{facets}endsolid tet\n")
    robot = robots.from_urdf(received / "arm.urdf")
    out = export_mjcf(robot, tmp_path / "out")
    model = mujoco.MjModel.from_xml_path(str(out.mjcf))
    assert sum(model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH for g in range(model.ngeom)) == 2
