"""The hand-off study's motions, planned once per process.

The cell study (:mod:`pinarms.studies.cell`) plans the mushroom line's two SCARA cycles, their
two-arm schedule and the AUBO-i3 station's crate cycle for its own rows, with the very
specifications :func:`pinarms.export.shipped.shipped_motions` uses; it hands them here
(:func:`remember`), and the hand-off study, which runs after it in the demo, takes them
(:func:`handoff_motions`) instead of planning them again (about 25 s). The crate-guard move is
seed 001's planned move (:func:`pinarms.studies.seed001_motion._planned_move_001`, planned once
per process). When the cell study has not run, everything is planned as before, so the hand-off
study alone gives the same motions and the same figures.
"""

from __future__ import annotations

from typing import Any

__all__ = ["remember", "forget", "handoff_motions", "KEPT_NAMES"]

#: What the cell study hands over: the ``mushroom_line`` cell, its arms' cycles ``{arm: cycle}``
#: and their ``schedule``; the ``aubo_food_station`` cell and its table → crate cycle.
KEPT_NAMES = ("line", "line_cycles", "schedule", "station", "station_cycle")

_KEPT: dict[str, Any] = {}


def remember(**plans: Any) -> None:
    """Keep plans of this process for the hand-off study (names: :data:`KEPT_NAMES`)."""
    from pinarms.robots.errors import InvalidInput

    unknown = sorted(set(plans) - set(KEPT_NAMES))
    if unknown:
        raise InvalidInput(f"remember: unknown plans {unknown}; known: {', '.join(KEPT_NAMES)}")
    _KEPT.update(plans)


def forget() -> None:
    """Drop every kept plan (the next hand-off study plans all of them)."""
    _KEPT.clear()


def handoff_motions() -> list:
    """The shipped motions in :func:`~pinarms.export.shipped.shipped_motions`'s order (station
    cycle, crate-guard move, the line's left and right cycles, the line schedule), taking what the
    cell study kept and planning the rest."""
    from pinarms.export.shipped import ShippedMotion, shipped_motions

    kept = dict(_KEPT)
    if not all(k in kept for k in KEPT_NAMES):
        return shipped_motions(line=True)
    from pinarms.studies.cell import LINE_TASKS
    from pinarms.studies.seed001_motion import _planned_move_001

    plan = _planned_move_001()[1]["plan"]  # the crate-guard move: seed 001 planned it (cached per process)
    line, cycles = kept["line"], kept["line_cycles"]
    out = [ShippedMotion("station_cycle", kept["station"], kept["station_cycle"], arm="aubo"),
           ShippedMotion("crate_guard_move", plan.cell, plan)]
    out += [ShippedMotion(f"line_{name}_cycle", line, cycles[name], arm=name) for name in LINE_TASKS]
    out.append(ShippedMotion("line_schedule", line, kept["schedule"], cycles={n: cycles[n] for n in LINE_TASKS}))
    return out
