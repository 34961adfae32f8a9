"""Statuses of the optimisers' results: enums whose value is the word printed and written to JSON.

Every big call of :mod:`pinarms.optim` takes one frozen input object (checked in its
``__post_init__``) and returns a result whose ``status`` is a member of a :class:`Status`
subclass (as toppra's ``ParameterizationReturnCode`` and ruckig's ``Result``), with
``status_reason`` saying why where it did not fully succeed:

========================  ==========================  =============================================
call                      input                       status
========================  ==========================  =============================================
``run_line``              ``LineSpec``                ``LineStatus`` (ok, misses above target)
``size_line``             ``SizingProblem``           ``SizingStatus`` (ok, not found)
``search_layout``         ``LayoutRequest``           ``LayoutStatus`` (found, no placement);
                                                      ``CandidateFailure`` per candidate
``minimize_time``         ``TimingRequest``           ``TimingStatus`` (solved, or why the GA stopped)
``minimize_time_jerk``    ``TimingRequest``           (its ``TimeJerkResult``; raises as below)
``run_ga``                ``GARequest``               ``GAStop`` (``GAResult.stop_reason``)
``build_task_map``        ``MapRequest``              ``MapStatus`` (built, refine left, no feasible
                                                      node); ``build_tray_map``, ``build_delta_map``
                                                      take ``TrayMapRequest``, ``DeltaMapRequest``
========================  ==========================  =============================================

The rule for what is a status and what stays an exception:

- **bad input raises** (a named exception of :mod:`pinarms.optim.errors` or ``InvalidInput``, from the
  input object's ``__post_init__``, before any work): the caller must change what it asked;
- **an answer that falls short is a status**: the call has something to return (the ranking
  of every candidate, the best line tried, a feasible timing from a GA stopped early) and
  the status says how far it got and why (no placement runs the cycle, no number of arms
  meets the miss rate, the line misses more than asked, the GA hit its time limit);
- **no answer at all raises**: where the call cannot build the object it promises (no timing
  within the bounds meets the limits, so there is no trajectory) it raises a named exception
  (:class:`~pinarms.optim.errors.InfeasibleProblem`), listed in its docstring;
- a failure of the machinery (a task failing on a cluster) raises
  (:class:`pinarms.errors.ExecutionError`).

Where the work runs (``scheduler``) and how it reports (``progress``, ``callback``) are
keywords of the call, not fields of the input: they never change the result.

A status compares equal to its word (``status == "ok"``) and formats as it
(``f"{status}"``), so printed tables and JSON files keep their words.
"""

from __future__ import annotations

from enum import Enum

__all__ = ["Status"]


class Status(str, Enum):
    """Base of the status enums: the member's value is its printed word."""

    def __str__(self) -> str:
        return str(self.value)

    def __format__(self, spec: str) -> str:
        return format(str(self.value), spec)
