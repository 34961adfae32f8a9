"""Item streams on a belt: Poisson arrivals at a rate, a regular pitch, or an arrivals file.

An item is described by the time ``t0`` [s] it crosses the belt's start (``u = 0``), its
position ``w`` across the belt [m], its type (mass [kg], size [m]) and its yaw [rad] about
the belt's z. Every random stream takes a seed; the same seed gives the same items.

Arrivals file (CSV, UTF-8, header ``time,across,type,yaw``; ``yaw`` optional): one item per
row, time [s] ≥ 0 non-decreasing, across [m] on the belt, type a name of the given types.
A file larger than :data:`MAX_FILE_BYTES` or with more than :data:`MAX_ITEMS` rows is
refused; every error names the row (1 = the first data row) and the column.
"""

from __future__ import annotations

import csv
import io
import itertools
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np
from numpy.typing import ArrayLike

from pinarms.files import read_bounded
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.numbers import finite_number
from pinarms.optim.line.errors import ArrivalsFileError
from pinarms.errors import InvalidInput

__all__ = ["ItemType", "Items", "poisson_items", "regular_items", "read_arrivals", "MAX_ITEMS", "MAX_FILE_BYTES",
           "MAX_FIELD_CHARS"]

#: Largest arrivals file read [bytes] and most items in a stream.
MAX_FILE_BYTES = 64 * 1024 * 1024
MAX_ITEMS = 2_000_000


@dataclass(frozen=True)
class ItemType:
    """A kind of item: ``name``, ``mass`` [kg] (≥ 0), ``size`` (length along, width across,
    height) [m] (> 0)."""

    name: str
    mass: float = 0.1
    size: tuple[float, float, float] = (0.08, 0.05, 0.04)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name or "," in self.name:
            raise InvalidInput(f"item type name must be a non-empty string without commas, got {self.name!r}")
        m = finite_number(self.mass, f"mass [kg] of item type {self.name!r}")
        if m < 0.0:
            raise InvalidInput(f"mass [kg] of item type {self.name!r} must be >= 0, got {self.mass!r}")
        if np.ndim(self.size) != 1 or len(self.size) != 3:
            raise InvalidInput(f"size of item type {self.name!r} must be 3 numbers [m], got {self.size!r}")
        size = tuple(finite_number(s, f"size [m] of item type {self.name!r}", positive=True) for s in self.size)
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "size", size)


@dataclass(frozen=True, eq=False)
class Items:
    """A stream of items, sorted by ``t0`` (arrays of shape (N,)).

    Attributes:
        t0: time each item crosses ``u = 0`` [s]; ``w``: position across [m];
        kind: index into ``types``; ``yaw``: [rad]; ``types``: the :class:`ItemType` s.
    """

    t0: np.ndarray
    w: np.ndarray
    kind: np.ndarray
    yaw: np.ndarray
    types: tuple[ItemType, ...]

    def __len__(self) -> int:
        return int(self.t0.size)

    @property
    def mass(self) -> np.ndarray:
        return np.array([t.mass for t in self.types])[self.kind]

    @property
    def height(self) -> np.ndarray:
        return np.array([t.size[2] for t in self.types])[self.kind]

    def subset(self, index: ArrayLike) -> "Items":
        return Items(self.t0[index], self.w[index], self.kind[index], self.yaw[index], self.types)


def _checked(belt: Belt, t0: np.ndarray, w: np.ndarray, kind: np.ndarray, yaw: np.ndarray,
             types: tuple[ItemType, ...]) -> Items:
    if t0.size > MAX_ITEMS:
        raise InvalidInput(f"a stream holds at most {MAX_ITEMS} items, got {t0.size}: simulate a shorter time")
    half = np.array([t.size[1] for t in types])[kind] / 2.0
    off = np.flatnonzero(np.abs(w) + half > belt.width / 2.0 + 1e-12)
    if off.size:
        k = int(off[0])
        raise InvalidInput(f"item {k} at {w[k]:.4f} m across is off the belt (width {belt.width} m, item "
                           f"{2 * half[k]} m wide): keep |across| + width/2 <= {belt.width / 2} m")
    order = np.argsort(t0, kind="stable")
    return Items(*(a[order] for a in (t0, w, kind, yaw)), types)


def _lateral(rng: np.random.Generator, n: int, belt: Belt, types: tuple[ItemType, ...], kind: np.ndarray) -> np.ndarray:
    half = np.array([t.size[1] for t in types])[kind] / 2.0
    room = belt.width / 2.0 - half
    if np.any(room < 0.0):
        raise InvalidInput(f"an item type is wider than the belt ({belt.width} m)")
    return rng.uniform(-1.0, 1.0, n) * room


def _types(types: Sequence[ItemType] | None) -> tuple[ItemType, ...]:
    out = tuple(types) if types is not None else (ItemType("item"),)
    if not out or not all(isinstance(t, ItemType) for t in out):
        raise InvalidInput("types must be a non-empty sequence of ItemType")
    return out


def poisson_items(belt: Belt, rate: float, duration: float, *, types: Sequence[ItemType] | None = None,
                  seed: int = 0) -> Items:
    """Items arriving as a Poisson process of ``rate`` [items/s] over ``duration`` [s], each at a
    uniform random position across (within the belt), of a uniform random type, yaw uniform in [-π, π)."""
    rate = finite_number(rate, "rate [items/s]", positive=True)
    duration = finite_number(duration, "duration [s]", positive=True)
    tt = _types(types)
    expected = rate * duration
    if not expected <= MAX_ITEMS:  # inf too; checked before numpy draws or allocates
        raise InvalidInput(f"{rate:g} items/s over {duration:g} s is {expected:.3g} items expected; a stream holds "
                           f"at most {MAX_ITEMS} items: lower the rate or simulate a shorter time")
    rng = np.random.default_rng(seed)
    n = int(rng.poisson(expected))
    if n > MAX_ITEMS:
        raise InvalidInput(f"the Poisson draw gave {n} items; a stream holds at most {MAX_ITEMS} items: "
                           f"lower the rate or simulate a shorter time")
    t0 = np.sort(rng.uniform(0.0, duration, n))
    kind = rng.integers(0, len(tt), n)
    w = _lateral(rng, n, belt, tt, kind)
    yaw = rng.uniform(-np.pi, np.pi, n)
    return _checked(belt, t0, w, kind, yaw, tt)


def regular_items(belt: Belt, period: float, duration: float, *, w: float | None = None,
                  types: Sequence[ItemType] | None = None, seed: int = 0) -> Items:
    """Items every ``period`` [s] from t = 0 over ``duration`` [s] (a regular pitch of
    ``belt.speed · period`` m), all at ``w`` across (default: uniform random, seeded)."""
    period = finite_number(period, "period [s]", positive=True)
    duration = finite_number(duration, "duration [s]", positive=True)
    tt = _types(types)
    count = math.ceil(duration / period) if duration / period < 2.0 * MAX_ITEMS else math.inf
    if count > MAX_ITEMS:  # counted before numpy allocates
        raise InvalidInput(f"one item every {period:g} s over {duration:g} s is {duration / period:.3g} items; a "
                           f"stream holds at most {MAX_ITEMS} items: a longer period or a shorter time")
    rng = np.random.default_rng(seed)
    t0 = np.arange(0.0, duration, period)
    kind = np.zeros(t0.size, dtype=int)
    ww = _lateral(rng, t0.size, belt, tt, kind) if w is None else np.full(t0.size, finite_number(w, "across [m]"))
    return _checked(belt, t0, ww, kind, np.zeros(t0.size), tt)


def read_arrivals(path: str | Path, belt: Belt, types: Sequence[ItemType]) -> Items:
    """Items from an arrivals file (module doc).

    The file is read in blocks of rows, each checked at once (a row at a time only to name the
    first bad row of a block), and reading stops at the first row past :data:`MAX_ITEMS`.

    Raises:
        ArrivalsFileError: unreadable, not a regular file, too large, a missing or repeated column,
            a field over :data:`MAX_FIELD_CHARS` characters, a bad value (row and column named).
        InvalidInput: an item off the belt.
    """
    tt = _types(types)
    p = Path(path) if isinstance(path, (str, os.PathLike)) else path
    data = read_bounded(p, MAX_FILE_BYTES, "arrivals file", error=ArrivalsFileError)
    if b"\r" in data:  # csv ends a row at \r, \n or \r\n alike: one line end for the count below
        data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    lines = data.count(b"\n") + 1
    if lines > MAX_ITEMS + 1 and lines - len(_BLANK_LINE.findall(data)) > MAX_ITEMS + 1:  # counted before parsing
        raise ArrivalsFileError(f"arrivals file {p}: more than {MAX_ITEMS} rows (non-blank lines after the header); "
                                f"split the file")
    # decoded as it is parsed: the text is never held whole (a str of it can take 4 bytes a character)
    reader = csv.reader(io.TextIOWrapper(io.BytesIO(data), encoding="utf-8-sig", newline=""))
    header = [h.strip() for h in (_block(reader, p, 1) or [[]])[0]]
    for col in ("time", "across", "type"):
        if col not in header:
            raise ArrivalsFileError(f"arrivals file {p}: header lacks column {col!r} (need time,across,type[,yaw])")
    seen = set()
    for h in header:
        if h in seen:
            raise ArrivalsFileError(f"arrivals file {p}: the header names column {h!r} twice; name each column once")
        seen.add(h)
    table = _Table(p, {h: i for i, h in enumerate(header)}, belt, tt)
    r = 0  # data rows before the block, blank ones included (1 = the first data row)
    while chunk := _block(reader, p, _BLOCK_ROWS):
        table.add(r + 1, chunk)
        r += len(chunk)
    return _checked(belt, *table.arrays(), tt)


#: A line of an arrivals file that holds no value (blank, or only separators).
_BLANK_LINE = re.compile(rb"^[ \t\f\v,]*$", re.MULTILINE)
#: Rows checked together by :func:`read_arrivals`.
_BLOCK_ROWS = 65_536
#: Longest field of an arrivals file [characters] (the ``csv`` module's own limit).
MAX_FIELD_CHARS = csv.field_size_limit()


def _block(reader: Any, p: Any, n: int) -> list[list[str]]:
    """The next ``n`` rows of a CSV reader (fewer at the end); csv's and UTF-8's errors named by row."""
    try:
        return list(itertools.islice(reader, n))
    except csv.Error as exc:
        what = f"a field longer than {MAX_FIELD_CHARS} characters" if "field larger" in str(exc) else str(exc)
        raise ArrivalsFileError(f"arrivals file {p}, row {reader.line_num - 1}: {what}; this is not an arrivals "
                                f"list") from None
    except UnicodeDecodeError:
        raise ArrivalsFileError(f"arrivals file {p}: not UTF-8 text (near row {reader.line_num}); save it as "
                                f"UTF-8") from None


class _Table:
    """The columns of an arrivals file, filled a block of rows at a time (:func:`read_arrivals`)."""

    def __init__(self, p: Any, idx: dict[str, int], belt: Belt, types: tuple[ItemType, ...]) -> None:
        self.p, self.idx, self.belt, self.types = p, idx, belt, types
        self.names = {t.name: k for k, t in enumerate(types)}
        self.half = np.array([t.size[1] for t in types]) / 2.0
        self.parts: list[np.ndarray] = []
        self.count = 0
        self.last = 0.0

    def add(self, first: int, chunk: list[list[str]]) -> None:
        """Check the rows ``chunk`` (numbered from ``first``) at once; on any fault, row by row, to
        name the first bad row. Blank rows are skipped; past :data:`MAX_ITEMS` rows, refused."""
        rows = [row for row in chunk if "".join(row).strip()]
        if self.count + len(rows) > MAX_ITEMS:
            r = first + [k for k, row in enumerate(chunk) if "".join(row).strip()][MAX_ITEMS - self.count]
            raise ArrivalsFileError(f"arrivals file {self.p}: more than {MAX_ITEMS} rows (row {r}); split the file")
        self.count += len(rows)
        try:
            a = self._fast(rows) if rows else np.zeros((0, 4))
        except (ValueError, KeyError, IndexError):
            a = None
        if a is None:  # raises at the first bad row
            a = np.array([self._row(first + k, row) for k, row in enumerate(chunk) if "".join(row).strip()],
                         dtype=float).reshape(-1, 4)
        self.parts.append(a)
        if a.size:
            self.last = float(a[-1, 0])

    def _fast(self, rows: list[list[str]]) -> np.ndarray | None:
        n_cols, n = len(self.idx), len(rows)
        if any(len(row) != n_cols for row in rows):
            return None
        col = {h: [row[i] for row in rows] for h, i in self.idx.items()}
        t = np.fromiter(map(float, col["time"]), float, n)
        w = np.fromiter(map(float, col["across"]), float, n)
        yaw = np.fromiter(map(float, col["yaw"]), float, n) if "yaw" in col else np.zeros(n)
        kind = np.fromiter((self.names[k.strip()] for k in col["type"]), float, n)
        good = (np.all(np.isfinite(t)) and np.all(np.isfinite(w)) and np.all(np.isfinite(yaw)) and t[0] >= self.last
                and np.all(np.diff(t) >= 0.0)
                and np.all(np.abs(w) + self.half[kind.astype(int)] <= self.belt.width / 2.0 + 1e-12))
        return np.column_stack([t, w, kind, yaw]) if good else None

    def _row(self, r: int, row: list[str]) -> tuple[float, float, int, float]:
        """One row checked: ``(time, across, type, yaw)`` (else ArrivalsFileError naming it and the column)."""
        p, idx, tt = self.p, self.idx, self.types
        if len(row) != len(idx):
            raise ArrivalsFileError(f"arrivals file {p}, row {r}: {len(row)} columns, the header has {len(idx)}")

        def num(col: str) -> float:
            try:
                x = float(row[idx[col]])
            except ValueError:
                raise ArrivalsFileError(f"arrivals file {p}, row {r}, column {col!r}: "
                                        f"{row[idx[col]]!r} is not a number") from None
            if not np.isfinite(x):
                raise ArrivalsFileError(f"arrivals file {p}, row {r}, column {col!r}: {x} is not finite")
            return x

        t = num("time")
        if t < 0.0 or t < self.last:
            raise ArrivalsFileError(f"arrivals file {p}, row {r}, column 'time': {t} s must be >= 0 and not "
                                    f"before the previous row ({self.last} s)")
        self.last = t
        kind = row[idx["type"]].strip()
        if kind not in self.names:
            raise ArrivalsFileError(f"arrivals file {p}, row {r}, column 'type': unknown type {kind!r}; "
                                    f"known: {sorted(self.names)}")
        yaw = num("yaw") if "yaw" in idx else 0.0
        w = num("across")
        if abs(w) + tt[self.names[kind]].size[1] / 2.0 > self.belt.width / 2.0 + 1e-12:
            raise ArrivalsFileError(f"arrivals file {p}, row {r}, column 'across': the item at {w} m is off the "
                                    f"belt (width {self.belt.width} m, item {tt[self.names[kind]].size[1]} m wide)")
        return t, w, self.names[kind], yaw

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(t0, w, kind, yaw)`` of every row read."""
        a = np.concatenate(self.parts) if self.parts else np.zeros((0, 4))
        return a[:, 0], a[:, 1], a[:, 2].astype(int), a[:, 3]
