"""The paper-vs-pinarms table: one row per published number.

A :class:`Row` holds the paper's value, pinarms' value, the unit (the paper's: mm, deg),
an absolute tolerance and a one-line reason wherever the two differ. ``status`` is
``"agrees"`` (within the tolerance), ``"differs"`` (outside it: the note says why) or
``"n/a"`` (no comparable published number: the paper's value is qualitative or its
inputs are not printed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

__all__ = ["Row", "format_table", "markdown_table"]

Value = float | tuple[float, ...] | str | None


def _as_tuple(value: Value) -> tuple[float, ...] | None:
    if value is None or isinstance(value, str):
        return None
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    return tuple(float(v) for v in arr)


@dataclass(frozen=True)
class Row:
    """One compared number (or a small tuple of numbers, e.g. a position).

    Attributes:
        study: seed key ("000", "001", "002", "004").
        quantity: what is compared, short.
        paper: the published value (number, tuple, a qualitative string, or None).
        pinarms: the value computed here.
        unit: unit of both values.
        tolerance: absolute tolerance in ``unit`` (None: not comparable).
        note: one line: where the number comes from, or why the values differ.
    """

    study: str
    quantity: str
    paper: Value
    pinarms: Value
    unit: str = ""
    tolerance: float | None = None
    note: str = ""

    @property
    def difference(self) -> float | None:
        """max |pinarms − paper| over the tuple, or None when not comparable."""
        a, b = _as_tuple(self.paper), _as_tuple(self.pinarms)
        if a is None or b is None or len(a) != len(b):
            return None
        return float(max(abs(x - y) for x, y in zip(a, b)))

    @property
    def status(self) -> str:
        diff = self.difference
        if diff is None or self.tolerance is None:
            return "n/a"
        return "agrees" if diff <= self.tolerance else "differs"

    def as_dict(self) -> dict[str, Any]:
        def plain(v: Value) -> Any:
            t = _as_tuple(v)
            if t is None:
                return v
            return t[0] if len(t) == 1 and not isinstance(v, (tuple, list, np.ndarray)) else list(t)

        return {
            "study": self.study,
            "quantity": self.quantity,
            "paper": plain(self.paper),
            "pinarms": plain(self.pinarms),
            "unit": self.unit,
            "tolerance": self.tolerance,
            "difference": self.difference,
            "status": self.status,
            "note": self.note,
        }


def _fmt_value(value: Value, digits: int = 5) -> str:
    if value is None:
        return "—"
    if isinstance(value, str):
        return value
    t = _as_tuple(value)
    parts = [f"{v:.{digits}g}" if math.isfinite(v) else str(v) for v in t]
    return parts[0] if len(parts) == 1 and not isinstance(value, (tuple, list, np.ndarray)) else "(" + ", ".join(parts) + ")"


def _cells(row: Row) -> list[str]:
    tol = "—" if row.tolerance is None else f"{row.tolerance:g}"
    return [row.study, row.quantity, _fmt_value(row.paper), _fmt_value(row.pinarms), row.unit, tol, row.status, row.note]


HEADER = ["seed", "quantity", "paper", "pinarms", "unit", "tol", "status", "note"]


def format_table(rows: Sequence[Row], title: str = "paper vs pinarms") -> str:
    """A plain-text table for the terminal."""
    cells = [HEADER] + [_cells(r) for r in rows]
    widths = [max(len(c[i]) for c in cells) for i in range(len(HEADER) - 1)]
    lines = [title, "=" * len(title)]
    for k, c in enumerate(cells):
        lines.append("  ".join(v.ljust(w) for v, w in zip(c[:-1], widths)) + ("  " + c[-1] if c[-1] else ""))
        if k == 0:
            lines.append("  ".join("-" * w for w in widths) + "  ----")
    agree = sum(r.status == "agrees" for r in rows)
    differ = sum(r.status == "differs" for r in rows)
    na = sum(r.status == "n/a" for r in rows)
    lines.append(f"{len(rows)} rows: {agree} agree, {differ} differ (reason given), {na} not comparable")
    return "\n".join(lines)


def markdown_table(rows: Sequence[Row]) -> str:
    """The same table in GitHub markdown."""
    def esc(s: str) -> str:
        return s.replace("|", "\\|")

    lines = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    lines += ["| " + " | ".join(esc(c) for c in _cells(r)) + " |" for r in rows]
    return "\n".join(lines)
