"""Robot names: a typo is answered with the close names."""

from __future__ import annotations

import pytest

from pinarms import robots
from pinarms.errors import RobotNotFound
from pinarms.robots.registry import suggest


@pytest.mark.parametrize(
    "typed, expected",
    [
        ("aubo_i5", ["aubo_i3"]),
        ("AUBO-I3", ["aubo_i3"]),  # case and dash
        ("ur_5", ["ur5"]),
        ("pand", ["panda"]),
        ("koji", ["koji_turner", "koji_turner_rail"]),  # part of a name
        ("scara", ["scara_mushroom"]),
        ("conveyor", []),
    ],
)
def test_suggestions(typed, expected):
    assert suggest(typed) == expected


def test_unknown_name_says_did_you_mean():
    with pytest.raises(RobotNotFound, match=r"unknown robot 'aubo_i5'; did you mean aubo_i3\? known robots: .*ur5"):
        robots.load("aubo_i5")
    with pytest.raises(RobotNotFound, match=r"did you mean koji_turner or koji_turner_rail\?"):
        robots.load("koji")
    with pytest.raises(RobotNotFound) as err:
        robots.load("conveyor")
    assert "did you mean" not in str(err.value) and "known robots" in str(err.value)
