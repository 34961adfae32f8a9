"""The pick-and-place cycle: one request in (:class:`CycleRequest`), one call (:func:`plan_cycle`), one result out.

- :mod:`.spec`: the task and the result (:class:`PickPlace`, :class:`CycleResult` with its
  ``status``) and the helpers every way of planning a cycle shares;
- :mod:`.vertical`: the vertical lines measured and the rest between moves (shared by every planner);
- :mod:`.request`: :class:`CycleRequest` and its settings groups (:class:`CycleTiming`,
  :class:`CycleLoad`, :class:`CycleApproach`, :class:`CellSettings`), checked when built;
- :mod:`.joint`: the joint-space cycle (IK on one branch, time-optimal moves);
- :mod:`.straight`: straight vertical approach and retreat at pick and place;
- :mod:`.in_cell`: the cycle planned inside a cell, keeping its clearance
  (:class:`CellCycleReport`; around obstacles through :mod:`pinarms.optim.motion.transfer`);
- :mod:`.plan`: :func:`plan_cycle`, the dispatcher (``plan_cycle(CycleRequest(robot, spec, ...))``).

``from pinarms.optim.cycle import plan_cycle, PickPlace, ...`` works as before.
"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "CYCLE_KINDS": "pinarms.optim.cycle.spec",
    "CYCLE_APPROACHES": "pinarms.optim.cycle.spec",
    "CycleStatus": "pinarms.optim.cycle.spec",
    "LINE_NAMES": "pinarms.optim.cycle.spec",
    "CycleResult": "pinarms.optim.cycle.spec",
    "PickPlace": "pinarms.optim.cycle.spec",
    "CycleRequest": "pinarms.optim.cycle.request",
    "CycleTiming": "pinarms.optim.cycle.request",
    "CycleLoad": "pinarms.optim.cycle.request",
    "CycleApproach": "pinarms.optim.cycle.request",
    "CellSettings": "pinarms.optim.cycle.request",
    "plan_cycle": "pinarms.optim.cycle.plan",
    "LINE_SAMPLES": "pinarms.optim.cycle.spec",
}

__all__ = [
    "CYCLE_KINDS", "CYCLE_APPROACHES", "CycleStatus", "LINE_NAMES", "CycleResult", "PickPlace", "CycleRequest", "CycleTiming", "CycleLoad", "CycleApproach", "CellSettings", "plan_cycle",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
