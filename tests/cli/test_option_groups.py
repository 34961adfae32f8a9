"""Option groups (pinarms.cli.option_groups): the flags a group adds, the one object the command gets, its checks."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import click
import numpy as np
import pytest
from click.testing import CliRunner

from pinarms.cli._common import PinarmsCommand
from pinarms.cli.option_groups import Flag, LoadFlags, TimingFlags, UnitFlags, flag, option_group
from pinarms.errors import InvalidInput


@dataclass(frozen=True)
class Box:
    """A test group: two lengths, the second checked."""

    width: float = 1.0
    depth: float = 2.0

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--width", type=float, default=1.0, show_default=True, help="Width [m]."),
        flag("--depth", type=float, default=2.0, help="Depth [m]."),
    )

    def __post_init__(self) -> None:
        if self.depth <= 0.0:
            raise InvalidInput(f"depth must be > 0, got {self.depth}")


def _command(**changes):
    seen = {}

    @click.command(cls=PinarmsCommand)
    @click.argument("name")
    @option_group(Box, "box", **changes)
    @option_group(UnitFlags, "units", only=("mm",), mm={"help": "Lengths in mm here."})
    def show(name: str, box: Box, units: UnitFlags) -> None:
        seen.update(name=name, box=box, units=units)

    return show, seen


def test_a_group_adds_its_flags_and_passes_one_checked_object():
    show, seen = _command(depth={"default": 3.0})
    result = CliRunner().invoke(show, ["crate", "--width", "0.5", "--mm"])
    assert result.exit_code == 0, result.output
    assert seen["name"] == "crate" and seen["box"] == Box(0.5, 3.0)  # the command's own default for --depth
    assert seen["units"].mm and not seen["units"].deg and seen["units"].length == 1e-3
    text = CliRunner().invoke(show, ["--help"]).output
    assert "--width FLOAT" in text and "[default: 1.0]" in text and "Lengths in mm here." in text
    assert "--deg" not in text  # only --mm of the unit flags
    # the group's check fails: one Error line naming the flag, not the field
    bad = CliRunner().invoke(show, ["crate", "--depth", "-1"])
    assert bad.exit_code == 1 and bad.output.strip() == "Error: --depth must be > 0, got -1.0"


def test_a_group_refuses_fields_it_does_not_have():
    with pytest.raises(TypeError, match=r"no field or flag \['height'\]"):
        option_group(Box, "box", height={"help": "?"})
    with pytest.raises(TypeError, match="no field or flag"):
        option_group(Box, "box", only=("width", "length"))


def test_the_shared_groups_give_si_values():
    timing = TimingFlags(vmax="1,2,3", amax="4")
    v, a, j = timing.limits(np.ones(3))
    np.testing.assert_array_equal(v, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(a, [4.0, 4.0, 4.0])  # one value: every joint
    assert j is None
    with pytest.raises(InvalidInput, match="--vmax takes one value or one per joint"):
        timing.limits(np.ones(2))
    with pytest.raises(click.BadParameter, match="--amax must be comma-separated numbers"):
        TimingFlags(amax="fast")
    load = LoadFlags(payload="800g")
    assert load.asked and load.kg == pytest.approx(0.8) and load.torque_limits(3) is True
    assert LoadFlags(torque_max="5,6").torque_limits(2).tolist() == [5.0, 6.0]
    assert not LoadFlags().asked and LoadFlags().torque_limits(2) is False
