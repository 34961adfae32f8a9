"""Layout search: where to bolt an arm for the most picks per minute, split by stage.

- :mod:`.request`: :class:`LayoutRequest` (what is asked, checked when built) and :class:`LayoutStatus`;
- :mod:`.candidates`: candidate base placements (grid, seeded random), their frames, :class:`CandidateFailure`;
- :mod:`.evaluate`: one candidate's cycle plans, failure classes, and one refinement start;
- :mod:`.result`: :class:`LayoutSearch` and :class:`Refinement`;
- :mod:`.search`: :func:`search_layout`, which screens, plans, ranks and refines (its module
  docstring lists the steps).

"""

from .search import (FAILURES, CandidateFailure, LayoutRequest, LayoutSearch, LayoutStatus, Refinement, base_to_world,
                     grid_candidates, points_in_base_frame, random_candidates, search_layout)

__all__ = ["FAILURES", "CandidateFailure", "LayoutRequest", "LayoutStatus", "LayoutSearch", "Refinement",
           "grid_candidates", "random_candidates", "base_to_world", "points_in_base_frame", "search_layout"]
