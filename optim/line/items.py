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
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from pinarms.optim.line.belt import Belt, _number
from pinarms.optim.line.errors import ArrivalsFileError
from pinarms.robots.errors import InvalidInput

__all__ = ["ItemType", "Items", "poisson_items", "regular_items", "read_arrivals", "MAX_ITEMS", "MAX_FILE_BYTES"]

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
        m = _number(self.mass, f"mass [kg] of item type {self.name!r}")
        if m < 0.0:
            raise InvalidInput(f"mass [kg] of item type {self.name!r} must be >= 0, got {self.mass!r}")
        if np.ndim(self.size) != 1 or len(self.size) != 3:
            raise InvalidInput(f"size of item type {self.name!r} must be 3 numbers [m], got {self.size!r}")
        size = tuple(_number(s, f"size [m] of item type {self.name!r}", positive=True) for s in self.size)
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

    def subset(self, index: Any) -> "Items":
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
    rate = _number(rate, "rate [items/s]", positive=True)
    duration = _number(duration, "duration [s]", positive=True)
    tt = _types(types)
    rng = np.random.default_rng(seed)
    n = int(rng.poisson(rate * duration))
    t0 = np.sort(rng.uniform(0.0, duration, n))
    kind = rng.integers(0, len(tt), n)
    w = _lateral(rng, n, belt, tt, kind)
    yaw = rng.uniform(-np.pi, np.pi, n)
    return _checked(belt, t0, w, kind, yaw, tt)


def regular_items(belt: Belt, period: float, duration: float, *, w: float | None = None,
                  types: Sequence[ItemType] | None = None, seed: int = 0) -> Items:
    """Items every ``period`` [s] from t = 0 over ``duration`` [s] (a regular pitch of
    ``belt.speed · period`` m), all at ``w`` across (default: uniform random, seeded)."""
    period = _number(period, "period [s]", positive=True)
    duration = _number(duration, "duration [s]", positive=True)
    tt = _types(types)
    rng = np.random.default_rng(seed)
    t0 = np.arange(0.0, duration, period)
    kind = np.zeros(t0.size, dtype=int)
    ww = _lateral(rng, t0.size, belt, tt, kind) if w is None else np.full(t0.size, _number(w, "across [m]"))
    return _checked(belt, t0, ww, kind, np.zeros(t0.size), tt)


def read_arrivals(path: str | Path, belt: Belt, types: Sequence[ItemType]) -> Items:
    """Items from an arrivals file (module doc).

    Raises:
        ArrivalsFileError: unreadable, too large, a missing column, a bad value (row and column named).
        InvalidInput: an item off the belt.
    """
    tt = _types(types)
    names = {t.name: k for k, t in enumerate(tt)}
    p = Path(path)
    try:
        if p.stat().st_size > MAX_FILE_BYTES:
            raise ArrivalsFileError(f"arrivals file {p} is larger than {MAX_FILE_BYTES} bytes")
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ArrivalsFileError(f"cannot read arrivals file {p}: {exc}") from None
    reader = csv.reader(io.StringIO(text))
    header = [h.strip() for h in next(reader, [])]
    for col in ("time", "across", "type"):
        if col not in header:
            raise ArrivalsFileError(f"arrivals file {p}: header lacks column {col!r} (need time,across,type[,yaw])")
    idx = {h: i for i, h in enumerate(header)}
    rows: list[tuple[float, float, int, float]] = []
    last = 0.0
    for r, row in enumerate(reader, start=1):
        if not row or all(not c.strip() for c in row):
            continue
        if len(rows) >= MAX_ITEMS:
            raise ArrivalsFileError(f"arrivals file {p}: more than {MAX_ITEMS} rows")
        if len(row) != len(header):
            raise ArrivalsFileError(f"arrivals file {p}, row {r}: {len(row)} columns, the header has {len(header)}")

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
        if t < 0.0 or t < last:
            raise ArrivalsFileError(f"arrivals file {p}, row {r}, column 'time': {t} s must be >= 0 and not "
                                    f"before the previous row ({last} s)")
        last = t
        kind = row[idx["type"]].strip()
        if kind not in names:
            raise ArrivalsFileError(f"arrivals file {p}, row {r}, column 'type': unknown type {kind!r}; "
                                    f"known: {sorted(names)}")
        yaw = num("yaw") if "yaw" in idx else 0.0
        w = num("across")
        if abs(w) + tt[names[kind]].size[1] / 2.0 > belt.width / 2.0 + 1e-12:
            raise ArrivalsFileError(f"arrivals file {p}, row {r}, column 'across': the item at {w} m is off the "
                                    f"belt (width {belt.width} m, item {tt[names[kind]].size[1]} m wide)")
        rows.append((t, w, names[kind], yaw))
    a = np.array(rows, dtype=float).reshape(-1, 4)
    return _checked(belt, a[:, 0], a[:, 1], a[:, 2].astype(int), a[:, 3], tt)
