"""A line of the user's own arm: ``n`` copies of any arm beside a belt, each with its box.

:func:`arm_line` (an :class:`ArmLineRequest` in, a ``LineSpec`` out) lays the arms out as seed 000's line lays out its SCARAs, with distances a
6-axis arm needs: the belt (surface ``belt_height`` m, ``width`` m wide) runs along the world's
x axis; arm k stands at x = ``first`` + k × ``spacing``, ``base_offset`` m to the side of the
belt's centre line (y > 0), its base ``base_height`` m above the belt's surface; its box at ``box`` (dx, dy, dz) m
from its base. The tool points down: the arm's tcp z axis along the world's -z (the tool axis,
docs/workspace.md; an arm whose tool points along another axis of its link gets a tool point
turned onto it, ``pinarms belt --tool-axis``). Its task maps are built, never stored (they hold
for that arm, layout and belt speed only).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pinarms.optim.line import Belt, ItemType, LineSpec, PlaceBox, Rule, Station, Stream, TrackingSpec, base_pose
from pinarms.errors import InvalidInput

__all__ = ["arm_line", "ArmLineRequest", "ITEM"]

#: The item of a line of the user's arm: a 0.1 kg box of 0.08 × 0.06 × 0.04 m.
ITEM = ItemType("item", 0.1, (0.08, 0.06, 0.04))


def _finite(value: Any, what: str, *, positive: bool = False) -> float:
    x = float(value)
    if not np.isfinite(x) or (positive and x <= 0.0):
        raise InvalidInput(f"{what} must be a finite{' positive' if positive else ''} number, got {value!r}")
    return x


@dataclass(frozen=True)
class ArmLineRequest:
    """A line of ``n_arms`` copies of ``robot`` (a :class:`pinarms.robots.Robot`; module doc): ``rate`` items
    per minute at random on a belt at ``speed`` [m/s], the layout (``base_offset``, ``base_height``, ``box``,
    ``spacing``, ``first``, ``belt_height``, ``width`` [m]), the tracking pick's ``descend`` [s], the
    assignment ``rule``, the Monte Carlo ``seeds`` and ``duration`` [s], the task maps' ``map_grid`` and
    ``map_yaw``, and the ``item``.

    Raises:
        InvalidInput: a distance, speed or time that is not a finite number (positive where it must be).
    """

    robot: Any
    n_arms: int
    rate: float
    speed: float = 0.1
    base_offset: float = 0.4
    base_height: float = 0.0
    box: tuple[float, float, float] = (-0.1, 0.25, 0.15)
    spacing: float = 1.0
    first: float = 1.0
    belt_height: float = 0.8
    width: float = 0.3
    descend: float = 0.5
    rule: str = "first"
    seeds: tuple[int, ...] = (0, 1, 2, 3, 4)
    duration: float = 600.0
    map_grid: tuple[int, int] = (12, 5)
    map_yaw: str = "auto"
    item: ItemType = ITEM

    def __post_init__(self) -> None:
        _finite(self.base_offset, "base_offset [m]")
        for v in self.box:
            _finite(v, "box offset [m]")
        _finite(self.spacing, "spacing [m]", positive=True)
        _finite(self.first, "first [m]")
        _finite(self.belt_height, "belt_height [m]")
        _finite(self.base_height, "base_height [m]")
        _finite(self.descend, "descend [s]", positive=True)


def arm_line(request: ArmLineRequest) -> LineSpec:
    """The :class:`~pinarms.optim.line.LineSpec` of ``request``'s line (module doc)."""
    r = request
    offset, (dx, dy, dz), step = float(r.base_offset), (float(v) for v in r.box), float(r.spacing)
    x0, z = float(r.first), float(r.belt_height)
    zb = z + float(r.base_height)
    stations = tuple(Station(f"arm {k + 1}", r.robot, base_pose(x0 + step * k, offset, zb),
                             PlaceBox((x0 + step * k + dx, offset + dy, zb + dz), f"box {k + 1}"))
                     for k in range(int(r.n_arms)))
    belt = Belt((0.0, 0.0, z), speed=r.speed, width=r.width, length=x0 + step * int(r.n_arms) + 0.5)
    return LineSpec(belt, stations, Stream("poisson", r.rate / 60.0, r.duration, types=(r.item,)),
                    TrackingSpec(descend=float(r.descend)), Rule(r.rule), r.seeds, 0.01, r.map_grid, map_yaw=r.map_yaw)
