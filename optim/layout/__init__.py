"""Layout search: where to bolt an arm for the most picks per minute, split by stage.

- :mod:`.candidates`: candidate base placements (grid, seeded random) and their frames;
- :mod:`.evaluate`: one candidate's cycle plans, failure classes, and one refinement start;
- :mod:`.result`: :class:`LayoutSearch` and :class:`Refinement`;
- :mod:`.search`: :func:`search_layout`, which screens, plans, ranks and refines (its module
  docstring lists the steps).

"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "FAILURES": ".search",
    "LayoutSearch": ".result",
    "Refinement": ".result",
    "base_to_world": ".candidates",
    "grid_candidates": ".candidates",
    "points_in_base_frame": ".candidates",
    "random_candidates": ".candidates",
    "search_layout": ".search",
}

__all__ = [
    "FAILURES", "LayoutSearch", "Refinement", "grid_candidates", "random_candidates", "base_to_world",
    "points_in_base_frame", "search_layout",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
