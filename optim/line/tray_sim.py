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

from pinarms.optim.line.tray_map import TrayMap
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
    of the place rendezvous [s], ``finish`` (at rest at home) [s], ``wait`` held before it [s],
    ``branch`` the place's IK branch label in the map (-1: the arm has one)."""

    tray: int
    v: float
    time: float
    finish: float
    wait: float
    branch: int = -1


def find_place(p: SimPlace, du: float, w: float, meet: float, fill: dict, key: int) -> Place | None:
    """The earliest reachable free slot for a pick at ``du`` (from the arm's base), ``w`` meeting
    its item at ``meet`` (module doc); ``fill[(key, k)]`` the slots taken in tray ``k``.

    Along the place grid cell by cell and on each place branch (:meth:`TrayMap.place_cells`: the
    times are linear in ``v`` there, so the crossing is exact; a cell's last node is its own, not
    the next, possibly infeasible, cell's), the earliest place over branches and cells."""
    m, tb = p.tray_map, p.trays
    X0, X1, R0, R1 = m.place_cells(du, w)
    ok = np.isfinite(X0)
    if not ok.any():
        return None
    V, v = tb.belt.speed, p.v
    v0, v1 = v[:-1], v[1:]
    te = meet + m.track
    k0 = int(np.ceil((V * (te + np.nanmin(np.fmin(X0, X1))) - v[-1] + tb.phase) / tb.pitch - 1e-9))
    k1 = int(np.floor((V * (te + np.nanmax(np.fmax(X0, X1))) - v[0] + tb.phase) / tb.pitch)) + 1
    for k in range(k0, max(k0, k1) + 1):  # k1: the first tray to enter the window after the arm can be there
        if fill.get((key, k), 0) >= tb.capacity:
            continue
        t0, t1 = (v0 - tb.phase + k * tb.pitch) / V, (v1 - tb.phase + k * tb.pitch) / V
        g0, g1 = te + X0 - t0, te + X1 - t1  # the arm's arrival less the tray's, linear along each cell
        with np.errstate(invalid="ignore", divide="ignore"):
            f = np.where(ok & (g0 <= 0.0), 0.0, np.where(ok & (g1 <= 0.0), g0 / (g0 - g1), np.nan))
        if not np.isfinite(f).any():
            continue
        t_place = np.where(np.isfinite(f), t0 + f * (t1 - t0), np.inf)
        b, c = np.unravel_index(int(np.argmin(t_place)), t_place.shape)
        fc = float(f[b, c])
        vj = float(v0[c] + fc * (v1[c] - v0[c]))
        x, r = X0[b, c] + fc * (X1[b, c] - X0[b, c]), R0[b, c] + fc * (R1[b, c] - R0[b, c])
        t = float(t_place[b, c])
        return Place(k, vj, t, float(t + m.place + r), float(max(0.0, t - te - x)), int(m.branches[b]))
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
