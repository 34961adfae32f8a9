"""The delta study: the standard pick cycle (25/305/25 mm) of the shipped delta against its datasheet,
and the same cycle for seed 000's SCARA (rows filed under ``"delta"``).

The delta's cycle is pinarms' time-optimal motion there and back under the motor speed,
acceleration and torque limits (assumed: docs/delta.md) with the payload, plus ABB's 2 x 35 ms
of air activation; like the datasheet's, it turns axis 4 by 90 degrees on each way, rest to rest,
beside the platform's move (:func:`pinarms.optim.standard_cycle.delta_cycle_time`: a way takes the
longer of the two). Each row's note gives the cycle without the turn too.
"""

from __future__ import annotations

import time

import numpy as np

from pinarms.papers import IRB360_1600
from pinarms.report import Row

from pinarms.studies.study import Study

__all__ = ["DELTA_CYCLE_START_M", "SCARA_CYCLE_START_M", "delta_cycle_rows", "study_delta"]

#: Where the delta's gate starts [m] (base frame): centred under the base, 1.0 m below the motor
#: axes (the top of the Ø1.60 m cylinder is at 0.908 m), across along leg 1's azimuth (x).
DELTA_CYCLE_START_M = (-0.1525, 0.0, -1.0)
#: Seed 000's SCARA: across along y at 0.30 m from its axis, tcp 0.09 m above its base (j3 at 0.10 m).
SCARA_CYCLE_START_M = (0.30, -0.1525, 0.09)
_SCARA_Q_REF = (-0.5, 1.0, 0.10, 0.0)


def _binding(usage: dict[str, float]) -> str:
    """The limits the time-optimal motion reaches (used to within 0.1 %)."""
    return ", ".join(k for k, v in usage.items() if v >= 0.999) or "none"


def delta_cycle_rows(quick: bool = False) -> list[Row]:
    """Rows: the delta at each datasheet payload, then seed 000's SCARA at 1 kg."""
    from pinarms import robots
    from pinarms.optim.standard_cycle import StandardCycle, serial_standard_cycle
    from pinarms.optim.standard_cycle.delta_cycle import delta_cycle_time, tool_turn_limits
    from pinarms.robots.delta import load_delta

    sheet = IRB360_1600
    grid = 80 if quick else 400
    delta = load_delta("delta_flexpicker")
    turn = np.deg2rad(sheet.axis4_rotation_deg)
    v_tool, a_tool = tool_turn_limits(delta)
    rows = []
    for payload, published in zip(sheet.payloads_kg, sheet.cycle_s):
        way = delta_cycle_time(delta, StandardCycle(start=DELTA_CYCLE_START_M, payload=payload), turn, grid)
        cycle = 2.0 * way.one_way_s + 2.0 * sheet.air_activation_s
        bare = 2.0 * way.move.duration + 2.0 * sheet.air_activation_s
        rows.append(Row("delta", f"delta_flexpicker standard cycle 25/305/25 mm, axis 4 turning 90 deg, at {payload:g} kg "
                                 f"(vs {sheet.model})",
                        round(published, 4), round(cycle, 4), "s", None,
                        f"time-optimal there and back under assumed motor limits (10 rad/s, 150 rad/s^2, 120 N m) "
                        f"+ 2 x 35 ms air, the tool turning 90 deg each way in {way.turn_s:.3f} s ({v_tool:g} rad/s, "
                        f"{a_tool:g} rad/s^2 assumed); {100.0 * (cycle / published - 1.0):+.0f} %; without the turn "
                        f"{bare:.3f} s; binding: {way.binding}"))
    scara = robots.load("scara_mushroom")
    cycle = StandardCycle(start=SCARA_CYCLE_START_M, direction=(0.0, 1.0, 0.0), payload=1.0)
    timing = serial_standard_cycle(scara, cycle, np.array(_SCARA_Q_REF), grid)
    rows.append(Row("delta", "seed 000 SCARA (scara_mushroom), same cycle at 1 kg, motion only", None,
                    round(2.0 * timing.duration, 4), "s", None,
                    "its chosen limits (3 rad/s, 12 rad/s^2; docs/robots/scara_mushroom.md); tool yaw held; "
                    f"binding: {_binding(timing.usage)}"))
    return rows


def study_delta(quick: bool = False) -> Study:
    """The delta study as a :class:`Study` of the demo."""
    start = time.perf_counter()
    rows = delta_cycle_rows(quick)
    return Study("delta", "delta robot: standard pick cycle vs the datasheet, and seed 000's SCARA", rows,
                 seconds=time.perf_counter() - start)
