"""A robot in a session: stored by registry name or embedded URDF, rebuilt with its payload, checked on load."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pinarms import robots
from pinarms.viz import SessionFormatError
from pinarms.viz.session_robots import rebuild_robot, robot_entry, shipped_model_dirs


def test_a_registry_robot_is_stored_by_name_and_rebuilt():
    arm = robots.load("aubo_i3")
    entry = robot_entry(arm, "left", np.eye(4))
    assert (entry.key, entry.source, entry.name, entry.urdf_text, entry.payload) == ("left", "registry", "aubo_i3",
                                                                                      None, None)
    assert entry.joint_names == tuple(arm.joint_names)
    back = rebuild_robot(entry, shipped_model_dirs())
    assert back.urdf_text == arm.urdf_text and back.tcp_frame == arm.tcp_frame


def test_another_robot_has_its_urdf_embedded_and_its_payload_reapplied():
    arm = robots.load("aubo_i3").with_payload({"mass_kg": 1.5})
    entry = robot_entry(robots.from_urdf_text(arm.urdf_text, tcp=arm.tcp_frame, name="custom"), "c", None)
    assert entry.source == "urdf" and entry.urdf_text == arm.urdf_text
    loaded = robot_entry(arm, "p", None)
    assert loaded.source == "registry" and loaded.payload["mass_kg"] == pytest.approx(1.5)
    assert rebuild_robot(loaded, shipped_model_dirs()).payload.mass == pytest.approx(1.5)


def test_a_robot_that_now_loads_with_other_joints_is_refused():
    entry = robot_entry(robots.load("aubo_i3"), "a", None)
    renamed = dataclasses.replace(entry, joint_names=("j1",) + entry.joint_names[1:-1])
    with pytest.raises(SessionFormatError, match="the registry's model changed"):
        rebuild_robot(renamed, shipped_model_dirs())
