"""The robot a reach task ships to a worker: the registry name, or the URDF text, checked by SHA-256."""

from __future__ import annotations

import dataclasses

import pytest

from pinarms import robots
from pinarms.errors import ModelError
from pinarms.robots.reach.robot_spec import robot_of, spec_of, urdf_sha256


def test_a_registry_robot_travels_by_name_and_another_by_its_urdf_text():
    aubo = robots.load("aubo_i3")
    spec = spec_of(aubo)
    assert spec.registry and spec.urdf_text is None and spec.sha256 == urdf_sha256(aubo)
    assert spec.family is not None  # its closed form travels with it
    custom = robots.from_urdf_text(aubo.urdf_text, tcp=aubo.tcp_frame, name="aubo_copy")
    other = spec_of(custom)
    assert not other.registry and other.urdf_text == aubo.urdf_text and other.family == spec.family
    assert urdf_sha256(robot_of(other)) == other.sha256


def test_a_worker_whose_urdf_differs_refuses_the_task():
    spec = dataclasses.replace(spec_of(robots.load("scara_mushroom")), sha256="0" * 64)
    with pytest.raises(ModelError, match="another pinarms version"):
        robot_of(spec)
