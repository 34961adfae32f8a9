"""A belt line in a session: the belt, the items on it and what became of each, ready to animate.

A :class:`LineRecord` keeps what the viewer needs to animate a window of a simulated line
(:mod:`pinarms.optim.line`): the belt (its pose ``belt_to_world``: ``u`` along the belt from its
start, ``w`` across to the left, ``z`` up from the surface; its length, width, thickness and
speed), the arms (keys of the session's robots, whose trajectories move them through their
picks) and one row per item (:data:`ITEM_COLUMNS`):

- ``t0`` [s] when it crosses ``u = 0``, ``w`` [m] across, ``yaw`` [rad], its ``length``,
  ``width``, ``height`` [m];
- ``arm``: the index of the arm that picks it in ``arms``, :data:`MISSED` (it leaves the
  last window at ``u_miss`` unpicked: drawn red from there) or :data:`NOT_DRAWN` (picked in
  the simulation, but its pick could not be replanned exactly for the picture: it stays on
  the belt, not marked);
- ``t_grasp`` [s]: the gripper has closed and the tool lifts the item; ``t_release`` [s]: the
  tool is at the box and lets go (both 0 unless picked).

Times are those of the animation (0 = the start of the window shown). In ``session.json`` it
is an item of the optional section ``"lines"`` (a row of :data:`pinarms.viz.session_format.KINDS`;
absent when a session holds no line, so older files and readers are unaffected). Hostile
files: every JSON number is checked finite and in range, the item table's shape, its
values (sizes > 0, items on the belt, arm indices, ordered times) and its row count
(at most :data:`MAX_LINE_ITEMS`) are checked, and :class:`SessionFormatError` names the
field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pinarms.errors import InvalidInput

from pinarms.viz.names import NAME_RE

__all__ = ["LineRecord", "BOX_DEPTH", "ITEM_COLUMNS", "MISSED", "NOT_DRAWN", "MAX_LINE_ITEMS", "MAX_LINE_ARMS",
           "MAX_LINE_LENGTH", "check_line", "encode_line", "decode_line"]

ITEM_COLUMNS = ("t0", "w", "yaw", "length", "width", "height", "arm", "t_grasp", "t_release")
MISSED = -1
NOT_DRAWN = -2
#: Depth of the drawn place boxes [m] (the line's session and its scene both use it).
BOX_DEPTH = 0.08
#: Most items a line record holds (a window of a line, not an hour of it).
MAX_LINE_ITEMS = 20_000
MAX_LINE_ARMS = 64
#: Longest belt [m], fastest belt [m/s], longest window [s] a record may describe.
MAX_LINE_LENGTH = 1000.0
MAX_LINE_SPEED = 100.0
MAX_LINE_WINDOW = 3600.0


@dataclass(frozen=True, eq=False)
class LineRecord:
    """One animated window of a line (module doc).

    Attributes:
        name: the record's name; ``arms``: session robot keys, in the index order of ``items[:, 6]``.
        belt_to_world: (4, 4) pose of the belt frame (origin: the start of its centre line, on its surface).
        length, width, thickness [m], speed [m/s] of the belt; ``u_miss`` [m]: where an unpicked
        item counts as missed (the end of the last window); ``duration`` [s]: the window shown.
        items: (N, 9) float array, columns :data:`ITEM_COLUMNS`.
    """

    name: str
    arms: tuple[str, ...]
    belt_to_world: np.ndarray
    length: float
    width: float
    thickness: float
    speed: float
    u_miss: float
    duration: float
    items: np.ndarray

    @property
    def n_picked(self) -> int:
        return int(np.count_nonzero(self.items[:, 6] >= 0))

    @property
    def n_missed(self) -> int:
        return int(np.count_nonzero(self.items[:, 6] == MISSED))


def _positive(value: Any, what: str, top: float) -> str | None:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or not 0.0 < value <= top:
        return f"{what} must be a number in (0, {top:g}], got {str(value)[:40]}"
    return None


def check_line(rec: LineRecord) -> str | None:
    """What is wrong with ``rec`` (a sentence naming the field), or ``None``: used on write and read."""
    for what, value, top in (("length", rec.length, MAX_LINE_LENGTH), ("width", rec.width, MAX_LINE_LENGTH),
                             ("thickness", rec.thickness, MAX_LINE_LENGTH), ("speed", rec.speed, MAX_LINE_SPEED),
                             ("duration", rec.duration, MAX_LINE_WINDOW)):
        bad = _positive(value, what, top)
        if bad:
            return bad
    if not (isinstance(rec.u_miss, (int, float)) and math.isfinite(rec.u_miss) and 0.0 <= rec.u_miss <= rec.length):
        return f"u_miss must lie on the belt, in [0, length = {rec.length:g}] m"
    if not 1 <= len(rec.arms) <= MAX_LINE_ARMS or len(set(rec.arms)) != len(rec.arms):
        return f"arms must name 1 to {MAX_LINE_ARMS} distinct robots, got {len(rec.arms)}"
    T = rec.belt_to_world
    R = T[:3, :3]
    if not np.allclose(T[3], [0, 0, 0, 1]) or not np.allclose(R.T @ R, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0:
        return "belt_to_world must be a rigid transform"
    it = rec.items
    if it.ndim != 2 or it.shape[1] != len(ITEM_COLUMNS):
        return f"items must have shape (N, {len(ITEM_COLUMNS)}), got {it.shape}"
    if it.shape[0] > MAX_LINE_ITEMS:
        return f"items holds {it.shape[0]:,} rows, more than the {MAX_LINE_ITEMS:,} a line record may hold"
    if not np.all(np.isfinite(it)):
        return "items holds NaN or infinite values"
    t0, w, _, size, arm, tg, tr = it[:, 0], it[:, 1], it[:, 2], it[:, 3:6], it[:, 6], it[:, 7], it[:, 8]
    if np.any(np.abs(t0) > MAX_LINE_WINDOW + MAX_LINE_LENGTH / rec.speed):
        return "items' t0 lie too far outside the window"
    if np.any(size <= 0.0) or np.any(size > rec.length):
        return "items' length, width and height must be > 0 and no longer than the belt"
    if np.any(np.abs(w) + size[:, 1] / 2.0 > rec.width / 2.0 + 1e-9):
        return f"an item lies off the belt (|w| + width/2 > {rec.width / 2:g} m)"
    if np.any(arm != np.round(arm)) or np.any(arm < NOT_DRAWN) or np.any(arm >= len(rec.arms)):
        return f"items' arm must be an index of arms (0..{len(rec.arms) - 1}), {MISSED} (missed) or {NOT_DRAWN}"
    picked = arm >= 0
    if np.any(tg[picked] < t0[picked]) or np.any(tr[picked] < tg[picked]) or np.any(np.abs(tr) > 2 * MAX_LINE_WINDOW):
        return "a picked item needs t0 <= t_grasp <= t_release"
    return None


def encode_line(r: LineRecord) -> tuple[dict, dict, dict]:
    """JSON fields, arrays and texts of one record (see :class:`pinarms.viz.session_format.Kind`)."""
    return ({"name": r.name, "arms": list(r.arms), "length": r.length, "width": r.width, "thickness": r.thickness,
             "speed": r.speed, "u_miss": r.u_miss, "duration": r.duration},
            {"belt_to_world": r.belt_to_world, "items": r.items}, {})


def decode_line(it: Any) -> LineRecord:
    """The record of a validated session item (JSON fields checked here, arrays already read)."""
    arms = it.field("arms", list)
    if len(arms) > MAX_LINE_ARMS or not all(isinstance(a, str) and NAME_RE.match(a) for a in arms):
        raise it.fail(f"{it.where}.arms must be a list of at most {MAX_LINE_ARMS} robot keys")
    nums = {k: it.field(k, (int, float)) for k in ("length", "width", "thickness", "speed", "u_miss", "duration")}
    rec = LineRecord(it.key, tuple(arms), it.arrays["belt_to_world"], *(float(nums[k]) for k in
                     ("length", "width", "thickness", "speed", "u_miss", "duration")), it.arrays["items"])
    bad = check_line(rec)
    if bad:
        raise it.fail(f"{it.where}: {bad}")
    return rec


def make_line(draft: LineRecord) -> LineRecord:
    """``draft`` checked, its numbers as floats and its arrays read-only; :class:`InvalidInput` naming what is wrong.

    The caller fills a :class:`LineRecord` with the belt (``belt_to_world`` (4, 4), ``length``,
    ``width``, ``thickness`` [m], ``speed`` [m/s]), the window (``u_miss`` [m], ``duration`` [s])
    and the item rows (anything shaped (N, 9)); this returns the record a session keeps.
    """
    name = draft.name
    T = np.array(draft.belt_to_world, dtype=float)
    rows = np.array(draft.items, dtype=float).reshape(-1, len(ITEM_COLUMNS))
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise InvalidInput(f"line {name!r}: belt_to_world must be a finite (4, 4) pose")
    T.flags.writeable = False
    rows.flags.writeable = False
    rec = LineRecord(name, tuple(draft.arms), T, float(draft.length), float(draft.width), float(draft.thickness),
                     float(draft.speed), float(draft.u_miss), float(draft.duration), rows)
    bad = check_line(rec)
    if bad:
        raise InvalidInput(f"line {name!r}: {bad}")
    return rec


__all__.append("make_line")
