"""The continuous proof of a :class:`.checker.MotionChecker`: a ladder of batched screens over samples.

Between two samples with travel ``B`` between them the excess ``E = min_k (d_k − margin_k)``
(1-Lipschitz in travel) keeps ``E ≥ (E_a + E_b − B)/2``; samples that pass with their
margins raised by ``s`` have ``E ≥ s``. :meth:`LadderProof.prove` screens the samples of a
motion at the coarsest level, halves the intervals not proven and screens their ends with
half the raise, down to ``step / 2^MAX_SPLITS`` (the module docstring of :mod:`.checker`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

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

    def prove(self, X: np.ndarray, budgets: np.ndarray, midpoint: Any, convex: bool = False, top: int = 0) -> Verdict:
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
        if self._timed_out():
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
        flags = np.ones(order.size, dtype=bool) if tight else self.coal_collides(Q[order], level, stop=True)
        if not flags.any():
            return Verdict(True)
        first = int(order[int(np.argmax(flags))])
        if self.batch_collides(Q[first][None], "margin")[0]:
            return Verdict(False, first)
        hits = self.batch_collides(Q[order], "margin", stop=True)
        if hits.any():
            return Verdict(False, int(order[int(np.argmax(hits))]))
        # every sample keeps the margins: prove the intervals between them, level by level
        states = [x for x in X]
        qs = [q for q in Q]
        lb = np.full(N, self.step / 2.0 ** (level + 1))  # proven lower bound of each sample's excess
        lb[order if tight else order[self.coal_collides(Q[order], level)]] = 0.0
        # intervals: (left sample, right sample, budget, source interval, fraction a, fraction b)
        todo = [(i, i + 1, float(budgets[i]), i, 0.0, 1.0) for i in range(N - 1)]
        while True:
            todo = [iv for iv in todo if lb[iv[0]] + lb[iv[1]] < iv[2]]
            if not todo:
                return Verdict(True, exact=level)
            if level >= MAX_SPLITS or self._timed_out():
                i = todo[0][3]
                return Verdict(False, i, todo[0][4], level)
            level += 1
            s_level = self.step / 2.0 ** (level + 1)
            nxt = []
            new_states = []
            for a, b, B, src, fa, fb in todo:
                xm, bl, br = midpoint(src, fa, fb, B)
                m = len(states) + len(new_states)
                new_states.append(np.asarray(xm, dtype=float))
                fm = 0.5 * (fa + fb)
                nxt.append((a, m, float(bl), src, fa, fm))
                nxt.append((m, b, float(br), src, fm, fb))
            Xm = np.array(new_states)
            inside = self.within_limits(Xm)
            if not inside.all():
                k = int(np.argmin(inside))
                return Verdict(False, todo[k][3], 0.5 * (todo[k][4] + todo[k][5]), level)
            Qm = self.full(Xm)
            states.extend(Xm)
            qs.extend(Qm)
            lb = np.concatenate([lb, np.full(len(new_states), -1.0)])
            ends = sorted({k for iv in nxt for k in iv[:2] if lb[k] < s_level})
            Qe = np.array([qs[k] for k in ends])
            # the cover alone screens the coarse levels; coal has the last word on the fine ones
            passed = self.covered(Qe, level) if tight and level <= COVER_LEVELS else ~self.batch_collides(Qe, level)
            for k, ok in zip(ends, passed):
                if ok:
                    lb[k] = s_level
            unknown = [k for k, ok in zip(ends, passed) if not ok and lb[k] < 0.0]
            if unknown:
                bad = self.batch_collides(np.array([qs[k] for k in unknown]), "margin")
                if bad.any():
                    k = unknown[int(np.argmax(bad))]
                    iv = next(iv for iv in nxt if k in iv[:2])
                    return Verdict(False, iv[3], iv[4], level)
                lb[unknown] = 0.0
            todo = nxt
