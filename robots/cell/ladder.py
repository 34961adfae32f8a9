"""The proof of the one continuous collision check: the Lipschitz ladder.

The rule
--------
Let ``E(s)`` be an *excess* along a motion — a distance minus what it must keep [m] — and
let it be 1-Lipschitz in the *travel* of the motion: between two states, ``E`` changes by
at most how far any point of the moving geometry can go (its approach budget) between them.
Between two samples ``a`` and ``b`` with travel budget ``B`` between them, a state that is
``β`` of travel past ``a`` (and so at most ``B − β`` before ``b``) has
``E ≥ max(E_a − β, E_b − (B − β)) ≥ (E_a + E_b − B) / 2``
(:func:`interval_bound`). So the interval keeps ``E ≥ 0`` everywhere — it is *proven* —
when ``E_a + E_b ≥ B``. Sample excesses need not be exact: any lower bound of each gives a
lower bound of the interval.

The ladder
----------
An interval not proven is halved: its midpoint is sampled and each half gets its own budget
(at most half of ``B`` for an even speed bound, the exact share otherwise). The halving runs
level by level, breadth first: all the intervals left at a level are halved together and
their midpoints evaluated in one batch (:func:`climb`), down to a finest level; an interval
still unproven there is not proven (never called clear). A sample that itself violates what
must be kept ends its intervals (the motion fails there).

The users, each with its own samples and excess (a :class:`Rungs`):

- :func:`pinarms.robots.cell.check_motion`: timed trajectories of a cell; samples in time, budget
  from the speed bounds, excess the smallest distance (coal) over the target clearance.
- :class:`pinarms.optim.motion.proof.LadderProof`: joint-space edges and timed paths of a planner;
  sample excesses are the margins' raises the batched screens pass at each level.
- The compiled edge proof on the sphere cover (:mod:`pinarms.optim.motion._fast_kernel`): the scalar
  rule :data:`interval_proven` (compiled on first use: numba is imported only then).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Protocol

import numpy as np

__all__ = ["Intervals", "LadderResult", "Rungs", "climb", "interval_bound", "interval_proven", "RELATIVE_SLACK"]

#: Relative slack of the compiled rule: a budget counts ``1 + RELATIVE_SLACK`` times over (a hair
#: over the rounding of the compiled excess, which sums many terms).
RELATIVE_SLACK = 1e-9


def interval_bound(e_a: Any, e_b: Any, budget: Any) -> Any:
    """``(e_a + e_b − budget) / 2``: the excess proven everywhere between two samples (module docstring).

    Scalars or arrays (element by element). ``interval_bound(...) >= 0`` exactly when
    ``e_a + e_b >= budget`` in floating point too (a difference of two floats is 0 only when
    they are equal, and halving a normal number keeps its sign).
    """
    return (e_a + e_b - budget) / 2.0


def _interval_proven(e_a: float, e_b: float, budget: float) -> bool:
    """Whether two samples of excess ``e_a``, ``e_b`` prove the interval of travel ``budget`` between them,
    ``budget`` counted :data:`RELATIVE_SLACK` over (the rule of :func:`interval_bound`, for compiled kernels)."""
    return e_a + e_b >= budget * (1.0 + RELATIVE_SLACK)


def __getattr__(name: str) -> Any:
    """``interval_proven``: :func:`_interval_proven` compiled by :func:`pinarms.compiled.jit` on first access."""
    if name == "interval_proven":
        from pinarms.compiled import jit

        compiled = jit(_interval_proven)
        globals()[name] = compiled
        return compiled
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass(frozen=True)
class Intervals:
    """Intervals between samples of one level: ``index (k, 3)`` [left sample, right sample, source]
    and ``value (k, 3)`` [budget, fa, fb] (two arrays: a level is taken and halved in a few calls).

    Attributes (views of those): ``left``, ``right``: the two end samples (indices into the
    excess array of :func:`climb`); ``budget``: the travel bound between them [m];
    ``source``: the given interval (0-based, in the samples' order) each lies in; ``fa``,
    ``fb``: its fractions of that interval (``0 ≤ fa < fb ≤ 1``).
    """

    index: np.ndarray
    value: np.ndarray

    left = property(lambda self: self.index[:, 0])
    right = property(lambda self: self.index[:, 1])
    source = property(lambda self: self.index[:, 2])
    budget = property(lambda self: self.value[:, 0])
    fa = property(lambda self: self.value[:, 1])
    fb = property(lambda self: self.value[:, 2])

    @classmethod
    def between(cls, budgets: np.ndarray) -> "Intervals":
        """The intervals between consecutive samples ``0..n`` of travel ``budgets (n,)``."""
        n = budgets.size
        index = np.empty((n, 3), dtype=int)
        index[:, 0] = index[:, 2] = np.arange(n)
        index[:, 1] = index[:, 0] + 1
        value = np.empty((n, 3))
        value[:, 0], value[:, 1], value[:, 2] = budgets, 0.0, 1.0
        return cls(index, value)

    def take(self, keep: np.ndarray) -> "Intervals":
        """The intervals where ``keep`` (bool mask or indices)."""
        return Intervals(self.index[keep], self.value[keep])

    def halves(self, first_new: int, left_budget: np.ndarray, right_budget: np.ndarray) -> "Intervals":
        """Both halves of each interval, in order (left, right, left, ...); the midpoint of interval ``k``
        is sample ``first_new + k``."""
        k = self.index.shape[0]
        index = np.repeat(self.index, 2, axis=0)
        index[0::2, 1] = index[1::2, 0] = first_new + np.arange(k)
        value = np.repeat(self.value, 2, axis=0)
        value[0::2, 0], value[1::2, 0] = left_budget, right_budget
        value[0::2, 2] = value[1::2, 1] = 0.5 * (self.fa + self.fb)
        return Intervals(index, value)


@dataclass(frozen=True)
class LadderResult:
    """What :func:`climb` proved.

    Attributes:
        proven: every interval proven (none unresolved, no failing or touching sample).
        level: the level the ladder reached.
        lower_bound: the smallest bound proven over the intervals it decided [m] (their
            :func:`interval_bound`; a touching end's own excess; ``inf`` if none).
        unresolved: an interval was still unproven at the finest level (or when the proof
            gave up, :meth:`Rungs.give_up`).
        source, fa, fb: the first unresolved interval, or the first interval ending at the
            failing sample (its given interval and fractions); ``-1, 0, 1`` when none.
        sample: the failing sample (:meth:`Rungs.evaluate`), else ``-1``.
    """

    proven: bool
    level: int
    lower_bound: float
    unresolved: bool = False
    source: int = -1
    fa: float = 0.0
    fb: float = 1.0
    sample: int = -1


class Rungs(Protocol):
    """The samples of one motion, for :func:`climb`: where the midpoints are and what their excess is."""

    def halve(self, intervals: Intervals) -> tuple[np.ndarray, np.ndarray]:
        """Make the midpoint sample of each interval (the next sample indices, in order); the budgets of both halves."""

    def evaluate(self, excess: np.ndarray, intervals: Intervals, level: int) -> tuple[np.ndarray, int]:
        """The excess of every sample (the new midpoints appended) at ``level``; the first failing sample or −1."""

    def give_up(self) -> bool:
        """Whether the proof must stop (a deadline): the intervals left are then unresolved."""


def climb(excess: Any, budgets: Any, rungs: Rungs, *, finest: int, level: int = 0,
          target: Callable[[np.ndarray], Any] | None = None, contact: float | None = None) -> LadderResult:
    """Prove the intervals between samples of excess ``excess (n+1,)`` and travel ``budgets (n,)``, level by level.

    At each level, an interval is proven when its :func:`interval_bound` reaches its target
    (``target(min(e_a, e_b))``, default 0), else halved (:meth:`Rungs.halve`) and its
    midpoint evaluated with the others of the level (:meth:`Rungs.evaluate`), down to level
    ``finest``; ``level``: the level of the given samples. ``contact``: an interval with an
    end at or below it is decided, not halved (a touching sample: not proven); ``None``: the
    rungs fail such samples themselves.
    """
    e = np.asarray(excess, dtype=float)
    intervals = Intervals.between(np.asarray(budgets, dtype=float))
    lower, touched = np.inf, False
    while True:
        e_a, e_b = e[intervals.left], e[intervals.right]
        bound = interval_bound(e_a, e_b, intervals.budget)
        low = np.minimum(e_a, e_b) if contact is not None or target is not None else None
        proven = bound >= (0.0 if target is None else target(low))
        if contact is not None:  # a touching end decides its interval: not proven, not halved
            touching = low <= contact
            proven &= ~touching
            lower = min(lower, _smallest(low[touching]))
            touched = touched or bool(touching.any())
            open_ = ~touching & ~proven
        else:
            open_ = ~proven
        lower = min(lower, _smallest(bound[proven]))
        if not open_.any():
            return LadderResult(not touched, level, lower)
        if level >= finest or rungs.give_up():
            first = int(np.argmax(open_))
            return LadderResult(False, level, min(lower, _smallest(bound[open_])), True, int(intervals.source[first]),
                                float(intervals.fa[first]), float(intervals.fb[first]))
        intervals = intervals.take(open_)
        level += 1
        left_budget, right_budget = rungs.halve(intervals)
        intervals = intervals.halves(e.size, np.asarray(left_budget, dtype=float),
                                     np.asarray(right_budget, dtype=float))
        e, failed = rungs.evaluate(e, intervals, level)
        if failed >= 0:
            first = int(np.argmax((intervals.left == failed) | (intervals.right == failed)))
            return LadderResult(False, level, lower, False, int(intervals.source[first]), float(intervals.fa[first]),
                                float(intervals.fb[first]), int(failed))


def _smallest(values: np.ndarray) -> float:
    """The smallest of ``values`` (``inf`` when empty)."""
    return float(values.min()) if values.size else np.inf
