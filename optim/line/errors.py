"""Errors of the line family: a belt an arm cannot reach, a malformed arrivals file or task map."""

from __future__ import annotations

from pinarms.errors import InvalidInput, UnreachableTarget

__all__ = ["BeltOutOfReach", "ArrivalsFileError", "TaskMapError"]


class BeltOutOfReach(UnreachableTarget):
    """An arm of the line reaches no point of the belt (the message names the arm and the
    belt point nearest to its reach)."""


class ArrivalsFileError(InvalidInput):
    """A malformed arrivals file (the message names the row and the column)."""


class TaskMapError(InvalidInput):
    """A task map that cannot be right (a grid not strictly increasing, a time negative or past
    the bound, a size past the cap), or a task map file that is malformed, too large or fails its
    checksum (the message names the map or the file and the field)."""
