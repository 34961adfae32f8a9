"""The pick-and-place cycle: one request in (:class:`CycleRequest`), one call (:func:`plan_cycle`), one result out.

- :mod:`.spec`: the task and the result (:class:`PickPlace`, :class:`CycleResult` with its
  ``status``) and the helpers every way of planning a cycle shares;
- :mod:`.request`: :class:`CycleRequest` and its settings groups (:class:`CycleTiming`,
  :class:`CycleLoad`, :class:`CycleApproach`, :class:`CellSettings`), checked when built;
- :mod:`.joint`: the joint-space cycle (IK on one branch, time-optimal moves);
- :mod:`.straight`: straight vertical approach and retreat at pick and place;
- :mod:`.in_cell`: the cycle planned inside a cell, keeping its clearance
  (:class:`CellCycleReport`; around obstacles through :mod:`optim.motion.transfer`);
- :mod:`.plan`: :func:`plan_cycle`, the dispatcher (``plan_cycle(CycleRequest(robot, spec, ...))``).

``from pinarms.optim.cycle import plan_cycle, PickPlace, ...`` works as before.
"""

from .plan import *  # noqa: F401,F403
from .plan import __all__
from .spec import LINE_SAMPLES, _hold, _line_deviation, _segment_distance  # noqa: F401  (old import paths)
