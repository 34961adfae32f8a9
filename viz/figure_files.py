"""Writing a matplotlib figure to a file, and the checked numbers every plot draws.

Figures are drawn on matplotlib's Agg canvas directly (no pyplot state, the user's backend
is left alone) and written atomically as ``.png`` or ``.svg`` (an ``.svg`` without its date,
so that the same figure gives the same bytes).
"""

from __future__ import annotations

import io
from pathlib import Path


import numpy as np
from numpy.typing import ArrayLike
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from pinarms.files import atomic_write
from pinarms.errors import InvalidInput

__all__ = ["save_figure", "checked_numbers"]

_FORMATS = {".png": "png", ".svg": "svg"}


def save_figure(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` to ``path`` (``.png`` or ``.svg``, 120 dpi, tight) atomically; return the path."""
    p = Path(path)
    fmt = _FORMATS.get(p.suffix.lower())
    if fmt is None:
        raise InvalidInput(f"plot path {str(p)!r} must end in .png or .svg")
    buf = io.BytesIO()
    FigureCanvasAgg(fig)
    fig.savefig(buf, format=fmt, dpi=120, bbox_inches="tight", metadata={"Date": None} if fmt == "svg" else None)
    data = buf.getvalue()
    return atomic_write(p, lambda f: f.write(data))


def checked_numbers(values: ArrayLike, what: str, allow_inf: bool = False) -> np.ndarray:
    """``values`` as a finite float array (±inf kept if ``allow_inf``), or InvalidInput naming ``what``."""
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be numbers, got {type(values).__name__}") from exc
    if np.any(np.isnan(arr)) if allow_inf else not np.all(np.isfinite(arr)):
        raise InvalidInput(f"{what} holds NaN{'' if allow_inf else ' or infinite'} values")
    return arr
