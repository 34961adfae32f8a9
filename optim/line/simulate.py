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
Items whose start is ``t`` can be started now; the rule (an :class:`~.rules.AssignmentRule` object,
:mod:`pinarms.optim.line.rules`: its ``prefer`` orders the candidates) picks one, or, when only later starts
exist, the arm sleeps until the earliest its rule prefers. An item that no arm takes is **missed**
(it leaves the last window).

Two loops run this: :mod:`~.sim_loop` in Python (any rule object, the guard, trays) and
:mod:`~._sim_kernel` compiled (the built-in rules without guard or trays, a few microseconds a
decision); they give the same runs (``tests/optim/line/test_simulate_recorded.py``).

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

from dataclasses import dataclass, field, replace
from typing import Any, Sequence

import numpy as np

from pinarms.optim.line.items import Items
from pinarms.optim.line.rules import AssignmentRule, Rule, assignment_rule
from pinarms.optim.line.rules.base import EPS
from pinarms.optim.line.sim_arm import SimArm, arm_states
from pinarms.optim.line.sim_loop import NO_TRAY, Columns, run_events
from pinarms.errors import InvalidInput

__all__ = ["SimArm", "SimResult", "simulate", "EPS", "NO_TRAY"]


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
    tray: np.ndarray | None = None  #: per item its tray index (:data:`NO_TRAY`: none); None: boxes only
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


def simulate(arms: Sequence[SimArm], items: Items, speed: float, rule: Rule | str | AssignmentRule = "first", *,
             duration: float | None = None, width: float | None = None, guard: Any = None) -> SimResult:
    """Run the line (module doc). ``arms`` in any order (sorted upstream first here);
    ``speed`` [m/s] must be the maps' belt speed; ``rule``: a name, a :class:`Rule` or an
    :class:`~.rules.AssignmentRule` object; ``duration`` [s]: the observed time for the rates
    (default the last arrival); ``width`` [m]: belt width (rules that split the belt across).

    The built-in rules without a guard or trays run in the compiled loop (:mod:`~._sim_kernel`),
    every other case in the Python loop (:mod:`~.sim_loop`); both give the same runs.

    Raises:
        InvalidInput: no arms, a speed ≤ 0 or NaN or differing from the maps', bad rule.
    """
    rule, trays = _checked(arms, items, speed, rule, width, guard)
    order = np.array(sorted(range(len(arms)), key=lambda k: arms[k].u_base), dtype=np.int64)
    upstream_first = [arms[k] for k in order]
    states = arm_states(upstream_first, items, speed)
    form = rule.kernel_form() if guard is None and not trays else None
    if form is not None:
        from pinarms.optim.line.sim_compiled import run_compiled

        cols, decisions = run_compiled(states, items, speed, form, width or 0.0)
        checks, tray_state = (0, 0), None
    else:
        run = run_events(upstream_first, states, items, speed, rule, width or 0.0, guard)
        cols, decisions, checks, tray_state = run.columns, run.decisions, tuple(run.checks), run.trays
    picked_by = np.where(cols.picked_by >= 0, order[np.maximum(cols.picked_by, 0)], -1)
    out = _result(tuple(a.name for a in arms), items, replace(cols, picked_by=picked_by), decisions, checks, duration)
    if not trays:
        return out
    from pinarms.optim.line.tray_sim import tray_counts

    seen, unfilled, rate = tray_counts([a.place for a in upstream_first], tray_state.fill, _span(items, duration))
    return replace(out, **tray_state.columns(), trays_seen=seen, trays_unfilled=unfilled, tray_fill=rate)


def _span(items: Items, duration: float | None) -> float:
    """The observed span [s]: ``duration``, else the last arrival."""
    return float(duration) if duration is not None else (float(items.t0[-1]) if len(items) else 0.0)


def _result(names: tuple[str, ...], items: Items, cols: Columns, decisions: int, checks: tuple,
            duration: float | None) -> SimResult:
    """The :class:`SimResult` of the item columns (arm indices in the caller's order)."""
    span = _span(items, duration)
    busy = np.zeros(len(names))  # time moving within the observed span [0, span]
    done = cols.picked_by >= 0
    np.add.at(busy, cols.picked_by[done], np.clip(cols.finish[done], 0.0, span) - np.clip(cols.start[done], 0.0, span))
    return SimResult(names, cols.picked_by, cols.meet, cols.u_meet, cols.start, cols.finish, max(span, 1e-9), busy,
                     decisions, items.t0, (int(checks[0]), int(checks[1])), items.w, items.kind)


def _checked(arms: Sequence[SimArm], items: Items, speed: float, rule: Rule | str | AssignmentRule,
             width: float | None, guard: Any) -> tuple[AssignmentRule, bool]:
    """The rule object and whether any arm places in trays; InvalidInput (see :func:`simulate`)."""
    rule = assignment_rule(rule)
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
    if rule.needs_width and width is None:
        raise InvalidInput(f"the {rule.name!r} rule needs the belt width")
    trays = any(a.place is not None for a in arms)
    if trays and not rule.plans_trays:
        raise InvalidInput(f"arms placing in trays: the {rule.name!r} rule does not plan tray places yet; use "
                           "another rule")
    if trays and guard is not None:
        raise InvalidInput("arms placing in trays: the neighbour check does not plan tray places yet; use no cell")
    return rule, trays
