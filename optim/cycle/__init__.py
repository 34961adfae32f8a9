"""The pick-and-place cycle: one spec in (:class:`PickPlace`), one call (:func:`plan_cycle`), one result out.

- :mod:`.spec`: the spec and the result (:class:`PickPlace`, :class:`CycleResult`) and the
  helpers every way of planning a cycle shares;
- :mod:`.plan`: :func:`plan_cycle`, the dispatcher: joint-space transfers here, or
- :mod:`.straight`: straight vertical approach and retreat at pick and place;
- :mod:`.in_cell`: the cycle planned inside a cell, keeping its clearance
  (:class:`CellCycleReport`; around obstacles through :mod:`optim.motion.cycle`).

``from pinarms.optim.cycle import plan_cycle, PickPlace, ...`` works as before; the old paths
``pinarms.optim.cell_cycle`` and ``pinarms.optim.straight_approach`` are the same module objects
as :mod:`.in_cell` and :mod:`.straight`.
"""

from .plan import *  # noqa: F401,F403
from .plan import __all__
from .spec import LINE_SAMPLES, _hold, _line_deviation, _segment_distance  # noqa: F401  (old import paths)
