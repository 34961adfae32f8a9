"""First in window: the item furthest downstream, the one that leaves the window soonest (FIFO)."""

from __future__ import annotations

import numpy as np

from pinarms.optim.line.rules.base import AssignmentRule, Decision, KernelForm, startable

__all__ = ["FirstInWindow"]


class FirstInWindow(AssignmentRule):
    """The startable item that arrived first (ties: the lower index)."""

    name = "first"

    def prefer(self, d: Decision) -> np.ndarray:
        s, c = startable(d), d.candidates
        return s[np.lexsort((c.index[s], c.t0[s]))]

    def kernel_form(self) -> KernelForm | None:
        return self._form_of(FirstInWindow, KernelForm(order=0))
