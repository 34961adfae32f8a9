"""The check every input of the line's specifications goes through: a finite number, named in the error.

Shared by the belt, the item stream, the tracking and tray specifications and :class:`~pinarms.optim.line.api.LineSpec`.
"""

from __future__ import annotations

import numpy as np

from pinarms.errors import InvalidInput

__all__ = ["finite_number"]


def finite_number(value: object, what: str, *, positive: bool = False) -> float:
    """``value`` as a float; ``what`` names it (with its unit) in the error.

    Raises:
        InvalidInput: not a finite number (a bool counts as no number), or ``positive`` and not > 0.
    """
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    x = float(value) if ok else float("nan")
    if not np.isfinite(x):
        raise InvalidInput(f"{what} must be a finite number, got {value!r}")
    if positive and x <= 0.0:
        raise InvalidInput(f"{what} must be > 0, got {value!r}")
    return x
