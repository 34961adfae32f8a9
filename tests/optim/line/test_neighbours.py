"""Neighbours whose windows overlap: picks go through the cell's continuous check."""

import numpy as np
import pytest

from pinarms.optim.line import Belt, ItemType, PlaceBox, Station, TrackingSpec
from pinarms.optim.line.neighbours import NeighbourGuard
from pinarms.robots.cell import load_cell
from pinarms.errors import InvalidInput

ENOKI = ItemType("enoki bunch", 0.15, (0.12, 0.06, 0.04))


@pytest.fixture(scope="module")
def mushroom_line():
    """The two SCARAs of ``mushroom_line`` face each other across one belt (docs/cells.md)."""
    cell = load_cell("mushroom_line")
    belt = Belt((-1.0, 0.0, 0.80), speed=0.1, width=0.30, length=2.0)
    st = [Station(n, cell.arm(n).robot, cell.arm(n).base_to_world, PlaceBox((0.22, s * 0.68, 0.93), f"{n} box"))
          for n, s in (("left", 1.0), ("right", -1.0))]
    return cell, belt, st


def test_same_spot_same_time_is_blocked_far_apart_is_clear(mushroom_line):
    cell, belt, st = mushroom_line
    guard = NeighbourGuard(cell, st, belt, TrackingSpec(), (ENOKI,), clearance=0.005)
    # (arm, item, start, meet, u, w, kind): both arms meet items side by side in the middle, at once
    left = ("left", 0, 0.0, 2.0, 1.0, 0.03, 0)
    right = ("right", 1, 0.0, 2.0, 1.0, -0.03, 0)
    assert guard(left, right) is False
    # the right arm meets its item 0.5 m upstream, 2.5 s later: the left arm is back at its box
    later = ("right", 2, 0.0, 4.5, 0.75, -0.05, 0)
    assert guard(left, later) is True
    assert guard.checks == 2
    # independent check of the blocked pair: the cell's exact distance over the shared time
    from pinarms.robots.cell import ArmMotion

    a, b = guard._plan(left), guard._plan(right)
    motions = [ArmMotion("left", a.trajectory, 2.0 - a.times[0]), ArmMotion("right", b.trajectory, 2.0 - b.times[0])]
    res = cell.with_pairs("arm-arm").check_motion(motions, margin=0.01, curve=True)
    assert res.min_clearance < 0.005


def test_guard_rejects_a_station_that_is_not_a_cell_arm(mushroom_line):
    cell, belt, st = mushroom_line
    moved = Station("left", st[0].robot, np.eye(4), st[0].place)
    with pytest.raises(InvalidInput, match="stands elsewhere"):
        NeighbourGuard(cell, [moved], belt, TrackingSpec(), (ENOKI,))
    with pytest.raises(InvalidInput, match="not an arm of cell"):
        NeighbourGuard(cell, [Station("middle", st[0].robot, st[0].base_to_world, st[0].place)], belt,
                       TrackingSpec(), (ENOKI,))
