"""Payloads: a new robot carries them, its weight moves with the centre of mass, bad tensors are named."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.robots import InvalidInput
from pinarms.robots.dynamics import total_mass
from pinarms.robots.payload import InvalidPayload, Payload

G = 9.81


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


def test_with_payload_returns_a_new_robot_and_leaves_the_original(aubo):
    q = aubo.random_q(5, seed=4)
    before = aubo.gravity(q)
    loaded = aubo.with_payload(1.5, com=[0.0, 0.0, 0.05], inertia=[0.004, 0.004, 0.002])
    assert loaded is not aubo and loaded.payload.mass == 1.5 and aubo.payload is None
    np.testing.assert_array_equal(aubo.gravity(q), before)
    assert not np.allclose(loaded.gravity(q), before)
    np.testing.assert_array_equal(loaded.fk(q), aubo.fk(q))  # kinematics untouched
    assert total_mass(loaded) == pytest.approx(total_mass(aubo) + 1.5, abs=1e-12)
    # a payload replaces the previous one; zero mass gives the bare arm back
    again = loaded.with_payload(3.0)
    assert total_mass(again) == pytest.approx(total_mass(aubo) + 3.0, abs=1e-12)
    np.testing.assert_allclose(loaded.with_payload(0.0).gravity(q), before, atol=1e-12)
    assert loaded.with_payload(0.0).payload is None


def test_payload_com_offset_moves_its_weight_along_the_tool(aubo):
    # a point mass 0.1 m further along the tcp's z weighs like a point mass at that frame point
    q = aubo.random_q(20, seed=8)
    off = aubo.with_payload(2.0, com=[0.0, 0.0, 0.1])
    T = aubo.fk(q)
    J = aubo.jacobian(q)
    lever = T[:, :3, :3] @ np.array([0.0, 0.0, 0.1])  # base axes
    # linear Jacobian of the offset point: J_v - [lever]x J_w
    Jw = J[:, 3:, :]
    Jp = J[:, :3, :] - np.cross(lever[:, :, None], Jw, axis=1)
    expected = np.einsum("nij,i->nj", Jp, np.array([0.0, 0.0, 2.0 * G]))
    np.testing.assert_allclose(off.gravity(q) - aubo.gravity(q), expected, atol=1e-10)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"mass": -1.0}, "negative mass"),
        ({"mass": float("nan")}, "finite"),
        ({"mass": 1.0, "inertia": [[0.01, 0.002, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.01]]}, "not symmetric"),
        ({"mass": 1.0, "inertia": [0.01, 0.01, -0.001]}, "positive semi-definite"),
        ({"mass": 1.0, "inertia": [0.001, 0.001, 0.01]}, "triangle inequality"),
        ({"mass": 0.0, "inertia": [0.001, 0.001, 0.001]}, "mass is 0"),
        ({"mass": 1.0, "com": [0.0, 0.1]}, "com must be 3"),
        ({"mass": 1.0, "inertia": np.eye(2)}, r"\(3, 3\)"),
    ],
)
def test_bad_payloads_are_named(aubo, kwargs, match):
    with pytest.raises(InvalidPayload, match=match):
        aubo.with_payload(**kwargs)
    assert issubclass(InvalidPayload, InvalidInput)


def test_payload_on_an_unknown_frame_is_refused(aubo):
    with pytest.raises(InvalidInput, match="no frame 'gripper'"):
        aubo.with_payload(1.0, frame="gripper")


def test_payload_round_trips_through_its_dict():
    p = Payload(1.5, com=[0.0, 0.01, 0.05], inertia=[[0.004, 0.0, 0.0], [0.0, 0.004, 0.0], [0.0, 0.0, 0.002]])
    q = Payload.from_dict(p.as_dict())
    assert q.mass == p.mass and q.frame == "tcp"
    np.testing.assert_array_equal(q.com, p.com)
    np.testing.assert_array_equal(q.inertia, p.inertia)
    with pytest.raises(InvalidPayload, match="unknown payload field"):
        Payload.from_dict({"mass_kg": 1.0, "colour": "red"})
