"""The continuous proof of a :class:`.checker.MotionChecker`: a ladder of batched screens over samples.

Between two samples with travel ``B`` between them the excess ``E = min_k (d_k − margin_k)``
(1-Lipschitz in travel) keeps ``E ≥ (E_a + E_b − B)/2`` (the rule and its ladder:
:mod:`pinarms.robots.cell.ladder`); samples that pass with their margins raised by ``s`` have
``E ≥ s``. :meth:`LadderProof.prove` screens the samples of a motion at the coarsest level,
then climbs the ladder (:func:`pinarms.robots.cell.ladder.climb`): the intervals not proven are
halved and their ends screened with half the raise, down to ``step / 2^MAX_SPLITS`` (the
module docstring of :mod:`.checker`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.robots.cell.ladder import Intervals, climb

__all__ = ["LadderProof", "Verdict", "GiveUp", "coarse_first", "MAX_SPLITS", "COARSE_LEVELS", "COVER_LEVELS"]

#: Finest level of the proof: intervals of ``step / 2^MAX_SPLITS`` travel; still unproven there: invalid.
MAX_SPLITS = 10
#: An edge is first sampled up to ``2^COARSE_LEVELS`` steps apart (screens raised accordingly).
COARSE_LEVELS = 3
#: Levels up to this one are screened by the sphere cover alone where it is tight
#: (:attr:`MotionChecker.cover_decides_screens`); finer levels go to coal where it is inconclusive.
COVER_LEVELS = 0


class GiveUp(Exception):
    """A proof passed its checker's deadline."""


@dataclass(frozen=True)
class Verdict:
    """What a proof over samples found: ``ok`` and, when not, the first failing sample (index, fraction)."""

    ok: bool
    first_bad: int = -1
    fraction: float = 1.0
    exact: int = 0


@lru_cache(maxsize=4096)
def _coarse_first(n: int) -> np.ndarray:
    order = _coarse_order(n)
    order.flags.writeable = False
    return order


def coarse_first(n: int) -> np.ndarray:
    """Indices 0..n ordered ends first, then midpoints of ever finer halvings (bit-reversed order)."""
    return _coarse_first(int(n))


def _coarse_order(n: int) -> np.ndarray:
    """Indices 0..n ordered ends first, then midpoints of ever finer halvings (bit-reversed order)."""
    if n <= 0:
        return np.zeros(1, dtype=int)
    bits = max(1, int(math.ceil(math.log2(n))))
    k = np.arange(1 << bits)
    rev = np.zeros_like(k)
    for b in range(bits):
        rev |= ((k >> b) & 1) << (bits - 1 - b)
    inner = (rev * n) >> bits  # bit-reversed fractions of the interval, floored to samples
    order = np.concatenate([[0, n], inner])
    _, first = np.unique(order, return_index=True)
    return order[np.sort(first)]



class LadderProof:
    """The ladder of batched screens (a mixin of :class:`.checker.MotionChecker`)."""

    def prove(self, X: np.ndarray, budgets: np.ndarray, midpoint: ArrayLike, convex: bool = False, top: int = 0) -> Verdict:
        """Prove that the motion through samples ``X (N, n[+1])`` keeps every margin (:meth:`_prove`);
        past :attr:`deadline` the proof gives up: not valid."""
        try:
            return self._prove(X, budgets, midpoint, convex, top)
        except GiveUp:
            return Verdict(False, -1, 0.0)

    def _prove(self, X: np.ndarray, budgets: np.ndarray, midpoint: Any, convex: bool = False, top: int = 0) -> Verdict:
        """Prove that the motion through samples ``X (N, n[+1])`` keeps every margin.

        ``budgets (N-1,)``: travel bound [m] between consecutive samples (each ≤ ``step``);
        ``midpoint(i, a, b, B) -> (x, B_left, B_right)``: the state between fractions ``a`` and
        ``b`` of interval ``i`` (whose budget is ``B``) and the budgets of the two halves.
        ``convex``: the samples lie on a straight edge between two states within the joint
        limits (then every sample is within them: the limits box is convex). ``top``: the
        level of the given samples (0: budgets ≤ ``step``; −k: budgets ≤ ``step · 2^k``).

        The proof is a ladder of batched screens (module docstring): at level ``L`` an
        interval's budget is at most ``step / 2^L`` and its two ends are screened with the
        margins raised by ``s_L = step / 2^(L+1)``; both passing proves the interval (the
        excess stays ``≥ (s_L + s_L − B)/2 ≥ 0``). An interval not proven is halved; a sample
        closer than the margins themselves ends the proof (invalid), and so does an interval
        still unproven at level :data:`MAX_SPLITS`.
        """
        X = np.atleast_2d(np.asarray(X, dtype=float))
        N = X.shape[0]
        if self.timed_out():
            return Verdict(False, -1, 0.0)
        if not convex:
            inside = self.within_limits(X)
            if not inside.all():
                return Verdict(False, int(np.argmin(inside)), 0.0)
        Q = self.full(X)
        level = int(top)
        order = coarse_first(N - 1)
        order = order[~self.covered(Q[order], level)]  # what the cover leaves to coal, coarse-first
        if order.size == 0:
            return Verdict(True)
        tight = self.cover_decides_screens and level <= COVER_LEVELS
        flags = np.ones(order.size, dtype=bool) if tight else self.exact_collides(Q[order], level, stop=True)
        if not flags.any():
            return Verdict(True)
        first = int(order[int(np.argmax(flags))])
        if self.batch_collides(Q[first][None], "margin")[0]:
            return Verdict(False, first)
        hits = self.batch_collides(Q[order], "margin", stop=True)
        if hits.any():
            return Verdict(False, int(order[int(np.argmax(hits))]))
        # every sample keeps the margins: prove the intervals between them, level by level
        lb = np.full(N, self.step / 2.0 ** (level + 1))  # proven lower bound of each sample's excess
        lb[order if tight else order[self.exact_collides(Q[order], level)]] = 0.0
        rungs = _ScreenRungs(self, Q, midpoint, tight)
        result = climb(lb, np.asarray(budgets, dtype=float), rungs, finest=MAX_SPLITS, level=level)
        if result.proven:
            return Verdict(True, exact=result.level)
        # a midpoint outside the limits is reported where it lies, a failing screen from its interval's start
        return Verdict(False, result.source, result.fb if rungs.outside else result.fa, result.level)


class _ScreenRungs:
    """The samples of one proof for the ladder (:func:`pinarms.robots.cell.ladder.climb`): midpoints from the
    caller's ``midpoint``, and as excess of a sample the raise of the margins its screen passes at
    each level (``s_L = step / 2^(L+1)``; 0: it keeps the margins only)."""

    def __init__(self, checker: Any, Q: np.ndarray, midpoint: Any, tight: bool) -> None:
        self.checker, self.midpoint, self.tight = checker, midpoint, tight
        self.Q = Q  # the cell configuration of every sample
        self.new = np.empty((0, Q.shape[1]))
        #: the last failing midpoint was outside the joint limits (not too close)
        self.outside = False

    def halve(self, intervals: Intervals) -> tuple[np.ndarray, np.ndarray]:
        states, left, right = [], [], []
        for src, fa, fb, B in zip(intervals.source.tolist(), intervals.fa.tolist(), intervals.fb.tolist(),
                                  intervals.budget.tolist()):
            xm, bl, br = self.midpoint(src, fa, fb, B)
            states.append(np.asarray(xm, dtype=float))
            left.append(float(bl))
            right.append(float(br))
        self.new = np.array(states)
        return np.array(left), np.array(right)

    def evaluate(self, lb: np.ndarray, intervals: Intervals, level: int) -> tuple[np.ndarray, int]:
        """Screen the ends of ``intervals`` not yet proven ``s_L`` clear (the new midpoints first checked
        against the limits); a midpoint that fails the margins themselves fails the proof."""
        c = self.checker
        inside = c.within_limits(self.new)
        if not inside.all():
            self.outside = True
            return lb, lb.size + int(np.argmin(inside))
        self.Q = np.concatenate([self.Q, c.full(self.new)])
        lb = np.concatenate([lb, np.full(len(self.new), -1.0)])
        s_level = c.step / 2.0 ** (level + 1)
        is_end = np.zeros(lb.size, dtype=bool)
        is_end[intervals.left] = is_end[intervals.right] = True
        ends = np.flatnonzero(is_end & (lb < s_level))
        # the cover alone screens the coarse levels; coal has the last word on the fine ones
        Qe = self.Q[ends]
        passed = c.covered(Qe, level) if self.tight and level <= COVER_LEVELS else ~c.batch_collides(Qe, level)
        lb[ends[passed]] = s_level
        unknown = ends[~passed & (lb[ends] < 0.0)]
        if unknown.size:
            bad = c.batch_collides(self.Q[unknown], "margin")
            if bad.any():
                return lb, int(unknown[int(np.argmax(bad))])
            lb[unknown] = 0.0
        return lb, -1

    def give_up(self) -> bool:
        """Past the checker's deadline (:meth:`.coal_batches.CoalBatches.timed_out`)."""
        return self.checker.timed_out()
