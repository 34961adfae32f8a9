"""What a kind of session content declares and what its decoder reads: array and text fields, and the item view.

:class:`ArraySpec` and :class:`TextSpec` describe an item's arrays and text members in the table of
kinds (:data:`pinarms.viz.session_schema.KINDS`); :class:`SessionItemView` is what a kind's decoder
reads from one item while a file is read (:class:`pinarms.viz.session_document.SessionItem`). The
schema, the archive reader and the document reader all import this module, which imports none of
them: no circle, not even through imports for type checkers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

__all__ = ["ArraySpec", "TextSpec", "SessionItemView"]


@dataclass(frozen=True)
class ArraySpec:
    """An array field of an item: ``shape`` entries are ints (fixed), or names of dimensions.

    A named dimension takes the first value met in the item and every other use must
    repeat it; ``"nq"`` is bound to the joint count of the item's robot. ``min_rows``
    bounds the first dimension from below. ``columns=True``: the field is a JSON object of
    named arrays of this shape (history columns), ``required`` names those that must exist.
    """

    field: str
    shape: tuple[int | str, ...]
    allow_inf: bool = False
    min_rows: int = 0
    columns: bool = False
    required: tuple[str, ...] = ()


@dataclass(frozen=True)
class TextSpec:
    """A text member of an item (UTF-8), referenced by the JSON field ``field`` (or null when ``optional``)."""

    field: str
    member: str  # pattern with {i}
    xml: bool = False


class SessionItemView(Protocol):
    """One item of a section while it is read, as a decoder sees it (its arrays and texts already read)."""

    where: str
    key: str
    obj: dict
    robot: str | None
    joint_names: tuple[str, ...]
    arrays: dict[str, Any]
    texts: dict[str, str | None]

    def fail(self, what: str) -> Exception:
        """The error naming the file and ``what`` is wrong with this item."""
        ...

    def field(self, key: str, types: type | tuple) -> Any:
        """The item's JSON field ``key``, of one of ``types``."""
        ...
