"""MuJoCo export: the MJCF keeps the flange and the tcp (as sites) where MuJoCo's own URDF
import drops them; MuJoCo's tcp agrees with pinarms' forward kinematics; mimic joints are
equality constraints MuJoCo enforces."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import mujoco  # a test dependency (the project's [test] extra): an independent engine
import numpy as np
import pytest

from pinarms import robots
from pinarms.export import export_mjcf, export_urdf
from pinarms.errors import InvalidInput

TOL_M = 1e-9


def _equalities(model: mujoco.MjModel) -> list[tuple[int, int, np.ndarray]]:
    """``(dependent qpos address, leader qpos address, polycoef)`` of each joint equality."""
    out = []
    for k in range(model.neq):
        if model.eq_type[k] == mujoco.mjtEq.mjEQ_JOINT:
            a, b = model.eq_obj1id[k], model.eq_obj2id[k]
            out.append((model.jnt_qposadr[a], model.jnt_qposadr[b], model.eq_data[k, :5].copy()))
    return out


def _set(model: mujoco.MjModel, data: mujoco.MjData, arm, q: np.ndarray) -> None:
    """Independent joints from ``q`` by name; the others from MuJoCo's equality constraints."""
    for name, value in zip(arm.joint_names, q):
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = value
    for dep, lead, c in _equalities(model):
        x = data.qpos[lead]
        data.qpos[dep] = c[0] + c[1] * x + c[2] * x**2 + c[3] * x**3 + c[4] * x**4


@pytest.mark.parametrize("name", ["koji_turner", "aubo_i3", "scara_mushroom", "gantry_flower", "ur5"])
def test_mujoco_tcp_matches_pinarms_fk(name, tmp_path):
    arm = robots.load(name)
    out = export_mjcf(arm, tmp_path / name)
    model = mujoco.MjModel.from_xml_path(str(out.mjcf))
    data = mujoco.MjData(model)
    assert out.sites == (("flange", "tcp") if name != "ur5" else ("tool0",))
    for q in arm.random_q(12, seed=3):
        _set(model, data, arm, q)
        mujoco.mj_kinematics(model, data)
        for frame in out.sites:
            np.testing.assert_allclose(data.site(frame).xpos, arm.position(q, frame), atol=TOL_M)
            np.testing.assert_allclose(data.site(frame).xmat.reshape(3, 3), arm.fk(q, frame)[:3, :3], atol=1e-9)


def test_mujoco_alone_drops_the_tool_the_export_keeps_it(tmp_path):
    plain = mujoco.MjModel.from_xml_path(str(export_urdf("aubo_i3", tmp_path / "urdf").urdf))
    names = {plain.body(i).name for i in range(plain.nbody)}
    assert "tcp" not in names and "flange" not in names  # fused away by MuJoCo's URDF import
    kept = mujoco.MjModel.from_xml_path(str(export_mjcf("aubo_i3", tmp_path / "mjcf").mjcf))
    assert {kept.site(i).name for i in range(kept.nsite)} == {"flange", "tcp"}


def test_koji_parallelogram_is_two_equality_constraints_mujoco_enforces(tmp_path):
    arm = robots.load("koji_turner")
    out = export_mjcf(arm, tmp_path / "koji")
    model = mujoco.MjModel.from_xml_path(str(out.mjcf))
    eqs = _equalities(model)
    assert len(eqs) == 2 and all(np.allclose(c, [0.0, -1.0, 0.0, 0.0, 0.0]) for _, _, c in eqs)
    data = mujoco.MjData(model)
    _set(model, data, arm, np.array([0.3, 0.2, -0.2, 0.5]))
    worst, tilt = 0.0, 0.0
    for _ in range(500):  # 1 s under gravity, unactuated, onto the shoulder's limit: the linkage holds
        mujoco.mj_step(model, data)
        worst = max(worst, max(abs(data.qpos[dep] - (c[0] + c[1] * data.qpos[lead])) for dep, lead, c in eqs))
        tilt = max(tilt, np.degrees(np.arccos(np.clip(data.site("tcp").xmat.reshape(3, 3)[2, 2], -1.0, 1.0))))
    # measured: 7.8e-4 rad (MuJoCo's default soft constraint: 0.034 rad); the tool axis stays vertical
    assert worst < 2e-3 and tilt < 0.2


def test_export_mjcf_checks_its_inputs(tmp_path):
    with pytest.raises(InvalidInput, match="site 'gripper' is not a link"):
        export_mjcf("aubo_i3", tmp_path / "x", sites=("gripper",))
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "keep.txt").write_text("x")
    with pytest.raises(InvalidInput, match="not empty"):
        export_mjcf("aubo_i3", tmp_path / "full")
    assert (tmp_path / "full" / "keep.txt").read_text() == "x"
    root = ET.parse(export_mjcf("aubo_i3", tmp_path / "full", overwrite=True).mjcf).getroot()
    assert root.tag == "mujoco" and not (tmp_path / "full" / "keep.txt").exists()


def test_cli_urdf_export_mjcf(tmp_path):
    from click.testing import CliRunner

    from pinarms.cli import cli

    result = CliRunner().invoke(cli, ["urdf", "export", "aubo_i3", str(tmp_path / "a"), "--mjcf"])
    assert result.exit_code == 0, result.output
    assert "aubo_i3.xml (sites: flange, tcp)" in result.stdout
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "a" / "aubo_i3.xml"))
    assert model.nsite == 2
