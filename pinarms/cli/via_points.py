"""Via points of the trajectory commands: from ``--via``/``--times`` options, or a CSV or JSON file.

A via-point file (:func:`read_via_file`) is JSON ``{"times": [...], "positions": [[...], ...],
"kind": ..., "degree": ...}`` or a CSV with a header row (a ``t``/``time`` column of knot
times, one column per joint); a bad cell, row or key is an :class:`InvalidInput` naming the
file, the row and the column.
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import Any

import click
import numpy as np

from pinarms.files import read_bounded_text
from pinarms.errors import InvalidInput

from pinarms.cli._common import floats

__all__ = ["TRAJECTORY_KINDS", "read_via_file", "via_input"]

#: Largest via-point file read [bytes].
MAX_VIA_FILE_BYTES = 16 * 2**20

#: Trajectory kinds of ``pinarms plan --kind`` (and of a via-point file's ``kind``).
TRAJECTORY_KINDS = ("3-5-3", "multi-quintic", "quintic-bspline", "polynomial", "piecewise")


def read_via_file(path: str) -> dict[str, Any]:
    """Via points from a JSON or CSV file.

    JSON: ``{"times": [...], "positions": [[...], ...], "kind": ..., "degree": ...}``
    (``times``/``kind`` optional). CSV: a header row; a column named ``t`` or ``time``
    holds knot times, every other column is one joint; one row per via point.
    """
    file = Path(path)
    text = read_bounded_text(file, MAX_VIA_FILE_BYTES, "via-point file")  # a regular file: a FIFO never blocks
    if file.suffix.lower() == ".json":
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InvalidInput(f"{path}: not valid JSON ({exc.msg}, line {exc.lineno})") from None
        if not isinstance(doc, dict) or "positions" not in doc:
            raise InvalidInput(f"{path}: expected an object with 'positions' (and optional 'times', 'kind')")
        return _checked_via_doc(doc, path)
    reader = csv.reader(io.StringIO(text))
    numbered = [(reader.line_num, r) for r in reader if any(c.strip() for c in r)]  # line numbers of the file
    lines, rows = [n for n, _ in numbered], [r for _, r in numbered]
    if len(rows) < 3:
        raise InvalidInput(f"{path}: a CSV needs a header row and at least two via points")
    header = [h.strip().lower() for h in rows[0]]
    table = _csv_numbers(rows, lines, path)
    doc: dict[str, Any] = {}
    time_cols = [i for i, h in enumerate(header) if h in ("t", "time", "time_s", "t_s")]
    if time_cols:
        doc["times"] = table[:, time_cols[0]]
    joints = [i for i in range(len(header)) if i not in time_cols]
    doc["positions"] = table[:, joints]
    doc["joint_names"] = [rows[0][i].strip() for i in joints]
    return doc


def _csv_numbers(rows: list[list[str]], lines: list[int], path: str) -> np.ndarray:
    """The cells after the header row as a float table, or InvalidInput naming the row and column.

    A row is named by its line in the file (``lines``: the header is usually row 1), a
    column by its number (from 1) and its header.
    """
    header = rows[0]
    table = np.empty((len(rows) - 1, len(header)))
    for k, (r, row) in enumerate(zip(lines[1:], rows[1:])):
        if len(row) != len(header):
            raise InvalidInput(f"{path}: CSV row {r} has {len(row)} cells, the header has {len(header)} "
                               f"({', '.join(h.strip() for h in header)})")
        for c, cell in enumerate(row):
            try:
                value = float(cell)
            except ValueError:
                value = float("nan")
            if not np.isfinite(value):
                raise InvalidInput(f"{path}: CSV row {r}, column {c + 1} ({header[c].strip()!r}): "
                                   f"{cell.strip()!r} is not a finite number")
            table[k, c] = value
    return table


def _checked_via_doc(doc: dict[str, Any], path: str) -> dict[str, Any]:
    """A JSON via-point document with numeric arrays and a known kind, or InvalidInput."""
    out = dict(doc)
    for key, ndim in (("positions", 2), ("times", 1)):
        if out.get(key) is None:
            continue
        try:
            arr = np.asarray(out[key], dtype=float)
        except (TypeError, ValueError):
            raise InvalidInput(f"{path}: '{key}' must be {'rows of ' if ndim == 2 else 'a list of '}numbers "
                               f"(one {'row' if ndim == 2 else 'value'} per via point)") from None
        if key == "positions" and arr.ndim == 1:
            arr = arr[:, None]
        if arr.ndim != ndim:
            raise InvalidInput(f"{path}: '{key}' must be a {ndim}-D list of numbers, got shape {arr.shape}")
        out[key] = arr
    kind = out.get("kind")
    if kind is not None and kind not in TRAJECTORY_KINDS:
        raise InvalidInput(f"{path}: unknown 'kind' {kind!r}; use one of {', '.join(TRAJECTORY_KINDS)}")
    degree = out.get("degree")
    if degree is not None and (isinstance(degree, bool) or not isinstance(degree, int)):
        raise InvalidInput(f"{path}: 'degree' must be a whole number (3, 5 or 7), got {degree!r}")
    return out


def via_input(via: tuple[str, ...], times: str | None, file: str | None) -> tuple[np.ndarray | None, np.ndarray, dict]:
    """(times or None, positions (m+1, n_joints), extra file options)."""
    if file and via:
        raise click.UsageError("give via points either with --via or with --file, not both")
    extra: dict = {}
    if file:
        doc = read_via_file(file)
        positions = np.asarray(doc["positions"], dtype=float)
        t = None if doc.get("times") is None else np.asarray(doc["times"], dtype=float)
        extra = {k: v for k, v in doc.items() if k not in ("positions", "times")}
    elif via:
        points = [floats(v, "--via") for v in via]
        if len({p.size for p in points}) != 1:
            raise InvalidInput(f"every --via must have the same number of joint values, got sizes {[p.size for p in points]}")
        positions = np.vstack(points)
        t = None
    else:
        raise click.UsageError("give via points with --via (repeat it, one point each) or --file")
    if times is not None:
        t = floats(times, "--times")
    if positions.ndim == 1:
        positions = positions[:, None]
    if positions.shape[0] < 2:
        raise InvalidInput(f"need at least two via points, got {positions.shape[0]}")
    return t, positions, extra
