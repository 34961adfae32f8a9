"""Check the arms of a cell moving together, continuously in time.

Each arm follows its own joint trajectory with its own time offset (and, for a cyclic
schedule, its own period); arms without a motion hold still. :func:`check_motion` samples
the common time window and proves, between the samples, what it reports.

The time-step rule
------------------
For each arm, the speed of every point of its collision geometry is at most
``v(t) = Σ_j |q̇_j(t)| · ℓ_j``, with ``ℓ_j`` the *lever* of joint ``j`` (1 for a prismatic
joint; for a revolute joint, a bound of the distance from its origin to any point of the
geometry it carries, from the joint offsets, strokes and bounding spheres downstream, see
:func:`joint_levers`). Two bodies approach each other at most at ``V(t) = v_1(t) + v_2(t)``,
the two fastest arms' bounds (one moving arm: its ``v(t)``; :mod:`.speed_bound` says why).
Over a short step ``h`` the speed cannot exceed its larger end value by more than
``A h / 2`` (``A = Σ_j max|q̈_j| ℓ_j``, from the trajectory's exact acceleration peaks), nor
its arm's cap ``Σ_j max|q̇_j| ℓ_j`` (the exact velocity peaks). The samples are placed so that the
*approach budget* ``∫ V dt`` between two consecutive samples is at most ``margin``:
dense where the arms move fast, sparse where they dwell. On an interval ``[a, b]`` with
budget ``B`` the distance of every pair then stays at least ``(d_a + d_b − B) / 2``, where
``d`` is the smallest distance over the checked pairs at a sample (coal, exact): the
Lipschitz rule and its ladder of halvings, stated once in :mod:`.ladder`.

Each sample is first screened on the conservative sphere cover (:mod:`.cover`, compiled: it
contains every geometry, so what it proves is proven), then, where the cover is
inconclusive, by Pinocchio's C++ broad phase, with a safety distance
``required + margin``: a sample farther than that from every contact has
``d ≥ required + margin`` and needs no exact distance (its interval bound is then at least
``required``). The others get coal's exact smallest distance. An interval whose bound is
below its target (the required clearance, or 0 where a sample is already closer than it)
while its ends are clear is split in halves (same formula, half the budget) until it is
proven or a sample shows the violation, at most 6 times (budget ``margin / 64``); an interval
still unproven then (a distance within ``margin / 128`` of the target) counts as not clear.
Nothing thinner than ``margin`` is missed, and a reported "collision-free" or "clear" is a
proof, not a sampling guess.

The first contact (a sample with distance ≤ 0) is located by bisection to within 1e-6 s
and reported with its pair and depth.

Where the parts live (all importable from here): the schedule of the arms' motions
(:class:`ArmMotion`, :func:`configurations`, :func:`sample_motions`) in :mod:`.timeline`, the
speed bound (:func:`joint_levers`) in :mod:`.speed_bound`, the report (:class:`MotionCheck`,
:class:`Contact`) in :mod:`.motion_report`, the proof between samples (:func:`.ladder.climb`)
in :mod:`.ladder`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pinarms.errors import InvalidInput
from pinarms.robots.cell.collision import check_margin, exact_min_distance
from pinarms.robots.cell.ladder import Intervals, climb
from pinarms.robots.cell.motion_curves import moving_arm_curves
from pinarms.robots.cell.motion_minimum import TIE_M, FirstRound, first_round, smallest_clearance  # noqa: F401  (TIE_M, re-exported)
from pinarms.robots.cell.motion_report import Contact, MotionCheck
from pinarms.robots.cell.pairs import CollisionPair
from pinarms.robots.cell.speed_bound import joint_levers, speed_profile, travel_stops
from pinarms.robots.cell.timeline import (MAX_SAMPLES, MAX_TIME, ArmMotion, arm_motions, as_time, configurations,  # noqa: F401  (MAX_TIME, re-exported)
                       motion_window, sample_motions)

from pinarms.robots.cell.cell_model import CellModel

__all__ = ["ArmMotion", "Contact", "MotionCheck", "check_motion", "joint_levers", "motion_window", "sample_motions"]

#: Largest number of halvings of one interval (its approach budget then 1/64 of the margin);
#: an interval still unproven is reported as not clear (never as clear).
MAX_SPLITS = 6
#: Largest margin or clearance a check takes [m].
MAX_DISTANCE = 1e3
#: Largest number of bisection steps locating the first contact (1e-6 s over MAX_TIME needs 41).
MAX_BISECTIONS = 64


# ------------------------------------------------------------------ the check
def check_motion(
    cell: "CellModel",
    motions: Any,
    *,
    margin: float = 0.01,
    clearance: float = 0.0,
    window: tuple[float, float] | None = None,
    hold: Any = None,
    curve: bool = False,
    cover: bool = True,
) -> MotionCheck:
    """Check the arms' motions together, continuously in time (module doc: the rule).

    Args:
        motions: :class:`ArmMotion` objects, or ``{arm: trajectory}`` /
            ``{arm: (trajectory, offset[, period])}``.
        margin: the thinnest gap or obstacle the check resolves [m] (sets the time step).
        clearance: the distance every pair must keep [m] (``clear`` tells if proven).
        window: ``(t_start, t_end)`` [s]; default: from the earliest start to the latest
            end of the motions, or ``(0, longest period)`` when a motion is periodic.
        hold: cell configuration ``(nq,)`` of the arms without a motion (default :attr:`Cell.hold`:
            each arm's hold pose).
        curve: compute the exact smallest distance at every sample instead of only at the
            samples the screen flags, and each moving arm's distance to everything else per
            group of pairs (:attr:`MotionCheck.curves`, :mod:`.motion_curves`): what the
            clearance-over-time plot draws.
        cover: screen the samples on the sphere cover before the broad phase (same verdicts,
            faster); ``False``: the broad phase and coal alone — a check that shares no code
            with the cover, as :func:`pinarms.optim.plan_motion`'s re-check of a path the cover proved.

    Raises:
        InvalidInput: an unknown arm, a trajectory of the wrong width, bad numbers, or a
            window that would need more than 2 000 000 samples.
    """
    margin, required = _distances(margin, clearance)
    motions = arm_motions(cell, motions)
    hold_q = cell.hold if hold is None else cell.robot.check_q(hold)[0][0]
    t0, t1 = _window(motions, window)
    schedule = _schedule(cell, motions, t0, t1, margin)
    screen = required + margin
    # every pair not proven farther than the screen distance (Cell.pairs_for): the pairs left
    # out keep a distance above `screen` >= `required` in every configuration
    n_pairs = cell.pair_count(screen + 1e-6)
    pairs = cell.candidates[:n_pairs]
    left_out = cell.reach_bounds[n_pairs - len(cell.pairs):]
    samples = _Samples(cell, motions, hold_q, n_pairs, bool(cover))
    d = samples.screen(schedule.times, screen, curve)
    lower, unresolved = _prove(schedule, d, required, samples)
    first = _first_contact(samples, pairs)
    report = _report(samples, pairs, first, lower, unresolved, left_out, schedule, margin, required)
    if curve:  # the moving arms against everything else, at every sample (the clearance plot)
        curves, closest = moving_arm_curves(cell, [m.arm for m in motions], samples.configurations(report.times))
        report = dataclasses.replace(report, curves=curves, curve_pairs=closest)
    return report


def _distances(margin: Any, clearance: Any) -> tuple[float, float]:
    """The checked ``margin`` (> 0) and required ``clearance`` (≥ 0) [m], both at most :data:`MAX_DISTANCE`."""
    margin = check_margin(margin)
    if margin <= 0.0 or margin > MAX_DISTANCE:
        raise InvalidInput(f"margin must be > 0 m and at most {MAX_DISTANCE:g} m: it sets the time step, got {margin!r}")
    required = check_margin(clearance)
    if required > MAX_DISTANCE:
        raise InvalidInput(f"clearance must be at most {MAX_DISTANCE:g} m, got {clearance!r}")
    return margin, required


def _window(motions: list[ArmMotion], window: Any) -> tuple[float, float]:
    """The checked window ``(t0, t1)`` [s] (default :func:`motion_window`), ``t1 >= t0``."""
    if window is None:
        window = motion_window(motions)
    try:
        w0, w1 = window
    except (TypeError, ValueError):
        raise InvalidInput(f"window must be (t_start, t_end) [s], got {window!r}") from None
    t0, t1 = as_time(w0, "window start"), as_time(w1, "window end")
    if t1 < t0:
        raise InvalidInput(f"window must be (t_start, t_end) with t_end >= t_start, got {window!r}")
    return t0, t1


@dataclass(frozen=True, eq=False)
class _Schedule:
    """Where a check samples: a fine ``grid`` [s], the approach ``budget`` ``∫ V dt`` [m] on it, the sample ``times``."""

    grid: np.ndarray
    budget: np.ndarray
    times: np.ndarray
    dt: float
    speed_bound: float
    window: tuple[float, float]

    def budget_between(self, ta: np.ndarray, tb: np.ndarray) -> np.ndarray:
        """The approach budget [m] spent between times ``ta`` and ``tb`` [s] (interpolated on the grid)."""
        return np.interp(tb, self.grid, self.budget) - np.interp(ta, self.grid, self.budget)


def _schedule(cell: "CellModel", motions: list[ArmMotion], t0: float, t1: float, margin: float) -> _Schedule:
    """A fine grid at the global speed bound's step, then a sample every ``margin`` of approach budget.

    Raises:
        InvalidInput: the window would need more than :data:`MAX_SAMPLES` grid points.
    """
    _, V_global = speed_profile(cell, motions, np.array([t0, max(t1, t0 + 1e-9)]))
    if V_global <= 0.0 or t1 == t0:
        grid = np.array([t0]) if t1 == t0 else np.array([t0, t1])
        budget = np.zeros(grid.size)
        dt = max(t1 - t0, 0.0)
    else:
        dt = margin / V_global
        n = int(math.ceil((t1 - t0) / dt))
        if n + 1 > MAX_SAMPLES:
            raise InvalidInput(
                f"the window of {t1 - t0:.3g} s needs {n + 1} samples at dt = {dt:.3g} s (speed bound "
                f"{V_global:.3g} m/s); check a shorter window or a larger margin (at most {MAX_SAMPLES} samples)"
            )
        grid = np.linspace(t0, t1, n + 1)
        V, _ = speed_profile(cell, motions, grid)
        budget = np.concatenate([[0.0], np.cumsum(V * np.diff(grid))])
    return _Schedule(grid, budget, grid[travel_stops(budget, margin)], dt, V_global, (t0, t1))


class _Samples:
    """Every sample of one check: time [s], smallest distance [m], closest pair (−1: screened), exact or not."""

    def __init__(self, cell: "CellModel", motions: list[ArmMotion], hold_q: np.ndarray, n_pairs: int,
                 cover: bool = True) -> None:
        self.cell, self.motions, self.hold_q, self.n_pairs, self.cover = cell, motions, hold_q, n_pairs, cover
        self.first: FirstRound | None = None  # the smallest clearance's first round (.motion_minimum)
        self.t: list = []
        self.d: list = []
        self.k: list = []
        self.x: list = []

    def configurations(self, ts: np.ndarray) -> np.ndarray:
        """The cell configurations ``(len(ts), nq)`` at cell times ``ts``."""
        return configurations(self.cell, self.motions, ts, self.hold_q)

    def screen(self, times: np.ndarray, screen: float, curve: bool) -> np.ndarray:
        """The scheduled samples: broad-phase screen at ``screen`` [m], exact distances where it flags (all with ``curve``).

        Returns the distances ``(len(times),)``: exact, or ``screen`` where the screen cleared the sample.
        """
        Q = self.configurations(times)
        # without the cover: the smallest clearance's first round and sweep (one broad-phase pass at the
        # smallest distance found) first; a sample it clears is farther than the screen too
        near = np.ones(times.size, dtype=bool)
        if not curve and not (self.cover and times.size >= COVER_ROWS):
            self.first = first_round(self.cell, Q, times, screen)
            near = self.first.near
        exact = np.ones(times.size, dtype=bool) if curve else np.zeros(times.size, dtype=bool)
        if not curve and near.any():
            exact[near] = self.flag(Q[near], screen + 1e-6)
        d = np.full(times.size, screen)
        k = np.full(times.size, -1, dtype=int)
        if exact.any():
            de, ke, _, _ = exact_min_distance(self.cell, Q[exact], n=self.n_pairs)
            d[exact], k[exact] = de, ke
        self.t, self.d, self.k, self.x = list(times), list(d), list(k), list(exact)
        return d

    def flag(self, Q: np.ndarray, screen: float) -> np.ndarray:
        """``(N,)`` bool: the configurations not proven farther than ``screen`` [m] from every contact.

        The sphere cover first (:mod:`.cover`: it contains every geometry, so a configuration it
        proves is proven), then Pinocchio's broad phase at ``screen`` on the rest: the same rows
        as the broad phase alone, fewer of them checked by it.
        """
        flagged = np.ones(Q.shape[0], dtype=bool)
        if self.cover and Q.shape[0] >= COVER_ROWS:
            cover, pair_set = _cover_pairs(self.cell, self.n_pairs)
            flagged = ~cover.screen(Q, pair_set, np.full(self.n_pairs, screen))
        if flagged.any():
            flagged[flagged] = self.cell.in_collision(Q[flagged], margin=screen)
        return flagged

    def cover_bounds(self, ts: np.ndarray) -> np.ndarray:
        """``(len(ts),)`` lower bounds [m] of each sample's smallest distance over every candidate pair.

        On the sphere cover where the check screens on it (compiled, tight: a bound ``min_k d_k``),
        else ``-inf`` (a check run with ``cover=False`` shares no code with the cover, its minimum
        included: :mod:`.motion_minimum` then bounds the samples by the broad phase and the budget).
        """
        if not (self.cover and ts.size >= COVER_ROWS):
            return np.full(ts.size, -np.inf)
        n = len(self.cell.candidates)
        cover, pair_set = _cover_pairs(self.cell, n)
        return np.concatenate([cover.excess(self.configurations(ts[a:a + BOUND_ROWS]), pair_set, np.zeros(n))
                               for a in range(0, ts.size, BOUND_ROWS)])

    def evaluate(self, ts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Exact smallest distances and closest pairs at extra times ``ts`` (kept as samples)."""
        ds, ks, _, _ = exact_min_distance(self.cell, self.configurations(ts), n=self.n_pairs)
        self.t.extend(ts)
        self.d.extend(ds)
        self.k.extend(ks)
        self.x.extend([True] * ts.size)
        return ds, ks

    def collected(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Times, distances, pair indices and exact flags of every sample so far, in time order."""
        order = np.argsort(np.asarray(self.t), kind="stable")
        return (np.asarray(self.t)[order], np.asarray(self.d)[order],
                np.asarray(self.k, dtype=int)[order], np.asarray(self.x, dtype=bool)[order])


#: Fewest samples screened on the sphere cover first (fewer: the broad phase alone); rows of cover bounds per block.
COVER_ROWS, BOUND_ROWS = 8, 4096


def _cover_pairs(cell: "CellModel", n_pairs: int) -> tuple[Any, Any]:
    """The cell's sphere cover and its :class:`.cover.PairSet` of the first ``n_pairs`` candidates (kept with the cell)."""
    from pinarms.robots.cell.cover import link_cover, pair_arrays

    # keyed by the pairs themselves: a cell of fewer pairs (Cell.with_pairs) shares this dict, not its pairs
    pair_a, pair_b = pair_arrays(cell.candidates[:n_pairs])
    key = (pair_a.tobytes(), pair_b.tobytes())
    cache = cell.memo("motion cover pairs", dict)
    if key not in cache:
        cover = link_cover(cell)
        cache[key] = (cover, cover.prepare(pair_a, pair_b))
    return cache[key]


class _TimeRungs:
    """The samples of a check for the ladder (:func:`.ladder.climb`): midpoints in time, budgets from the schedule,
    exact distances (:meth:`_Samples.evaluate`)."""

    def __init__(self, schedule: _Schedule, samples: _Samples) -> None:
        self.schedule, self.samples = schedule, samples
        self.t = np.asarray(schedule.times, dtype=float)  # the time of each sample of the ladder [s]
        self.mids = np.empty(0)

    def halve(self, intervals: Intervals) -> tuple[np.ndarray, np.ndarray]:
        ta, tb = self.t[intervals.left], self.t[intervals.right]
        self.mids = 0.5 * (ta + tb)
        self.t = np.concatenate([self.t, self.mids])
        return self.schedule.budget_between(ta, self.mids), self.schedule.budget_between(self.mids, tb)

    def evaluate(self, excess: np.ndarray, intervals: Intervals, level: int) -> tuple[np.ndarray, int]:
        return np.concatenate([excess, self.samples.evaluate(self.mids)[0]]), -1

    def give_up(self) -> bool:
        return False


def _prove(schedule: _Schedule, d: np.ndarray, required: float, samples: _Samples) -> tuple[float, bool]:
    """Prove every interval between samples; the proven lower bound [m] and whether an interval stayed unproven.

    The ladder of :mod:`.ladder` on the distances: an interval's bound ``(d_a + d_b − B) / 2``
    must reach its target (the required clearance, or 0 where a sample is already below
    it), else it is split in halves, at most :data:`MAX_SPLITS` times; one level at a time,
    all the midpoints of a level in one batched evaluation. Intervals with a sample in
    contact are left to :func:`_first_contact`.
    """
    rungs = _TimeRungs(schedule, samples)
    result = climb(d, schedule.budget_between(rungs.t[:-1], rungs.t[1:]), rungs, finest=MAX_SPLITS,
                   target=lambda low: np.where(low >= required, required, 0.0), contact=0.0)
    lower = min(float(d.min()) if d.size else np.inf, result.lower_bound)
    return lower, result.unresolved


def _first_contact(samples: _Samples, pairs: tuple[CollisionPair, ...]) -> Contact | None:
    """The first sample in contact, located by bisection from the last clear sample before it to 1e-6 s; else ``None``."""
    all_t, all_d, all_k, _ = samples.collected()
    contact_idx = np.flatnonzero(all_d <= 0.0)
    if not contact_idx.size:
        return None
    i = int(contact_idx[0])
    t_hit, d_hit, k_hit = all_t[i], all_d[i], all_k[i]
    if i > 0:  # bisect between the last clear sample and the first in contact
        ta, tb = all_t[i - 1], all_t[i]
        for _ in range(MAX_BISECTIONS):
            tm = 0.5 * (ta + tb)
            if tb - ta <= 1e-6 or not ta < tm < tb:
                break
            dm, km = samples.evaluate(np.array([tm]))
            if dm[0] <= 0.0:
                tb, d_hit, k_hit = tm, dm[0], km[0]
            else:
                ta = tm
        t_hit = tb
    return Contact(
        time=float(t_hit),
        pair=pairs[int(k_hit)],
        depth=float(max(-d_hit, 0.0)),
        q=samples.configurations(np.array([t_hit]))[0],
    )


def _report(samples: _Samples, pairs: tuple[CollisionPair, ...], first: Contact | None, lower: float, unresolved: bool,
            left_out: np.ndarray, schedule: _Schedule, margin: float, required: float) -> MotionCheck:
    """The :class:`MotionCheck`: every sample, the first contact, the verdicts and the proven bound.

    The bound is the intervals' (:func:`_prove`), lowered to every sample's distance and to
    the smallest bound ``left_out`` of the pairs the check left out.
    """
    all_t, all_d, all_k, all_x = samples.collected()
    lower = min(lower, float(all_d.min()))
    if left_out.size:  # the pairs left out are proven at least this far apart
        lower = min(lower, float(left_out[0]))
    d_min, t_min, pair_min = smallest_clearance(samples, schedule, all_t, all_d, all_k, all_x, margin + required)
    collision_free = first is None and lower > 0.0
    clear = first is None and lower >= required and not unresolved
    return MotionCheck(
        collision_free=bool(collision_free),
        clear=bool(clear),
        first_contact=first,
        max_depth=float(max(0.0, -all_d.min())),
        min_clearance=d_min,
        min_clearance_time=t_min,
        min_clearance_pair=pair_min,
        lower_bound=float(lower),
        times=all_t,
        clearance=all_d,
        pair_index=all_k,
        exact=all_x,
        dt=float(schedule.dt),
        speed_bound=float(schedule.speed_bound),
        margin=margin,
        required=required,
        window=schedule.window,
        pairs=pairs,
    )
