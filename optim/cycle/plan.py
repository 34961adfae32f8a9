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

Units: m, rad, s (rad/s … or m/s … for prismatic joints).
"""

from __future__ import annotations

from pinarms.optim.cycle.in_cell import plan_cycle_in_cell
from pinarms.optim.cycle.request import CellSettings, CycleApproach, CycleLoad, CycleRequest, CycleTiming
from pinarms.optim.cycle.spec import (  # noqa: F401  (the spec and result, re-exported here)
    CYCLE_APPROACHES,
    CYCLE_KINDS,
    LINE_NAMES,
    CycleResult,
    CycleStatus,
    PickPlace,
)
from pinarms.optim.cycle.straight import approach_cycle
from pinarms.errors import CollisionError, InvalidInput, UnreachableTarget
from pinarms.optim.errors import InfeasibleProblem, InvalidLimits, InvalidSettings

__all__ = ["CYCLE_KINDS", "CYCLE_APPROACHES", "CycleStatus", "LINE_NAMES", "CycleResult", "PickPlace",
           "CycleRequest", "CycleTiming", "CycleLoad", "CycleApproach", "CellSettings", "plan_cycle"]


def plan_cycle(request: CycleRequest) -> CycleResult:
    """Plan and time one full pick-and-place cycle (module doc)::

        plan_cycle(CycleRequest(arm, spec, timing=CycleTiming(amax=5.0)))

    Args:
        request: the robot, the :class:`PickPlace` spec and the settings (:class:`CycleRequest`,
            :class:`CycleTiming`, :class:`CycleLoad`, :class:`CycleApproach`,
            :class:`CellSettings`, which document them and check them when built).

    Returns:
        :class:`CycleResult`; its ``status`` (:class:`CycleStatus`) says whether the cycle was
        planned as asked or re-planned to keep a cell's clearance, or why there is none, with
        :attr:`CycleResult.reason`: a waypoint without an IK solution (``unreachable``; the reason
        names it: pick, above pick, via k, above place, place, its position and why), no timing
        under the limits (``limits not met``), or in a cell a pose, an idle arm or every re-planned
        cycle too close to something (``in collision``; the reason names the blocking bodies).
        :meth:`CycleResult.raise_for_status` raises that failure as an exception.

    Raises:
        InvalidInput: ``request`` is not a :class:`CycleRequest`, a bad ``q_start``, a robot that
            is not an arm of the cell. (Building the request raises the other input errors:
            :class:`CycleRequest`.)
        InvalidLimits: with ``approach="straight"``, no ``amax``.
    """
    if not isinstance(request, CycleRequest):
        raise InvalidInput(f"plan_cycle takes one CycleRequest, got {type(request).__name__}: "
                           "plan_cycle(CycleRequest(robot, PickPlace(pick, place), timing=CycleTiming(...)))")
    try:
        if request.cell is not None:
            return plan_cycle_in_cell(request)
        return approach_cycle(request)
    except (InvalidInput, InvalidLimits, InvalidSettings):
        raise
    except UnreachableTarget as exc:
        return _failed(request, CycleStatus.UNREACHABLE, exc)
    except CollisionError as exc:
        return _failed(request, CycleStatus.IN_COLLISION, exc)
    except InfeasibleProblem as exc:
        return _failed(request, CycleStatus.LIMITS_NOT_MET, exc)


def _failed(request: CycleRequest, status: CycleStatus, exc: Exception) -> CycleResult:
    """The result of a request without a cycle: its status, the reason in words and the exception."""
    return CycleResult(str(getattr(request.robot, "name", "robot")), request.spec, status=status,
                       reason=str(exc), error=exc)
