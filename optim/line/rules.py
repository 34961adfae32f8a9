"""Assignment rules: which item an idle arm takes next.

Each rule sees the candidates of one arm at its decision time ``t`` — items not yet taken
whose pick is feasible from the arm's state — as arrays (:class:`Candidates`), and returns
the index of the one to start now, or asks to wait. The rules (names as in the literature
and in the commercial tools, ``LINE_NOTES.md``):

- ``"first"``: first in window — the item furthest downstream (leaves the window soonest; FIFO).
- ``"nearest"``: the item nearest the tool at ``t`` (ABB/Schneider "nearest").
- ``"shortest"``: the item whose task ends first (shortest processing time).
- ``"bands"``: arm ``k`` of ``n`` takes only items in band ``k`` of ``n`` equal bands across the
  belt (Schneider's balancing by band), first in window within its band.
- ``"split"``: a fixed load split: arm ``k`` takes only every ``n``-th item (``index mod n == k``;
  FANUC's percentage split with equal shares).
- ``"lookahead"``: the best sequence of the next ``horizon`` candidates, by exhaustive
  branch and bound (most picks, then earliest end), its first item (Han, Feng, Yu 2020 solve
  the same finite-horizon problem by dynamic programming).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from pinarms.errors import InvalidInput

__all__ = ["RULES", "Rule", "Candidates", "choose_simple", "rank_simple", "best_sequence"]

RULES = ("first", "nearest", "shortest", "bands", "split", "lookahead")


@dataclass(frozen=True)
class Rule:
    """An assignment rule: ``name`` in :data:`RULES`; ``horizon``: items the look-ahead orders (1..8)."""

    name: str = "first"
    horizon: int = 4

    def __post_init__(self) -> None:
        if self.name not in RULES:
            raise InvalidInput(f"unknown assignment rule {self.name!r}; known: {', '.join(RULES)}")
        if isinstance(self.horizon, bool) or not isinstance(self.horizon, (int, np.integer)) or \
                not 1 <= self.horizon <= 8:
            raise InvalidInput(f"look-ahead horizon must be an integer in 1..8, got {self.horizon!r}")


@dataclass(frozen=True)
class Candidates:
    """Feasible picks of one arm at its decision time (arrays of shape (k,)): item ``index``,
    ``start`` [s] (when the arm must leave its box), ``meet`` [s] (rendezvous at the
    pre-grasp point), ``finish`` [s] (back at rest at the box), ``t0`` [s], ``w`` [m],
    ``distance`` [m] from the tool to the item at decision time."""

    index: np.ndarray
    start: np.ndarray
    meet: np.ndarray
    finish: np.ndarray
    t0: np.ndarray
    w: np.ndarray
    distance: np.ndarray


def rank_simple(rule: str, c: Candidates) -> np.ndarray:
    """Positions in ``c`` in a simple rule's order of preference (``c`` holds startable items only)."""
    if rule in ("first", "bands", "split"):
        return np.lexsort((c.index, c.t0))
    if rule == "nearest":
        return np.lexsort((c.index, c.t0, c.distance))
    if rule == "shortest":
        return np.lexsort((c.index, c.t0, c.finish))
    raise InvalidInput(f"rule {rule!r} is not a simple rule")


def choose_simple(rule: str, c: Candidates) -> int:
    """Position in ``c`` of the item a simple rule starts now (its first preference)."""
    return int(rank_simple(rule, c)[0])


def best_sequence(ready: float, items: list[int], intercept: Callable[[float, int], Any],
                  horizon: int) -> tuple[int, float, list[int]]:
    """Branch and bound over orders of up to ``horizon`` of ``items`` from an arm ready at ``ready``.

    ``intercept(t, i)`` gives ``(start, finish)`` of item ``i`` for the arm ready at ``t`` or
    None when it can no longer be picked. Returns (picks, end time, sequence) of the best order:
    most picks, then earliest end, then the earliest first start.
    """
    pool = items[:horizon]
    best: list[Any] = [(-1, np.inf), []]

    def dfs(t: float, left: tuple[int, ...], seq: list[int]) -> None:
        key = (len(seq), -t)
        if (key[0], key[1]) > (best[0][0], -best[0][1]):
            best[0], best[1] = (len(seq), t), list(seq)
        bound = len(seq) + len(left)
        if bound < best[0][0] or (bound == best[0][0] and t >= best[0][1]):
            return  # bound: even picking every remaining item cannot beat the best
        for k, i in enumerate(left):
            r = intercept(t, i)
            if r is None:
                continue
            dfs(r[1], left[:k] + left[k + 1:], seq + [i])

    dfs(ready, tuple(pool), [])
    return best[0][0], best[0][1], best[1]
