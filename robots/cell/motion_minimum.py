"""The true smallest clearance at the samples of a motion check (:func:`.motion.check_motion`).

Every sample the check kept is either exact over the checked pairs or cleared at the screen
distance; what the report states as the smallest clearance is coal's exact smallest distance
over *every* candidate pair at the samples, with its time and pair. Computing it at every
sample (hundreds of pairs each) is most of a check's time, so the samples are searched as a
branch and bound in time:

* the smallest distance over every pair, ``D(t)``, changes at most at the approach speed
  bound ``V(t)`` of the check's schedule (the rule its proof rests on, :mod:`.motion`), so an
  exact ``D(s)`` at one sample bounds every other sample from below:
  ``D(t) ≥ D(s) − |∫_s^t V dt|`` (the approach budget between them);
* where the check screens on the sphere cover, each sample also starts from the cover's
  lower bound (compiled, tight); with ``cover=False`` the search uses the broad phase, coal and
  the budget alone (it shares no code with the cover);
* without the cover, a first round of :data:`SMALLEST_BATCH` samples and one broad-phase pass at
  its smallest distance run before the check's screen (:func:`first_round`): a sample without
  any pair within that distance has none within the screen distance either, so the screen
  looks only at the samples flagged there (one broad-phase pass instead of two);
* the samples still open are swept by Pinocchio's broad phase (coal's collision test at a
  security margin) at the smallest distance found: a sample without any pair within it
  cannot hold the minimum;
* rounds of :data:`SMALLEST_BATCH` samples, spread evenly in time over the samples still
  open (their bound not above the smallest distance found), are computed exactly over every
  candidate pair (coal, pairs ordered by their bounding spheres and boxes), until none is open.

The result is the same exact minimum as computing every sample: a sample is skipped only
when a proven bound shows it cannot come within :data:`TIE_M` of the smallest found.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from pinarms.robots.cell.collision import exact_min_distance, pair_lower_bounds
from pinarms.robots.cell.pairs import CollisionPair

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.cell.cell_model import CellModel as Cell


class _Samples(Protocol):
    """What the search reads of a check's samples (:class:`pinarms.robots.cell.motion` keeps them)."""

    cell: "Cell"
    first: "FirstRound | None"

    def configurations(self, ts: np.ndarray) -> np.ndarray: ...

    def cover_bounds(self, ts: np.ndarray) -> np.ndarray: ...


class _Schedule(Protocol):
    """What the search reads of a check's schedule: the fine ``grid`` [s] and the approach ``budget`` [m] on it."""

    grid: np.ndarray
    budget: np.ndarray

__all__ = ["smallest_clearance", "first_round", "FirstRound", "SMALLEST_BATCH", "TIE_M"]

#: Samples evaluated together in one round of the search.
SMALLEST_BATCH = 16
#: Distances [m] closer than this to the smallest count as ties: the earliest sample of them is
#: reported (a motion symmetric about an obstacle reaches its smallest distance twice, and which of
#: two equal distances coal returns smaller is float noise that may differ between runs).
TIE_M = 1e-9
#: A sample the broad phase finds no pair within ``best + SWEEP_M`` of [m] is dropped (more than
#: :data:`TIE_M`: coal's collision test at a security margin is not exact to the nanometre).
SWEEP_M = 1e-6


def smallest_clearance(samples: "_Samples", schedule: "_Schedule", t: np.ndarray, d: np.ndarray, k: np.ndarray,
                       exact: np.ndarray, screen: float) -> tuple[float, float, CollisionPair | None]:
    """The smallest exact distance at the samples [m] over every candidate pair of the cell, its time [s] and pair.

    ``t, d, k, exact``: every sample of the check in time order (its distance, pair, exact
    or not). A sample computed exactly below the ``screen`` distance holds it: the samples
    the screen cleared are at least ``screen`` away, the pairs the check left out proven
    farther. Else the branch and bound of the module doc. ``(inf, t0, None)`` for a cell
    without pairs.
    """
    cell = samples.cell
    exact_d = np.where(exact, d, np.inf)
    i = earliest_of_smallest(t, exact_d)
    if exact_d[i] < screen:
        return float(d[i]), float(t[i]), cell.candidates[int(k[i])]
    n_all, n0 = len(cell.candidates), len(cell.pairs)
    if n_all == 0:
        return float("inf"), float(t[0]), None

    def bounds(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        Q = samples.configurations(t[rows])
        lb = pair_lower_bounds(cell, Q)
        lb[:, n0:] = np.maximum(lb[:, n0:], cell.reach_bounds)
        return Q, lb

    row_lb = samples.cover_bounds(t)
    budget = np.interp(t, schedule.grid, schedule.budget)  # ∫ V dt from the window's start [m]
    found_d = np.full(t.size, np.inf)
    found_k = np.full(t.size, -1)
    done = np.zeros(t.size, dtype=bool)
    swept = np.full(t.size, np.inf)  # the distance each sample was last swept at [m]
    best = float("inf")
    first = samples.first
    if first is not None:  # the round and the sweep made before the screen, on the scheduled samples
        at = np.searchsorted(t, first.times)
        if np.array_equal(t[at], first.times):
            found_d[at[first.rows]], found_k[at[first.rows]], done[at[first.rows]] = first.dist, first.pair, True
            best = float(np.min(first.dist))
            if first.swept < np.inf:
                swept[at] = first.swept
                row_lb[at[~first.near]] = np.maximum(row_lb[at[~first.near]], first.swept + SWEEP_M)
            row_lb = np.maximum(row_lb, _budget_bound(first.dist, budget, at[first.rows]))
    while True:
        open_ = np.flatnonzero(~done & (row_lb <= best + TIE_M))
        stale = open_[swept[open_] > best]
        if stale.size > SMALLEST_BATCH:  # the broad phase drops the samples farther than best
            swept[stale] = best
            near = cell.in_collision(samples.configurations(t[stale]), margin=best + SWEEP_M)
            row_lb[stale[~near]] = np.maximum(row_lb[stale[~near]], best + SWEEP_M)
            open_ = np.flatnonzero(~done & (row_lb <= best + TIE_M))
        if not open_.size:
            break
        # spread over the open samples in time: each exact one bounds its neighbours
        rows = open_[np.unique(np.linspace(0, open_.size - 1, min(SMALLEST_BATCH, open_.size)).round().astype(int))]
        Q, lb = bounds(rows)
        # a sample's distance matters only below the smallest found (ties included): above it, a bound will do
        dist, pair, _, _ = exact_min_distance(cell, Q, lb=lb, n=n_all, cap=best + TIE_M)
        found_d[rows], found_k[rows], done[rows] = dist, pair, True
        best = min(best, float(np.min(dist)))
        row_lb = np.maximum(row_lb, _budget_bound(dist, budget, rows))
    i = earliest_of_smallest(t, found_d)
    return float(found_d[i]), float(t[i]), cell.candidates[int(found_k[i])] if found_k[i] >= 0 else None


def _budget_bound(dist: np.ndarray, budget: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``(len(budget),)`` lower bounds [m] of every sample's distance from the exact ones ``dist`` at ``rows``:
    ``D(t) ≥ D(s) − |∫_s^t V dt|``."""
    return np.max(dist[:, None] - np.abs(budget[None, :] - budget[rows][:, None]), axis=0)


@dataclass(frozen=True, eq=False)
class FirstRound:
    """The search's first round, made before a check without the cover screens its samples (:func:`first_round`).

    ``times`` the scheduled samples [s]; ``rows`` the ones computed, ``dist`` and ``pair`` coal's
    smallest distance over every candidate pair there; ``swept`` the distance [m] the broad phase
    swept every sample at (``inf``: not swept), ``near`` the samples it found a pair within it
    (all where not swept).
    """

    times: np.ndarray
    rows: np.ndarray
    dist: np.ndarray
    pair: np.ndarray
    swept: float
    near: np.ndarray


#: The first round's smallest distance must exceed the screen distance by this much [m] for its sweep to
#: stand in for the screen's own pass (coal's collision test at a security margin is not exact to 1e-6).
SWEEP_GAP = 1e-4


def first_round(cell: "Cell", Q: np.ndarray, times: np.ndarray, screen: float) -> FirstRound:
    """:data:`SMALLEST_BATCH` scheduled samples spread in time, exact over every candidate pair; where their
    smallest distance exceeds ``screen`` by :data:`SWEEP_GAP`, one broad-phase pass over every sample at it.

    A sample with no pair within that distance has none within ``screen`` either: the check's
    screen then looks only at the samples flagged here (the same verdicts, one pass instead of
    two), and the search at the samples flagged here.
    """
    n_all, n0 = len(cell.candidates), len(cell.pairs)
    rows = np.unique(np.linspace(0, times.size - 1, min(SMALLEST_BATCH, times.size)).round().astype(int))
    if n_all == 0 or not rows.size:
        return FirstRound(times, rows[:0], np.empty(0), np.empty(0, dtype=int), np.inf, np.ones(times.size, dtype=bool))
    lb = pair_lower_bounds(cell, Q[rows])
    lb[:, n0:] = np.maximum(lb[:, n0:], cell.reach_bounds)
    dist, pair, _, _ = exact_min_distance(cell, Q[rows], lb=lb, n=n_all)
    best = float(np.min(dist))
    if not best >= screen + SWEEP_GAP or times.size <= SMALLEST_BATCH:
        return FirstRound(times, rows, dist, pair, np.inf, np.ones(times.size, dtype=bool))
    near = np.asarray(cell.in_collision(Q, margin=best + SWEEP_M), dtype=bool)
    return FirstRound(times, rows, dist, pair, best, near)


def earliest_of_smallest(t: np.ndarray, d: np.ndarray) -> int:
    """The index of the earliest time ``t`` whose ``d`` is within :data:`TIE_M` of the smallest ``d``."""
    ties = np.flatnonzero(d <= np.min(d) + TIE_M)
    return int(ties[np.argmin(t[ties])]) if ties.size else 0
