"""The hand-off study's motions, planned once per process: what the cell study hands over.

The cell study (:mod:`pinarms.studies.cell`) plans the mushroom line's two SCARA cycles, their
two-arm schedule and the AUBO-i3 station's crate cycle for its own rows, with the very
specifications :func:`pinarms.export.shipped.shipped_motions` uses; it hands them here
(:func:`remember`), and the hand-off study, which runs after it in the demo, takes them
(:func:`pinarms.studies.handoff.handoff_motions`) instead of planning them again (about 25 s).
This module imports nothing of the project above its errors (the cell study imports it). The crate-guard move is
seed 001's planned move (:func:`pinarms.optim.motion.crate_guard.crate_guard_move`, planned once
per process). When the cell study has not run, everything is planned as before, so the hand-off
study alone gives the same motions and the same figures.
"""

from __future__ import annotations

from typing import Any

__all__ = ["remember", "forget", "kept", "KEPT_NAMES"]

#: What the cell study hands over: the ``mushroom_line`` cell, its arms' cycles ``{arm: cycle}``
#: and their ``schedule``; the ``aubo_food_station`` cell and its table → crate cycle.
KEPT_NAMES = ("line", "line_cycles", "schedule", "station", "station_cycle")

_KEPT: dict[str, Any] = {}


def remember(**plans: Any) -> None:
    """Keep plans of this process for the hand-off study (names: :data:`KEPT_NAMES`)."""
    from pinarms.errors import InvalidInput

    unknown = sorted(set(plans) - set(KEPT_NAMES))
    if unknown:
        raise InvalidInput(f"remember: unknown plans {unknown}; known: {', '.join(KEPT_NAMES)}")
    _KEPT.update(plans)


def forget() -> None:
    """Drop every kept plan (the next hand-off study plans all of them)."""
    _KEPT.clear()


def kept() -> dict[str, Any]:
    """What was kept (a copy; empty when the cell study has not run in this process)."""
    return dict(_KEPT)
