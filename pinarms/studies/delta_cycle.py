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
from typing import Any

import numpy as np

from pinarms.papers import IRB360_1600
from pinarms.report import Row

from pinarms.studies.study import Study

__all__ = ["DELTA_CYCLE_START_M", "SCARA_CYCLE_START_M", "PAGE_BASE_HEIGHT_M", "delta_cycle_rows", "cycle_session",
           "study_delta"]

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


#: Height of the delta's base above the floor on the study's page [m] (the gate then runs 0.2 m above it).
PAGE_BASE_HEIGHT_M = 1.2


def cycle_session(payload: float = 1.0, quick: bool = False, hz: float = 200.0) -> Any:
    """A :class:`pinarms.viz.Session` of ``delta_flexpicker`` running the datasheet's cycle at ``payload`` [kg]:
    there (the platform's time-optimal move, the tool turning 90 deg), the air dwell at the place, back
    (the same move reversed, the tool turning back: the cycle time assumes the way back takes as long),
    the air dwell at the pick; sampled at ``hz`` [1/s]. Only the actuated angles are stored."""
    from pinarms import viz
    from pinarms.optim.standard_cycle import StandardCycle, gate_length, gate_points
    from pinarms.optim.standard_cycle.delta_cycle import delta_cycle_time, tool_turn_limits, turn_angle
    from pinarms.optim.standard_cycle.timing import profile_position
    from pinarms.robots.delta import inverse_position, load_delta

    sheet, delta = IRB360_1600, load_delta("delta_flexpicker")
    cycle = StandardCycle(start=DELTA_CYCLE_START_M, payload=payload)
    turn = np.deg2rad(sheet.axis4_rotation_deg)
    way = delta_cycle_time(delta, cycle, turn, 80 if quick else 400)
    one, air, length = way.one_way_s, sheet.air_activation_s, gate_length(cycle)
    edges = np.cumsum([0.0, one, air, one, air])
    t = np.union1d(np.arange(0.0, edges[-1], 1.0 / hz), edges)
    phase = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, 3)
    tau = t - edges[phase]
    there = profile_position(way.move, tau)
    s = np.select([phase == 0, phase == 1, phase == 2], [there, length, length - there], 0.0)
    turned = turn_angle(turn, *tool_turn_limits(delta), tau)
    tool = np.select([phase == 0, phase == 1, phase == 2], [turned, turn, turn - turned], 0.0)
    theta = inverse_position(delta.geometry, gate_points(cycle, s)[0])
    base = np.eye(4)
    base[2, 3] = PAGE_BASE_HEIGHT_M
    session = viz.Session(title=f"delta_flexpicker: the standard cycle 25/305/25 mm at {payload:g} kg, axis 4 "
                                f"turning 90 deg ({2 * one + 2 * air:.3f} s with 2 x 35 ms air)")
    session.add_delta(delta, key="delta_flexpicker", base_to_world=base, motion=(t, np.column_stack([theta, tool])))
    ends = gate_points(cycle, np.array([0.0, length]))[0] @ base[:3, :3].T + base[:3, 3]
    session.add_points("pick and place (platform centre)", ends, kind="target")
    return session


def study_delta(quick: bool = False) -> Study:
    """The delta study as a :class:`Study` of the demo (its page: the delta running the cycle at 1 kg)."""
    start = time.perf_counter()
    rows = delta_cycle_rows(quick)
    return Study("delta", "delta robot: standard pick cycle vs the datasheet, and seed 000's SCARA", rows,
                 session=cycle_session(1.0, quick), seconds=time.perf_counter() - start)
