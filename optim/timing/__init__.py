"""Segment timing: the durations of a trajectory's segments under limits.

- :mod:`.segments`: :func:`minimize_time` (GA, then the exact solver and polishing;
  :class:`TimingResult`), re-exported here, so ``from pinarms.optim.timing import
  minimize_time`` works as before;
- :mod:`.exact` (:func:`solve_exact`: the exact minimum-time durations), :mod:`.time_jerk`
  (:func:`minimize_time_jerk`: time and jerk traded), :mod:`.reference` (independent
  references: double-S, path velocity, toppra and ruckig limits).

"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "TimingResult": "pinarms.optim.timing.segments",
    "minimize_time": "pinarms.optim.timing.segments",
    "finish_timing": "pinarms.optim.timing.segments",
    "rescale_to_limits": "pinarms.optim.timing.segments",
}

__all__ = [
    "TimingResult", "minimize_time", "finish_timing", "rescale_to_limits",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
