"""Errors of the line family: a belt an arm cannot reach, a malformed arrivals file."""

from __future__ import annotations

from pinarms.robots.errors import InvalidInput, UnreachableTarget

__all__ = ["BeltOutOfReach", "ArrivalsFileError"]


class BeltOutOfReach(UnreachableTarget):
    """An arm of the line reaches no point of the belt (the message names the arm and the
    belt point nearest to its reach)."""


class ArrivalsFileError(InvalidInput):
    """A malformed arrivals file (the message names the row and the column)."""
