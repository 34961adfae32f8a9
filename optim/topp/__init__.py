"""Time-optimal timing along a path (TOPP-RA): the profile algorithm and the path timing built on it.

- :mod:`.profile`: the reachability-analysis algorithm alone (:func:`topp_profile`: controllable
  sets, greedy forward pass, interpolated rows), re-exported here, so
  ``from pinarms.optim.topp import topp_profile`` works as before;
- :mod:`.path_timing`: :func:`time_optimal` and :func:`time_scaled` of a joint path under a list
  of limits (:class:`PathTiming`).

The old path ``pinarms.optim.path_timing`` keeps working (the same module object).
"""

from . import profile as _profile
from .profile import *  # noqa: F401,F403

__all__ = list(_profile.__all__)
