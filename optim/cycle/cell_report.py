"""What :func:`pinarms.optim.plan_cycle` with a cell reports about the clearance it kept (:mod:`.in_cell`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

__all__ = ["CellCycleReport"]


@dataclass(frozen=True, eq=False)
class CellCycleReport:
    """How a cycle was made to keep its clearance in a cell.

    Attributes:
        cell: the cell's name; ``arm``: the arm's name in it.
        clearance: the distance required from fixtures and other arms [m]; ``margin``: the
            resolution of the continuous check [m].
        min_clearance: the smallest distance of the kept cycle at the check's samples [m]
            and the pair (``min_clearance_pair``, ``"body_a – body_b"``); ``lower_bound``:
            the proven bound between samples [m].
        lift: the lift kept [m]; ``via``: the via points added (base frame, m).
        cycle_time_without_cell: the cycle planned ignoring the cell [s];
            ``extra_time``: the kept cycle's time minus it [s].
        attempts: each attempt in order: ``(description, clear, min clearance [m], pair)``.
        planned_transfer: the transfer was planned around the cell (:mod:`pinarms.optim.motion.transfer`)
            after raising the lift and via points could not clear.
    """

    cell: str
    arm: str
    clearance: float
    margin: float
    min_clearance: float
    min_clearance_pair: str
    lower_bound: float
    lift: float
    via: tuple[tuple[float, float, float], ...]
    cycle_time_without_cell: float
    extra_time: float
    attempts: tuple[tuple[str, bool, float, str], ...] = field(default=())
    planned_transfer: bool = False

    def as_dict(self) -> dict[str, Any]:
        return {
            "cell": self.cell,
            "arm": self.arm,
            "clearance_m": self.clearance,
            "margin_m": self.margin,
            "min_clearance_m": self.min_clearance,
            "min_clearance_pair": self.min_clearance_pair,
            "lower_bound_m": self.lower_bound,
            "lift_m": self.lift,
            "via_m": [list(v) for v in self.via],
            "cycle_time_without_cell_s": self.cycle_time_without_cell,
            "extra_time_s": self.extra_time,
            "attempts": [{"what": a, "clear": c, "min_clearance_m": d, "pair": p} for a, c, d, p in self.attempts],
            "planned_transfer": self.planned_transfer,
        }
