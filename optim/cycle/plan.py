"""The dispatcher of the pick-and-place cycle: one :class:`CycleRequest` in, one :class:`CycleResult` out.

:func:`plan_cycle` picks the planner the request asks for, each in a module below this one
(plain imports, no callbacks):

* no cell: :func:`pinarms.optim.cycle.straight.approach_cycle` — the joint-space cycle
  (:mod:`pinarms.optim.cycle.joint`: IK on one branch, time-optimal moves through the lift points),
  or, with ``approach="straight"``, that cycle with straight vertical lines at pick and place
  (:mod:`pinarms.optim.cycle.straight`);
* a cell (:class:`CellSettings`): :func:`pinarms.optim.cycle.in_cell.plan_cycle_in_cell` — the same
  cycle checked continuously in the cell and re-planned (higher lift, via points, then a
  transfer planned round what blocks, :mod:`pinarms.optim.motion.transfer`) until it keeps its clearance.

``plan_cycle(robot, spec, **keywords)`` (the former keyword form) builds the request with
:meth:`CycleRequest.from_keywords` and plans it the same way.

Units: m, rad, s (rad/s … or m/s … for prismatic joints).
"""

from __future__ import annotations

from typing import Any

from pinarms.optim.cycle.in_cell import plan_cycle_in_cell
from pinarms.optim.cycle.request import CellSettings, CycleApproach, CycleLoad, CycleRequest, CycleTiming
from pinarms.optim.cycle.spec import (  # noqa: F401  (the spec and result, re-exported here)
    CYCLE_APPROACHES,
    CYCLE_KINDS,
    CYCLE_STATUSES,
    LINE_NAMES,
    CycleResult,
    PickPlace,
)
from pinarms.optim.cycle.straight import approach_cycle
from pinarms.errors import InvalidInput

__all__ = ["CYCLE_KINDS", "CYCLE_APPROACHES", "CYCLE_STATUSES", "LINE_NAMES", "CycleResult", "PickPlace",
           "CycleRequest", "CycleTiming", "CycleLoad", "CycleApproach", "CellSettings", "plan_cycle"]


def plan_cycle(request: CycleRequest | Any, /, spec: PickPlace | None = None, **keywords: Any) -> CycleResult:
    """Plan and time one full pick-and-place cycle (module doc).

    Call it with one :class:`CycleRequest`::

        plan_cycle(CycleRequest(arm, spec, timing=CycleTiming(amax=5.0)))

    or, as before, with the robot, the :class:`PickPlace` spec and keyword arguments
    (``kind``, ``vmax``, ``amax``, ``jmax``, ``method``, ``seed``, ``q_start``, ``payload``,
    ``torque_limits``, ``approach``, ``tool_speed``, ``cell``, ``clearance``, ``arm``, ``hold``,
    ``margin``, ``lift_step``, ``plan_transfer``: the fields of :class:`CycleTiming`,
    :class:`CycleLoad`, :class:`CycleApproach`, :class:`CellSettings` and
    :class:`CycleRequest`, which document them)::

        plan_cycle(arm, spec, amax=5.0)

    Returns:
        :class:`CycleResult`; its ``status`` (:data:`CYCLE_STATUSES`) says whether the cycle
        was planned as asked or re-planned to keep a cell's clearance.

    Raises:
        InvalidInput: ``spec`` is not a :class:`PickPlace`, a bad ``q_start``/``kind``/``approach``,
            or a request given together with other arguments.
        InvalidLimits: a limit ≤ 0, NaN/inf or of the wrong shape, or no ``vmax`` and the
            URDF has none; with ``approach="straight"``, no ``amax``.
        InvalidSettings: unknown ``method``, a payload without torque limits;
            ``SettingOutOfRange``: ``lift_step`` outside :data:`pinarms.optim.caps.LIFT_STEP_RANGE`,
            ``margin`` below :data:`pinarms.optim.caps.MIN_MARGIN`, a ``clearance`` outside 0 … 1 m, a
            ``tool_speed`` that is not > 0.
        UnreachableTarget: a waypoint has no IK solution; the message names it (pick,
            above pick, via k, above place, place), its position and why
            (``robot.ik_failure_reason``).
        InfeasibleProblem: no timing found (from :func:`pinarms.optim.minimize_time`).
        CollisionError: with a cell, the pick or place pose is too close to a fixture, or no
            re-planned cycle keeps the clearance; the message names the blocking bodies.
    """
    if isinstance(request, CycleRequest):
        if spec is not None or keywords:
            raise InvalidInput("plan_cycle(request) takes the request alone: put the spec and the settings in it "
                               "(or call plan_cycle(robot, spec, **keywords))")
    else:
        request = CycleRequest.from_keywords(request, spec, **keywords)
    if request.cell is not None:
        return plan_cycle_in_cell(request)
    return approach_cycle(request)
