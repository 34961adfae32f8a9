"""The simulator's event loop in Python: every rule object, the neighbour guard, trays.

:func:`run_events` processes the arms' events in time order (ties: upstream arm first); at each,
:func:`decide` shows the arm its candidates and starts the pick its rule prefers (module doc of
:mod:`pinarms.optim.line.simulate`). The run's state is named: :class:`Run` (what the loop changes),
:class:`Pick` (a pick as the neighbour guard sees it), :class:`Ongoing` (an arm's pick under way),
:class:`Columns` (what happened to each item), :class:`TrayState` (slots and places, for arms that
place in trays). The compiled loop (:mod:`~._sim_kernel`) gives the same runs for the built-in
rules without a guard or trays.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass, field
from typing import Any, NamedTuple, Sequence

import numpy as np

from pinarms.optim.line.items import Items
from pinarms.optim.line.rules.base import EPS, AssignmentRule, Candidates, Decision
from pinarms.optim.line.sim_arm import ArmState, SimArm

__all__ = ["Pick", "Ongoing", "Columns", "TrayState", "Run", "run_events", "decide", "window", "NO_TRAY"]

#: ``SimResult.tray`` of an item placed in no tray (tray indices may be negative: trays ahead at t = 0).
NO_TRAY = int(np.iinfo(np.int64).min)


class Pick(NamedTuple):
    """A pick as the neighbour guard sees it (a tuple: ``guard(pick, other)`` may unpack it): the arm's
    ``arm`` name, the ``item`` index, its ``start`` and ``meet`` [s], the pre-grasp point ``u`` and ``w``
    [m] and the item's ``kind``."""

    arm: str
    item: int
    start: float
    meet: float
    u: float
    w: float
    kind: int


class Ongoing(NamedTuple):
    """An arm's pick under way and when it ends [s]."""

    pick: Pick
    finish: float


@dataclass(frozen=True, eq=False)
class Columns:
    """Per item (n,): ``picked_by`` the arm's position upstream first (-1: missed), ``meet``,
    ``u_meet``, ``start``, ``finish`` (NaN: missed)."""

    picked_by: np.ndarray
    meet: np.ndarray
    u_meet: np.ndarray
    start: np.ndarray
    finish: np.ndarray

    @classmethod
    def empty(cls, n: int) -> "Columns":
        return cls(np.full(n, -1, dtype=np.int64), *(np.full(n, np.nan) for _ in range(4)))


@dataclass(frozen=True, eq=False)
class TrayState:
    """Tray slots and places: ``fill`` {(tray belt id, tray): slots taken or promised}, ``places`` the
    promised :class:`~.tray_sim.Place` of each candidate item, and per item its ``tray``
    (:data:`NO_TRAY`: none), ``u_place``, ``place_time``, ``place_wait``, ``place_branch``, ``no_tray``."""

    fill: dict
    places: list
    tray: np.ndarray
    u_place: np.ndarray
    place_time: np.ndarray
    place_wait: np.ndarray
    place_branch: np.ndarray
    no_tray: np.ndarray

    @classmethod
    def empty(cls, n: int) -> "TrayState":
        return cls({}, [None] * n, np.full(n, NO_TRAY, dtype=np.int64), np.full(n, np.nan), np.full(n, np.nan),
                   np.full(n, np.nan), np.full(n, -1, dtype=np.int64), np.zeros(n, dtype=bool))

    def columns(self) -> dict[str, np.ndarray]:
        return {"tray": self.tray, "u_place": self.u_place, "place_time": self.place_time,
                "place_wait": self.place_wait, "place_branch": self.place_branch, "no_tray": self.no_tray}


@dataclass(eq=False)
class Run:
    """What the loop changes during one run (the arms upstream first), and what it is given."""

    arms: Sequence[SimArm]
    states: Sequence[ArmState]
    items: Items
    speed: float
    rule: AssignmentRule
    width: float
    guard: Any
    columns: Columns
    trays: TrayState
    taken: np.ndarray
    neighbours: dict[int, list[int]]
    ongoing: list = field(default_factory=list)
    checks: list = field(default_factory=lambda: [0, 0])  #: neighbour checks run, of those blocked
    decisions: int = 0


def run_events(arms: Sequence[SimArm], states: Sequence[ArmState], items: Items, speed: float,
               rule: AssignmentRule, width: float, guard: Any) -> Run:
    """Run the line (:func:`pinarms.optim.line.simulate.simulate`) and return its final :class:`Run`."""
    n = len(items)
    run = Run(arms, states, items, speed, rule, width, guard, Columns.empty(n), TrayState.empty(n),
              np.zeros(n, dtype=bool), _overlapping(states) if guard else {}, [None] * len(arms))
    heap = [(0.0, k) for k in range(len(arms))]
    heapq.heapify(heap)
    while heap:
        t, k = heapq.heappop(heap)
        run.decisions += 1
        wake = decide(run, t, k)
        if wake is not None:
            heapq.heappush(heap, (wake, k))
    return run


def window(t: float, t0: np.ndarray, st: ArmState, speed: float) -> tuple[int, int]:
    """``(lo, hi)``: the items an arm deciding at ``t`` may meet (arrivals ``t0[lo:hi]``), widened by a
    rounding slack so that an item whose start is ``t`` (a window as narrow as a nanometre) is never
    rounded out; the intercept decides which of them are met."""
    slack = EPS + 4.0 * float(np.spacing(abs(t)))
    lo = int(np.searchsorted(t0, t - st.u_max / speed - slack))
    hi = int(np.searchsorted(t0, t - st.u_min / speed + st.max_tA + slack, side="right"))
    return lo, hi


def _takes(run: Run, k: int, idx: np.ndarray) -> np.ndarray:
    """Of items ``idx``, those not taken that arm ``k``'s rule lets it take."""
    idx = idx[~run.taken[idx]]
    return idx[run.rule.takes(k, len(run.arms), idx, run.items.w[idx], run.width)]


def decide(run: Run, t: float, k: int) -> float | None:
    """Arm ``k``'s decision at ``t``: start a pick or not; returns when it looks again (None: never)."""
    st, arm, t0, n = run.states[k], run.arms[k], run.items.t0, len(run.items)
    lo, hi = window(t, t0, st, run.speed)
    hi = max(hi, min(n, lo + run.rule.looks_beyond))
    idx = _takes(run, k, np.arange(lo, hi))
    nxt = _next_wake(run, t, hi, k)
    if idx.size == 0:
        return nxt
    c = st.intercept(t, idx, t0)
    if not c.ok.any():
        return nxt
    idx, s, m, f, u = idx[c.ok], c.start[c.ok], c.meet[c.ok], c.finish[c.ok], c.u[c.ok]
    if arm.place is not None:
        keep = _places(run, arm, idx, m, u, f)
        if not keep.any():
            return _tray_retry(arm, t, nxt)
        idx, s, m, f, u = idx[keep], s[keep], m[keep], f[keep], u[keep]
    w = run.items.w[idx]
    distance = np.hypot(run.speed * (t - t0[idx]) - st.rest[0], w - st.rest[1])
    cands = Candidates(idx, s, m, f, t0[idx], w, distance)
    prefs = run.rule.prefer(Decision(t, k, len(run.arms), cands, _intercept_of(st, t0)))
    if len(prefs) == 0 or s[prefs[0]] > t + EPS:
        return float(s.min()) if len(prefs) == 0 else float(s[prefs[0]])
    choice, blocked_until = _first_clear(run, k, t, cands, u, prefs)
    if choice is None:
        return max(t + 1e-6, blocked_until)
    _take(run, k, t, cands, float(u[choice]), choice)
    return float(f[choice])


def _intercept_of(st: ArmState, t0: np.ndarray):
    """``intercept(ready, item)`` of :class:`~.rules.base.Decision` for arm state ``st``."""
    def intercept(ready: float, i: int) -> tuple[float, float] | None:
        r = st.intercept(ready, np.array([i]), t0)
        return (float(r.start[0]), float(r.finish[0])) if r.ok[0] else None

    return intercept


def _pick(run: Run, k: int, t: float, c: Candidates, u: float, j: int) -> Pick:
    i = int(c.index[j])
    return Pick(run.arms[k].name, i, t, float(c.meet[j]), u, float(run.items.w[i]), int(run.items.kind[i]))


def _first_clear(run: Run, k: int, t: float, c: Candidates, u: np.ndarray,
                 prefs: np.ndarray) -> tuple[int | None, float]:
    """The first preferred candidate proven clear of the neighbours' ongoing picks, else None and when
    the earliest blocking pick ends."""
    blocked_until = np.inf
    for j in prefs:
        j = int(j)
        until = _blocked(run, _pick(run, k, t, c, float(u[j]), j), k, t)
        if until is None:
            return j, blocked_until
        blocked_until = min(blocked_until, until)
    return None, blocked_until


def _take(run: Run, k: int, t: float, c: Candidates, u: float, j: int) -> None:
    """Arm ``k`` starts the pick of candidate ``j`` at ``t``."""
    i = int(c.index[j])
    run.taken[i] = True
    cols = run.columns
    cols.picked_by[i], cols.meet[i], cols.u_meet[i], cols.start[i], cols.finish[i] = k, c.meet[j], u, t, c.finish[j]
    arm = run.arms[k]
    if arm.place is not None:
        _record_place(run.trays, arm, i)
    run.ongoing[k] = Ongoing(_pick(run, k, t, c, u, j), float(c.finish[j]))


def _overlapping(states: Sequence[ArmState]) -> dict[int, list[int]]:
    """For each arm, the arms whose pick windows on the belt overlap its own."""
    return {k: [j for j in range(len(states)) if j != k and states[j].u_min < states[k].u_max
                and states[k].u_min < states[j].u_max] for k in range(len(states))}


def _blocked(run: Run, pick: Pick, k: int, t: float) -> float | None:
    """None when ``pick`` is clear of every ongoing pick of an overlapping neighbour, else when
    the earliest blocking pick ends."""
    if run.guard is None:
        return None
    until = None
    for j in run.neighbours.get(k, ()):
        other = run.ongoing[j]
        if other is None or other.finish <= t:
            continue
        run.checks[0] += 1
        if not run.guard(pick, other.pick):
            run.checks[1] += 1
            until = other.finish if until is None else min(until, other.finish)
    return until


def _next_wake(run: Run, t: float, hi: int, k: int) -> float | None:
    """When the arm should look again if nothing can start now: the next item beyond the range."""
    t0, st = run.items.t0, run.states[k]
    rest = np.arange(hi, min(hi + 64, t0.size))
    rest = _takes(run, k, rest) if rest.size else rest
    j = hi if rest.size == 0 else int(rest[0])
    if j >= t0.size:
        return None
    return max(t + 1e-6, float(t0[j] + st.u_min / run.speed - st.max_tA))


def _tray_retry(arm: SimArm, t: float, nxt: float | None) -> float:
    """When an arm with no tray slot in reach looks again: a quarter tray period later (or its next wake)."""
    tb = arm.place.trays
    again = t + 0.25 * tb.pitch / tb.belt.speed
    return again if nxt is None else min(nxt, again)


def _places(run: Run, arm: SimArm, idx: np.ndarray, meet: np.ndarray, u: np.ndarray,
            finish: np.ndarray) -> np.ndarray:
    """Each candidate's earliest free reachable tray slot (:func:`~.tray_sim.find_place`): fills the
    promised places and ``finish``; returns which candidates have one, flags the others ``no_tray``."""
    from pinarms.optim.line.tray_sim import find_place

    trays, w = run.trays, run.items.w
    keep = np.zeros(idx.size, dtype=bool)
    for j, i in enumerate(idx):
        pl = find_place(arm.place, float(u[j] - arm.u_base), float(w[i]), float(meet[j]), trays.fill,
                        id(arm.place.trays))
        if pl is None:
            trays.no_tray[i] = True
            continue
        trays.places[i], finish[j], keep[j] = pl, pl.finish, True
    return keep


def _record_place(trays: TrayState, arm: SimArm, i: int) -> None:
    """Item ``i`` placed at its promised place: one more in its tray, and its tray columns."""
    pl = trays.places[i]
    key = (id(arm.place.trays), pl.tray)
    trays.fill[key] = trays.fill.get(key, 0) + 1
    trays.tray[i], trays.u_place[i], trays.place_time[i] = pl.tray, pl.v, pl.time
    trays.place_wait[i], trays.place_branch[i] = pl.wait, pl.branch
