"""What a line engineer looks at, written in one call: a session, its standalone page, the schedule plot.

Sits above the session, the HTML export and the plots (:mod:`pinarms.viz.line_session` only adds a
line to a session it is handed, so it imports none of them).
"""

from __future__ import annotations

from typing import Any, TYPE_CHECKING

from pinarms.viz.html import export_html
from pinarms.viz.line_plots import plot_line_schedule
from pinarms.viz.line_session import DEFAULT_WINDOW_S, add_line
from pinarms.viz.session import Session

if TYPE_CHECKING:
    from pinarms.optim.line.api import LineResult, LineSpec
    from pinarms.optim.line.schedule import LineSchedule

__all__ = ["save_line_views"]


def save_line_views(spec: LineSpec, result: LineResult, *, session: Session | None = None, html: Any = None, schedule: LineSchedule | None = None,
                    title: str | None = None, run: int = 0, duration: float = DEFAULT_WINDOW_S) -> list:
    """Write what a line engineer looks at: the session (``.pinarms``), its standalone page
    (``.html``) and the schedule plot (``.png``/``.svg``) of run ``run``, window [0, ``duration``] s
    for the animation and [0, 3 × ``duration``] s for the schedule; each path optional. Returns the paths written."""
    written = []
    if session is not None or html is not None:
        s = Session(title=title or f"belt line: {len(spec.stations)} arm(s), {60.0 * spec.stream.rate_per_s:g} items/min, "
                                   f"belt {spec.belt.speed:g} m/s")
        add_line(s, spec, result, run=run, duration=duration)
        if session is not None:
            written.append(s.save(session))
        if html is not None:
            written.append(export_html(s, html))
    if schedule is not None:
        written.append(plot_line_schedule(schedule, result, run=run, window=(0.0, 3.0 * duration)))
    return written
