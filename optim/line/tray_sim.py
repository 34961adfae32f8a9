"""Trays in the simulation: which tray slot a picked item goes to, and when.

Each arm that places in trays (:class:`SimPlace`) has a :class:`~.tray_maps.TrayMap` and its
:class:`~.trays.TrayBelt`. Tray ``k``'s place point is at ``v_k(t) = phase − k·pitch + V·t`` on
the tray belt (``V`` its speed). When an arm decides to pick an item whose pick ends at
``te = meet + track``, it looks for the place: over the trays in order of arrival (ascending
``k``) that still have a free slot (``capacity`` minus the slots already taken or promised), the
**earliest reachable place** along the arm's place grid ``v`` (ascending, downstream on the tray
belt): the first ``v`` where ``te + t_X(v) ≤ t_k(v) = (v − phase + k·pitch) / V`` (the arm,
transferring at once, is at ``v`` no later than the tray), refined linearly between nodes like
the pick's intercept. At a crossing the time-optimal transfer meets the tray exactly; at the
place window's entry the arm may be early and then holds the item for ``wait`` s (the map's
transfer time plus the hold); it waits for no tray beyond the first to enter its window after it
can be there. The slot is promised at the decision. An item for which no tray
slot is reachable is not picked by that arm (``no_tray`` counted when it is missed).

Trays are *seen* when they enter the first place window on their belt at ``t ≥ 0`` and leave
the last before the observed span ends; the fill rate is their placed items over their slots.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinarms.optim.line.tray_maps import TrayMap
from pinarms.optim.line.trays import TrayBelt

__all__ = ["SimPlace", "Place", "find_place", "tray_counts"]


@dataclass(frozen=True, eq=False)
class SimPlace:
    """An arm's place in trays as the simulator sees it: its ``tray_map``, the ``trays`` and
    ``v_base`` (its base projected on the tray belt, m)."""

    tray_map: TrayMap
    trays: TrayBelt
    v_base: float

    @property
    def v(self) -> np.ndarray:
        return self.v_base + self.tray_map.dv


@dataclass(frozen=True)
class Place:
    """A promised slot: ``tray`` index, ``v`` the pre-place point on the tray belt [m], ``time``
    of the place rendezvous [s], ``finish`` (at rest at home) [s], ``wait`` held before it [s]."""

    tray: int
    v: float
    time: float
    finish: float
    wait: float


def find_place(p: SimPlace, du: float, w: float, meet: float, fill: dict, key: int) -> Place | None:
    """The earliest reachable free slot for a pick at ``du`` (from the arm's base), ``w`` meeting
    its item at ``meet`` (module doc); ``fill[(key, k)]`` the slots taken in tray ``k``."""
    m, tb = p.tray_map, p.trays
    _, tX, tR = m.times(du, w, m.dv)
    ok = np.isfinite(tX)
    if not ok.any():
        return None
    V, v = tb.belt.speed, p.v
    te = meet + m.track
    k0 = int(np.ceil((V * (te + np.nanmin(tX)) - v[-1] + tb.phase) / tb.pitch - 1e-9))
    k1 = int(np.floor((V * (te + np.nanmax(tX)) - v[0] + tb.phase) / tb.pitch)) + 1
    for k in range(k0, max(k0, k1) + 1):  # k1: the first tray to enter the window after the arm can be there
        if fill.get((key, k), 0) >= tb.capacity:
            continue
        t_k = (v - tb.phase + k * tb.pitch) / V
        g = te + tX - t_k
        good = ok & (g <= 0.0)
        if not good.any():
            continue
        j = int(np.argmax(good))
        if j > 0 and ok[j - 1] and g[j - 1] > 0.0:
            f = g[j - 1] / (g[j - 1] - g[j])
            vj = v[j - 1] + f * (v[j] - v[j - 1])
            x, r = tX[j - 1] + f * (tX[j] - tX[j - 1]), tR[j - 1] + f * (tR[j] - tR[j - 1])
        else:
            vj, x, r = v[j], tX[j], tR[j]
        t_place = (vj - tb.phase + k * tb.pitch) / V
        return Place(k, float(vj), float(t_place), float(t_place + m.place + r), float(max(0.0, t_place - te - x)))
    return None


def tray_counts(places: list, fill: dict, span: float) -> tuple[int, int, float]:
    """(trays seen, trays that left with a free slot, fill rate) over the tray belts of ``places``
    (one :class:`SimPlace` per arm or None; arms sharing a TrayBelt object share its trays)."""
    belts: dict = {}
    for p in places:
        if p is None:
            continue
        lo, hi, _ = belts.get(id(p.trays), (np.inf, -np.inf, p.trays))
        belts[id(p.trays)] = (min(lo, float(p.v[0])), max(hi, float(p.v[-1])), p.trays)
    seen = unfilled = placed = slots = 0
    for key, (lo, hi, tb) in belts.items():
        V = tb.belt.speed
        k_first = int(np.ceil((tb.phase - lo) / tb.pitch - 1e-9))       # enters at t >= 0
        k_last = int(np.floor((V * span - hi + tb.phase) / tb.pitch))   # leaves by the span's end
        for k in range(k_first, k_last + 1):
            n = fill.get((key, k), 0)
            seen += 1
            unfilled += n < tb.capacity
            placed += n
            slots += tb.capacity
    return seen, unfilled, (placed / slots if slots else float("nan"))
