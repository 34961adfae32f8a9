"""Statuses of the optimisers' results: enums whose value is the word printed and written to JSON.

Every big call of :mod:`optim` takes one frozen input object and returns a result whose
``status`` is a member of a :class:`Status` subclass (as toppra's
``ParameterizationReturnCode`` and ruckig's ``Result``), with ``status_reason`` saying why
where it did not succeed. The rule for what is a status and what stays an exception:

- **bad input raises** (a named exception of :mod:`optim.errors` or ``InvalidInput``, from the
  input object's ``__post_init__``, before any work): the caller must change what it asked;
- **an answer the search could not find is a status** (no placement runs the cycle, no
  number of arms meets the miss rate, the line misses more than asked): the question was
  well posed and the result says what was found and why it falls short;
- a failure of the machinery (a task failing on a cluster) raises as before
  (:class:`pinarms.execution.ExecutionError`).

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
