"""Segment timing: the durations of a trajectory's segments under limits.

- :mod:`.segments`: :func:`minimize_time` (GA, then the exact solver and polishing;
  :class:`TimingResult`), re-exported here, so ``from pinarms.optim.timing import
  minimize_time`` works as before;
- :mod:`.exact` (:func:`solve_exact`: the exact minimum-time durations), :mod:`.time_jerk`
  (:func:`minimize_time_jerk`: time and jerk traded), :mod:`.reference` (independent
  references: double-S, path velocity, toppra and ruckig limits).

"""

from . import segments as _segments
from .segments import *  # noqa: F401,F403

__all__ = list(_segments.__all__)
