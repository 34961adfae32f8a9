"""Time-optimal timing along a path (TOPP-RA): the profile algorithm and the path timing built on it.

- :mod:`.profile`: the reachability-analysis algorithm alone (:func:`topp_profile`: controllable
  sets, greedy forward pass, interpolated rows), re-exported here, so
  ``from pinarms.optim.topp import topp_profile`` works as before;
- :mod:`.path_timing`: :func:`time_optimal` and :func:`time_scaled` of a joint path under a list
  of limits (:class:`PathTiming`), built from :mod:`.grid` (the grid of a section, the profile
  checked and refined), :mod:`.dense_check` (rows between grid points, exact joint peaks) and
  :mod:`.time_law` (s(t) as a piecewise polynomial, its smoothing, q(s(t)) composed exactly);
- :mod:`.row_bounds`: the rows as bounds on the state; :mod:`._profile_kernel`: the profile's loops, compiled.

"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "Profile": "pinarms.optim.topp.profile",
    "feasible_states": "pinarms.optim.topp.profile",
    "controllable_sets": "pinarms.optim.topp.profile",
    "greedy_profile": "pinarms.optim.topp.profile",
    "interpolated_rows": "pinarms.optim.topp.profile",
    "topp_profile": "pinarms.optim.topp.profile",
    "reachability_profile": "pinarms.optim.topp.profile",
    "X_CAP": "pinarms.optim.topp.profile",
}

__all__ = [
    "Profile", "feasible_states", "controllable_sets", "greedy_profile", "interpolated_rows", "topp_profile",
    "reachability_profile", "X_CAP",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
