"""Look-ahead: the best sequence of the next ``horizon`` candidates, by exhaustive branch and bound
(most picks, then earliest end), its first item (Han, Feng, Yu 2020 solve the same finite-horizon
problem by dynamic programming)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from pinarms.optim.line.rules.base import AssignmentRule, Decision, KernelForm
from pinarms.errors import InvalidInput

__all__ = ["LookAhead", "best_sequence", "MAX_HORIZON"]

#: Largest look-ahead horizon (orders of up to 8! sequences).
MAX_HORIZON = 8


def best_sequence(ready: float, items: list[int], intercept: Callable[[float, int], tuple[float, float] | None],
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


@dataclass(frozen=True)
class LookAhead(AssignmentRule):
    """The first item of the best order of the ``horizon`` (1..:data:`MAX_HORIZON`) candidates that
    can start soonest; the arm sleeps until that item's start when it is later than now."""

    horizon: int = 4
    name = "lookahead"
    plans_trays = False  # its intercepts know nothing of tray places

    def __post_init__(self) -> None:
        h = self.horizon
        if isinstance(h, bool) or not isinstance(h, (int, np.integer)) or not 1 <= h <= MAX_HORIZON:
            raise InvalidInput(f"look-ahead horizon must be an integer in 1..{MAX_HORIZON}, got {h!r}")

    @property
    def looks_beyond(self) -> int:
        return int(self.horizon)

    def prefer(self, d: Decision) -> np.ndarray:
        c = d.candidates
        order = np.argsort(c.start, kind="stable")[:self.horizon]
        _, _, seq = best_sequence(d.t, [int(c.index[j]) for j in order], d.intercept, int(self.horizon))
        first = int(order[0]) if not seq else int(np.flatnonzero(c.index == seq[0])[0])
        return np.array([first])

    def kernel_form(self) -> KernelForm | None:
        return self._form_of(LookAhead, KernelForm(horizon=int(self.horizon)))
