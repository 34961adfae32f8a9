"""Shortest: the item whose task ends first (shortest processing time)."""

from __future__ import annotations

import numpy as np

from pinarms.optim.line.rules.base import AssignmentRule, Decision, KernelForm, startable

__all__ = ["Shortest"]


class Shortest(AssignmentRule):
    """The startable item whose pick ends first (ties: the earlier arrival, then the lower index)."""

    name = "shortest"

    def prefer(self, d: Decision) -> np.ndarray:
        s, c = startable(d), d.candidates
        return s[np.lexsort((c.index[s], c.t0[s], c.finish[s]))]

    def kernel_form(self) -> KernelForm | None:
        return self._form_of(Shortest, KernelForm(order=2))
