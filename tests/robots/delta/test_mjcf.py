"""MJCF export of a delta with equality constraints: MuJoCo loads it, replays a motion, gives the same torques."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinarms.errors import InvalidInput
from pinarms.export.delta import closure_site, export_delta
from pinarms.export.delta_replay import mujoco_motor_torques, replay_delta_in_mujoco
from pinarms.robots.delta import inverse_position, read_closures
from pinarms.robots.delta.dynamics import closed_chain_state, motor_torques

mujoco = pytest.importorskip("mujoco")
W = 2.0 * np.pi


def _p(t):
    return np.stack([0.2 * np.sin(W * t), 0.1 * np.cos(W * t), -1.0 + 0.05 * np.sin(2 * W * t)], axis=1)


@pytest.fixture(scope="module")
def exported(delta, tmp_path_factory):
    loaded = delta.with_payload(1.0, offset=(0.01, 0.0, -0.02))
    return loaded, export_delta(loaded, tmp_path_factory.mktemp("delta") / "out")


def test_export_writes_urdf_closures_and_an_mjcf_mujoco_and_pinocchio_load(exported):
    loaded, files = exported
    assert sorted(p.name for p in files.folder.iterdir()) == [
        "delta_flexpicker.closures.xml", "delta_flexpicker.urdf", "delta_flexpicker.xml"]
    assert read_closures(files.closures) == loaded.closures
    model = mujoco.MjModel.from_xml_path(str(files.mjcf))
    assert model.neq == 3 and [model.eq(k).name for k in range(3)] == ["leg1", "leg2", "leg3"]
    assert model.site(closure_site("platform_ball2")).id >= 0
    # Pinocchio reads the closures back from the MJCF's <connect> elements too
    built = pin.buildModelsAndConstraintsFromMJCF(str(files.mjcf), constraints=True)
    assert built[0].nq == loaded.model.nq
    assert len(built[1]["point_anchor_constraint_models"]) == 3


def test_mujoco_replays_a_motion_and_its_platform_follows_pinarms_fk(exported):
    loaded, files = exported
    theta = inverse_position(loaded.geometry, _p(np.linspace(0.0, 1.0, 120)))
    replay = replay_delta_in_mujoco(loaded, files.mjcf, theta)
    assert replay.platform_error.max() <= 1e-6        # measured about 3e-15 m
    assert replay.closure_violation.max() <= 1e-12


def test_mujoco_torques_equal_pinarms_closed_chain_torques_with_payload(exported):
    loaded, files = exported
    t = np.linspace(0.0, 0.6, 5)
    pd = np.stack([0.2 * W * np.cos(W * t), -0.1 * W * np.sin(W * t), 0.1 * W * np.cos(2 * W * t)], axis=1)
    pdd = np.stack([-0.2 * W**2 * np.sin(W * t), -0.1 * W**2 * np.cos(W * t), -0.2 * W**2 * np.sin(2 * W * t)], axis=1)
    state = closed_chain_state(loaded, _p(t), pd, pdd)
    tau, _ = motor_torques(loaded, state)
    assert np.abs(tau).max() > 5.0
    assert np.abs(mujoco_motor_torques(loaded, files.mjcf, state) - tau).max() <= 1e-6   # measured 5e-15 N m


def test_export_refuses_a_non_empty_folder(exported, tmp_path):
    loaded, _ = exported
    (tmp_path / "keep.txt").write_text("mine")
    with pytest.raises(InvalidInput, match="not empty"):
        export_delta(loaded, tmp_path)
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]
