"""Layout search: where to bolt an arm for the most picks per minute, split by stage.

- :mod:`.request`: :class:`LayoutRequest` (what is asked, checked when built) and :class:`LayoutStatus`;
- :mod:`.candidates`: candidate base placements (grid, seeded random), their frames, :class:`CandidateFailure`;
- :mod:`.evaluate`: one candidate's cycle plans, failure classes, and one refinement start;
- :mod:`.result`: :class:`LayoutSearch` and :class:`Refinement`;
- :mod:`.search`: :func:`search_layout`, which screens, plans, ranks and refines (its module
  docstring lists the steps).

"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "FAILURES": "pinarms.optim.layout.search",
    "CandidateFailure": "pinarms.optim.layout.search",
    "LayoutRequest": "pinarms.optim.layout.search",
    "LayoutSearch": "pinarms.optim.layout.search",
    "LayoutStatus": "pinarms.optim.layout.search",
    "Refinement": "pinarms.optim.layout.search",
    "base_to_world": "pinarms.optim.layout.search",
    "grid_candidates": "pinarms.optim.layout.search",
    "points_in_base_frame": "pinarms.optim.layout.search",
    "random_candidates": "pinarms.optim.layout.search",
    "search_layout": "pinarms.optim.layout.search",
}

__all__ = [
    "FAILURES", "CandidateFailure", "LayoutRequest", "LayoutStatus", "LayoutSearch", "Refinement",
    "grid_candidates", "random_candidates", "base_to_world", "points_in_base_frame", "search_layout",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
