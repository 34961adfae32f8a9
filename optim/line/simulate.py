"""Event-based simulation of N arms picking items from a moving belt.

Each arm is a state machine: **idle** at rest at its box → (decision) → **moving** through its
pick (approach, tracking, leave, release; times from its :class:`TaskMap`) → idle. Events are
the instants an arm becomes idle or wakes up to look again; they are processed in time order
(ties: upstream arm first), so an item taken by one arm is gone for the others.

At a decision at time ``t`` an arm computes, for every item not yet taken near its window, the
**earliest reachable intercept**: along its map's grid of pre-grasp points ``u`` (ascending
downstream), the first ``u`` where ``t + t_A(u) ≤ t0 + u / v`` (the arm, leaving now, is at
``u`` no later than the item), refined linearly between grid points; the arm leaves at
``start = t0 + u/v − t_A(u) ≥ t`` so that it meets the item exactly (:class:`~.sim_arm.ArmState`).
Items whose start is ``t`` can be started now; the rule (:mod:`pinarms.optim.line.rules`) picks one, or, when only later
starts exist, the arm sleeps until the earliest. An item that no arm takes is **missed** (it
leaves the last window).

Neighbouring arms whose windows overlap: with a ``guard`` (:class:`pinarms.optim.line.neighbours.NeighbourGuard`:
exact picks through the cell's continuous check at the clearance), an arm starts a pick only when
it is proven clear of every ongoing pick of such a neighbour; otherwise it tries its rule's next
choice, or waits until that neighbour's pick ends. Each guarded pair is counted in
:attr:`SimResult.checks` (checks, blocked).

Arms with a ``place`` (:class:`~.tray_sim.SimPlace`) place in trays on a second belt: a
candidate item counts only with a free tray slot the arm can reach after the pick, which is
promised at the decision and sets the pick's end (:mod:`~.tray_sim`); the result then holds
each item's tray, the trays seen, unfilled and the fill rate.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from pinarms.optim.line.items import Items
from pinarms.optim.line.rules import Candidates, Rule, best_sequence, rank_simple
from pinarms.optim.line.sim_arm import ArmState, SimArm
from pinarms.errors import InvalidInput

__all__ = ["SimArm", "SimResult", "simulate", "EPS", "NO_TRAY"]

#: ``SimResult.tray`` of an item placed in no tray (tray indices may be negative: trays ahead at t = 0).
NO_TRAY = int(np.iinfo(np.int64).min)

#: Time tolerance of "start now" [s].
EPS = 1e-9


@dataclass(frozen=True, eq=False)
class SimResult:
    """What happened (arrays (N,) over items, in stream order).

    Attributes:
        picked_by: arm index or -1 (missed); ``meet``: rendezvous time [s] (NaN if missed);
        ``u_meet``: pre-grasp point along the belt [m]; ``start``, ``finish``: the pick's
        start and end [s]; ``t0``, ``w``, ``kind``: the items' arrival times [s],
        positions across [m] and types; ``arms``: names; ``duration``: observed time [s] (the stream's);
        ``busy``: per arm, time spent moving [s]; ``overlaps``: pairs of picks (item a, item b)
        by neighbouring arms with overlapping windows at overlapping times.
    """

    arms: tuple[str, ...]
    picked_by: np.ndarray
    meet: np.ndarray
    u_meet: np.ndarray
    start: np.ndarray
    finish: np.ndarray
    duration: float
    busy: np.ndarray
    decisions: int
    t0: np.ndarray = field(default_factory=lambda: np.zeros(0))
    checks: tuple[int, int] = (0, 0)
    w: np.ndarray = field(default_factory=lambda: np.zeros(0))
    kind: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    tray: np.ndarray | None = None  #: per item the tray index it was placed in (:data:`NO_TRAY`: none); None: boxes only
    u_place: np.ndarray | None = None  #: pre-place point on the tray belt [m]
    place_time: np.ndarray | None = None  #: place rendezvous [s]
    place_wait: np.ndarray | None = None  #: time held before the place rendezvous [s]
    place_branch: np.ndarray | None = None  #: the place's IK branch label in the tray map (-1: one branch)
    no_tray: np.ndarray | None = None  #: an arm could have picked the item but had no free reachable slot
    trays_seen: int = 0  #: trays that crossed every place window within the observed span
    trays_unfilled: int = 0  #: of those, trays that left the last window with a free slot
    tray_fill: float = float("nan")  #: placed items over the slots of the trays seen

    @property
    def unplaced(self) -> int:
        """Items missed although an arm could have picked them: no free tray slot within reach."""
        return 0 if self.no_tray is None else int(np.count_nonzero(self.no_tray & (self.picked_by < 0)))

    @property
    def n_items(self) -> int:
        return int(self.picked_by.size)

    @property
    def picks(self) -> int:
        return int(np.count_nonzero(self.picked_by >= 0))

    @property
    def misses(self) -> int:
        return self.n_items - self.picks

    @property
    def miss_rate(self) -> float:
        return self.misses / self.n_items if self.n_items else 0.0

    @property
    def picks_per_minute(self) -> float:
        return 60.0 * self.picks / self.duration

    @property
    def utilisation(self) -> np.ndarray:
        return self.busy / self.duration


def _eligible(rule: Rule, arm_index: int, n_arms: int, idx: np.ndarray, w: np.ndarray, width: float) -> np.ndarray:
    if rule.name == "bands":
        band = np.clip(((w[idx] + width / 2.0) / width * n_arms).astype(int), 0, n_arms - 1)
        return idx[band == arm_index]
    if rule.name == "split":
        return idx[idx % n_arms == arm_index]
    return idx


def simulate(arms: Sequence[SimArm], items: Items, speed: float, rule: Rule | str = "first", *,
             duration: float | None = None, width: float | None = None, guard: Any = None) -> SimResult:
    """Run the line (module doc). ``arms`` in any order (sorted upstream first here);
    ``speed`` [m/s] must be the maps' belt speed; ``duration`` [s]: the observed time for
    the rates (default the last arrival); ``width`` [m]: belt width (the "bands" rule).

    Raises:
        InvalidInput: no arms, a speed ≤ 0 or NaN or differing from the maps', bad rule.
    """
    rule, trays = _checked(arms, items, speed, rule, width, guard)
    names = tuple(a.name for a in arms)
    order = sorted(range(len(arms)), key=lambda k: arms[k].u_base)
    arms = [arms[k] for k in order]
    n = len(items)
    t0 = items.t0
    states = [ArmState(a, items, speed) for a in arms]
    picked_by = np.full(n, -1)
    meet, u_meet, start, finish = (np.full(n, np.nan) for _ in range(4))
    taken = np.zeros(n, dtype=bool)
    busy = np.zeros(len(arms))
    neighbours = _overlapping(states) if guard else {}
    ongoing: list = [None] * len(arms)
    fill: dict = {}
    tray_of = np.full(n, NO_TRAY, dtype=np.int64)
    u_place, place_time, wait = (np.full(n, np.nan) for _ in range(3))
    place_branch = np.full(n, -1, dtype=np.int64)
    no_tray = np.zeros(n, dtype=bool)
    places: list = [None] * n
    counts = [0, 0]
    heap = [(0.0, k) for k in range(len(arms))]
    heapq.heapify(heap)
    decisions = 0
    while heap:
        t, k = heapq.heappop(heap)
        st = states[k]
        decisions += 1
        lo, hi = _candidates(t, t0, st, speed)
        if rule.name == "lookahead":
            hi = max(hi, min(n, lo + rule.horizon))
        idx = np.arange(lo, hi)
        idx = _eligible(rule, k, len(arms), idx[~taken[lo:hi]], items.w, width or 0.0)
        nxt = _next_wake(t, hi, taken, t0, st, speed, rule, k, len(arms), items, width)
        if idx.size == 0:
            if nxt is not None:
                heapq.heappush(heap, (nxt, k))
            continue
        ok, s, m, f, u = st.intercept(t, idx, t0)
        if not ok.any():
            if nxt is not None:
                heapq.heappush(heap, (nxt, k))
            continue
        idx, s, m, f, u = idx[ok], s[ok], m[ok], f[ok], u[ok]
        if arms[k].place is not None:
            keep = _places(arms[k], idx, m, u, items.w, f, fill, places, no_tray)
            if not keep.any():
                heapq.heappush(heap, (_tray_retry(arms[k], t, nxt), k))
                continue
            idx, s, m, f, u = idx[keep], s[keep], m[keep], f[keep], u[keep]
        if rule.name == "lookahead":
            prefs = [_lookahead(st, t, idx, s, t0, rule.horizon)]
        else:
            sel = np.flatnonzero(s <= t + EPS)
            dist = np.hypot(speed * (t - t0[idx[sel]]) - st.rest[0], items.w[idx[sel]] - st.rest[1])
            c = Candidates(idx[sel], s[sel], m[sel], f[sel], t0[idx[sel]], items.w[idx[sel]], dist)
            prefs = [int(sel[j]) for j in rank_simple(rule.name, c)] if sel.size else []
        if not prefs or s[prefs[0]] > t + EPS:
            heapq.heappush(heap, (float(s.min()) if not prefs else float(s[prefs[0]]), k))
            continue
        choice, blocked_until = None, np.inf
        for j in prefs:
            pick = (arms[k].name, int(idx[j]), t, float(m[j]), float(u[j]), float(items.w[idx[j]]),
                    int(items.kind[idx[j]]))
            until = _blocked(guard, pick, float(f[j]), k, neighbours, ongoing, t, counts)
            if until is None:
                choice = j
                break
            blocked_until = min(blocked_until, until)
        if choice is None:
            heapq.heappush(heap, (max(t + 1e-6, blocked_until), k))
            continue
        i = int(idx[choice])
        taken[i] = True
        picked_by[i], meet[i], u_meet[i], start[i], finish[i] = order[k], m[choice], u[choice], t, f[choice]
        if arms[k].place is not None:
            _record_place(arms[k], places[i], i, fill, (tray_of, u_place, place_time, wait, place_branch))
        ongoing[k] = (arms[k].name, i, t, float(m[choice]), float(u[choice]), float(items.w[i]), int(items.kind[i]),
                      float(f[choice]))
        heapq.heappush(heap, (float(f[choice]), k))
    span = float(duration) if duration is not None else (float(t0[-1]) if n else 0.0)
    busy = np.zeros(len(names))  # time moving within the observed span [0, span]
    done = picked_by >= 0
    np.add.at(busy, picked_by[done], np.clip(finish[done], 0.0, span) - np.clip(start[done], 0.0, span))
    out = SimResult(names, picked_by, meet, u_meet,
                    start, finish, max(span, 1e-9), busy, decisions, t0, (counts[0], counts[1]),
                    items.w, items.kind)
    if not trays:
        return out
    return _with_trays(out, arms, fill, span, tray=tray_of, u_place=u_place, place_time=place_time, place_wait=wait,
                       place_branch=place_branch, no_tray=no_tray)


def _candidates(t: float, t0: np.ndarray, st: ArmState, speed: float) -> tuple[int, int]:
    """``(lo, hi)``: the items an arm deciding at ``t`` may meet (arrivals ``t0[lo:hi]``), widened by a
    rounding slack so that an item whose start is ``t`` (a window as narrow as a nanometre) is never
    rounded out; the intercept decides which of them are met."""
    slack = EPS + 4.0 * float(np.spacing(abs(t)))
    lo = int(np.searchsorted(t0, t - st.u_max / speed - slack))
    hi = int(np.searchsorted(t0, t - st.u_min / speed + st.max_tA + slack, side="right"))
    return lo, hi


def _overlapping(states: list) -> dict[int, list[int]]:
    """For each arm, the arms whose pick windows on the belt overlap its own."""
    return {k: [j for j in range(len(states)) if j != k and states[j].u_min < states[k].u_max
                and states[k].u_min < states[j].u_max] for k in range(len(states))}


def _tray_retry(arm: SimArm, t: float, nxt: float | None) -> float:
    """When an arm with no tray slot in reach looks again: a quarter tray period later (or its next wake)."""
    tb = arm.place.trays
    again = t + 0.25 * tb.pitch / tb.belt.speed
    return again if nxt is None else min(nxt, again)


def _record_place(arm: SimArm, pl: Any, i: int, fill: dict, columns: tuple[np.ndarray, ...]) -> None:
    """Item ``i`` placed at ``pl``: one more in its tray, and its tray, place, time, wait and branch columns."""
    fill[(id(arm.place.trays), pl.tray)] = fill.get((id(arm.place.trays), pl.tray), 0) + 1
    for column, value in zip(columns, (pl.tray, pl.v, pl.time, pl.wait, pl.branch)):
        column[i] = value


def _checked(arms: Sequence[SimArm], items: Items, speed: float, rule: Rule | str, width: float | None,
             guard: Any) -> tuple[Rule, bool]:
    """The rule as a :class:`Rule` and whether any arm places in trays; InvalidInput (see :func:`simulate`)."""
    rule = rule if isinstance(rule, Rule) else Rule(str(rule))
    if not arms:
        raise InvalidInput("simulate needs at least one arm")
    if not (isinstance(speed, (int, float)) and np.isfinite(speed) and speed > 0.0):
        raise InvalidInput(f"belt speed must be a finite number > 0 [m/s], got {speed!r}")
    for a in arms:
        for m in a.maps:
            if abs(m.speed - speed) > 1e-9 * max(1.0, speed):
                raise InvalidInput(f"arm {a.name!r}: its task map was built for {m.speed} m/s, the belt runs at "
                                   f"{speed} m/s: build the map at this speed")
        if len(a.maps) != len(items.types):
            raise InvalidInput(f"arm {a.name!r} has {len(a.maps)} maps for {len(items.types)} item types")
    if rule.name == "bands" and width is None:
        raise InvalidInput("the 'bands' rule needs the belt width")
    trays = any(a.place is not None for a in arms)
    if trays and (rule.name == "lookahead" or guard is not None):
        raise InvalidInput("arms placing in trays: the look-ahead rule and the neighbour check do not plan tray "
                           "places yet; use another rule and no cell")
    return rule, trays


def _with_trays(out: SimResult, arms: Sequence[SimArm], fill: dict, span: float, **places: np.ndarray) -> SimResult:
    """``out`` with the tray places of its items and the trays' counts and fill rate."""
    from dataclasses import replace

    from pinarms.optim.line.tray_sim import tray_counts

    seen, unfilled, rate = tray_counts([a.place for a in arms], fill, span)
    return replace(out, **places, trays_seen=seen, trays_unfilled=unfilled, tray_fill=rate)


def _places(arm: SimArm, idx: np.ndarray, meet: np.ndarray, u: np.ndarray, w: np.ndarray, finish: np.ndarray,
            fill: dict, places: list, no_tray: np.ndarray) -> np.ndarray:
    """Each candidate's earliest free reachable tray slot (:func:`~.tray_sim.find_place`): fills
    ``places`` and ``finish``; returns which candidates have one, flags the others ``no_tray``."""
    from pinarms.optim.line.tray_sim import find_place

    keep = np.zeros(idx.size, dtype=bool)
    for j, i in enumerate(idx):
        pl = find_place(arm.place, float(u[j] - arm.u_base), float(w[i]), float(meet[j]), fill, id(arm.place.trays))
        if pl is None:
            no_tray[i] = True
            continue
        places[i], finish[j], keep[j] = pl, pl.finish, True
    return keep


def _blocked(guard: Any, pick: tuple, finish: float, k: int, neighbours: dict, ongoing: list, t: float,
             counts: list) -> float | None:
    """None when ``pick`` is clear of every ongoing pick of an overlapping neighbour, else when
    the earliest blocking pick ends."""
    if guard is None:
        return None
    until = None
    for j in neighbours.get(k, ()):
        other = ongoing[j]
        if other is None or other[7] <= t:
            continue
        counts[0] += 1
        if not guard(pick, other[:7]):
            counts[1] += 1
            until = other[7] if until is None else min(until, other[7])
    return until


def _next_wake(t: float, hi: int, taken: np.ndarray, t0: np.ndarray, st: ArmState, speed: float, rule: Rule,
               k: int, n_arms: int, items: Items, width: float | None) -> float | None:
    """When the arm should look again if nothing can start now: the next item beyond the range."""
    rest = np.arange(hi, min(hi + 64, t0.size))
    rest = _eligible(rule, k, n_arms, rest[~taken[rest]], items.w, width or 0.0) if rest.size else rest
    j = hi if rest.size == 0 else int(rest[0])
    if j >= t0.size:
        return None
    return max(t + 1e-6, float(t0[j] + st.u_min / speed - st.max_tA))


def _lookahead(st: ArmState, t: float, idx: np.ndarray, s: np.ndarray, t0: np.ndarray, horizon: int) -> int:
    order = np.argsort(s, kind="stable")[:horizon]
    pool = [int(idx[j]) for j in order]

    def intercept(ready: float, i: int):
        ok, s1, m1, f1, _ = st.intercept(ready, np.array([i]), t0)
        return (float(s1[0]), float(f1[0])) if ok[0] else None

    _, _, seq = best_sequence(t, pool, intercept, horizon)
    if not seq:
        return int(order[0])
    return int(np.flatnonzero(idx == seq[0])[0])
