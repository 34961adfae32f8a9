"""Caps on the settings of cycles, line schedules and layout searches, in one place.

Every count, step and time a caller may set is checked against a stated range before any
work or allocation starts, so that a typing slip (``n_offsets=10**9``, ``lift_step=1e-7``,
a NaN dwell) is a :class:`~pinarms.optim.errors.SettingOutOfRange` naming the setting, its
value and the range, never a loop that runs for hours or a ``MemoryError``. The caps are
far above what any packing-line study needs (docs/files.md, "Limits on settings").

Units: m, s.
"""

from __future__ import annotations

import math

import numpy as np

from pinarms.optim.errors import SettingOutOfRange

__all__ = [
    "LIFT_STEP_RANGE", "MAX_LIFT_ATTEMPTS", "MAX_CLEARANCE", "MIN_MARGIN", "MAX_DWELL", "MAX_OFFSETS",
    "MAX_LINE_CYCLE_TIME",
    "MAX_AXIS_VALUES", "MAX_PLACEMENTS", "MAX_POINT_PAIRS", "MAX_REFINE", "MAX_REFINE_EVALUATIONS",
    "MAX_WORKSPACE_SAMPLES", "MAX_PATH_GRID", "MAX_PATH_ROUNDS", "MAX_PATH_GRID_POINTS",
    "MIN_PATH_KAPPA", "MIN_PATH_RTOL", "MAX_TIME_SCALED_SAMPLES", "MAX_POPULATION",
    "MAX_GENERATIONS", "MAX_EXACT_STARTS", "MAX_EXACT_ITERATIONS", "MAX_POLISH_EVALUATIONS",
    "count_setting", "number_setting",
]

#: Range [m] of ``CellSettings(lift_step=)`` (``plan_cycle`` in a cell): the rise per re-planning attempt.
LIFT_STEP_RANGE = (1e-3, 1.0)
#: Raised-lift attempts of one in-cell cycle before via points are tried (50 × 20 mm = 1 m).
MAX_LIFT_ATTEMPTS = 50
#: Largest clearance [m] a cycle or a line schedule may ask of fixtures and other arms.
MAX_CLEARANCE = 1.0
#: Smallest resolution [m] of the continuous checks of a cycle or a line schedule (``margin``).
MIN_MARGIN = 1e-3
#: Longest gripper dwell [s] at the pick and at the place (``PickPlace.dwell``).
MAX_DWELL = 3600.0
#: Most time offsets ``schedule_line`` scans per arm and period (``n_offsets``, ``--offsets``).
MAX_OFFSETS = 1000
#: Longest cycle [s] ``schedule_line`` schedules (its busy intervals are sampled every millisecond).
MAX_LINE_CYCLE_TIME = 600.0
#: Most values of one coordinate of a layout grid (``grid_candidates``: lo, lo + step, …, hi).
MAX_AXIS_VALUES = 1_000_000
#: Most base placements of one layout search (a grid, ``random_candidates(n)`` or ``candidates``).
MAX_PLACEMENTS = 1_000_000
#: Most (pick, place) pairs of one layout search (each placement plans one cycle per pair).
MAX_POINT_PAIRS = 1000
#: Most placements a layout search refines (``refine``) and cycles per refinement.
MAX_REFINE = 100
MAX_REFINE_EVALUATIONS = 10_000
#: Most workspace samples of a layout search's boundary margins (``workspace_samples``).
MAX_WORKSPACE_SAMPLES = 10_000_000

#: Most grid intervals and refinement rounds of a time-optimal path timing (``time_optimal(grid=, max_rounds=)``).
MAX_PATH_GRID = 100_000
MAX_PATH_ROUNDS = 50
#: Most points the grid of a time-optimal path timing may grow to while refining (a named error past it),
#: and the smallest ``kappa`` and ``rtol`` of that refinement.
MAX_PATH_GRID_POINTS = 1_000_000
MIN_PATH_KAPPA = 1e-4
MIN_PATH_RTOL = 1e-6
#: Most instants of a time-scaled path timing (``time_scaled(samples=)``).
MAX_TIME_SCALED_SAMPLES = 1_000_000
#: Largest GA population and generation budget (``GASettings``, ``GARequest(max_generations=)``).
MAX_POPULATION = 10_000
MAX_GENERATIONS = 1_000_000
#: Most random starts, SLSQP iterations per start and polishing evaluations of ``solve_exact``.
MAX_EXACT_STARTS = 1000
MAX_EXACT_ITERATIONS = 10_000
MAX_POLISH_EVALUATIONS = 1_000_000


def count_setting(value: object, name: str, least: int, most: int) -> int:
    """``value`` as an int in ``[least, most]``; else :class:`SettingOutOfRange` naming ``name`` and the range."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise SettingOutOfRange(f"{name} must be an integer from {least} to {most:,}, got {value!r}")
    if not least <= int(value) <= most:
        raise SettingOutOfRange(f"{name} = {int(value):,} is outside the range allowed, {least} to {most:,}: "
                                f"give a value in that range")
    return int(value)


def number_setting(value: object, name: str, least: float, most: float = math.inf, *, unit: str = "",
                   open_low: bool = False) -> float:
    """``value`` as a finite float in ``[least, most]`` (``(least, most]`` with ``open_low``).

    Raises :class:`SettingOutOfRange` naming ``name``, the value and the range, for NaN, inf,
    a non-number or a value outside it.
    """
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    x = float(value) if ok else math.nan
    low_ok = x > least if open_low else x >= least
    if not (math.isfinite(x) and low_ok and x <= most):
        lo = f"> {least:g}" if open_low else f">= {least:g}"
        hi = f" and <= {most:g}" if math.isfinite(most) else ""
        suffix = f" {unit}" if unit else ""
        raise SettingOutOfRange(f"{name} must be a finite number {lo}{hi}{suffix}, got {value!r}")
    return x
