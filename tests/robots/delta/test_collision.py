"""The delta's collision bodies: real rods (not the mid-line forearm), the platform, clearance to a fixture."""

import coal
import numpy as np
import pytest

from pinarms.robots.delta import forward_position, load_delta
from pinarms.robots.delta.collision import PART_RADII, PLATFORM_THICKNESS, collision_bodies, fixture_clearance
from pinarms.robots.delta.errors import DeltaInputError


@pytest.fixture(scope="module")
def delta():
    return load_delta("delta_flexpicker")


def _at(p) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T


def test_bodies_are_the_real_parts(delta):
    names = [b.name for b in collision_bodies(delta, [0.3, 0.3, 0.3])]
    assert sorted(names) == sorted([f"upper_arm_{i}" for i in (1, 2, 3)] + [f"rod_{i}{r}" for i in (1, 2, 3)
                                   for r in "ab"] + ["platform", "tool"])
    assert not any("forearm" in n for n in names)


def test_a_fixture_between_a_legs_rods_is_clear(delta):
    """A 40 mm cube on leg 1's mid-line, halfway down its forearm: the mid-line forearm of the tree passes
    through it, the two real rods pass h/2 on either side: clearance h/2 - rod radius - 20 mm exactly."""
    theta = np.array([0.3, 0.3, 0.3])  # symmetric: leg 1's rods lie in planes y = +-h/2
    g = delta.geometry
    q = delta.configuration(theta)
    from pinarms.robots.delta import rod_endpoints

    rods = rod_endpoints(delta, q)[0]            # leg 1: (2 rods, 2 ends, 3)
    middle = rods.mean(axis=(0, 1))              # on the mid-line
    d, body = fixture_clearance(delta, theta, coal.Box(0.04, 0.04, 0.04), _at(middle))
    assert body.startswith("rod_1")
    assert round(d, 9) == round(0.5 * g.rod_spacing - PART_RADII["rod"] - 0.02, 9)


def test_a_plate_under_the_tool(delta):
    """A plate 30 mm under the tcp: the tool is nearest, 30 mm less its radius; touching at the tcp: <= 0."""
    theta = np.array([0.4, 0.2, 0.5])
    tcp = delta.tcp_position(delta.configuration(theta))
    plate = coal.Box(0.5, 0.5, 0.01)
    d, body = fixture_clearance(delta, theta, plate, _at(tcp - [0.0, 0.0, 0.03 + 0.005]))
    assert body == "tool" and round(d, 9) == round(0.03 - PART_RADII["tool"], 9)
    d, _ = fixture_clearance(delta, theta, plate, _at(tcp - [0.0, 0.0, 0.004]))
    assert d <= 0.0
    # the platform's plate: a 20 mm cube level with it, 30 mm from its rim between legs 2 and 3
    g = delta.geometry
    theta = np.array([0.3, 0.3, 0.3])
    p = forward_position(g, theta)
    rim = g.platform_radius + 0.5 * g.rod_spacing
    d, body = fixture_clearance(delta, theta, coal.Box(0.02, 0.02, 0.02), _at(p - [rim + 0.03 + 0.01, 0.0, 0.0]))
    assert body == "platform" and round(d, 9) == 0.03
    assert PLATFORM_THICKNESS == 0.02


def test_bad_angles_refused(delta):
    with pytest.raises(DeltaInputError, match="three finite"):
        collision_bodies(delta, [0.1, np.nan, 0.2])
