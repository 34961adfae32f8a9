"""Nearest: the item nearest the tool at rest at decision time (ABB's and Schneider's "nearest")."""

from __future__ import annotations

import numpy as np

from pinarms.optim.line.rules.base import AssignmentRule, Decision, KernelForm, startable

__all__ = ["Nearest"]


class Nearest(AssignmentRule):
    """The startable item nearest the tool (ties: the earlier arrival, then the lower index)."""

    name = "nearest"

    def prefer(self, d: Decision) -> np.ndarray:
        s, c = startable(d), d.candidates
        return s[np.lexsort((c.index[s], c.t0[s], c.distance[s]))]

    def kernel_form(self) -> KernelForm | None:
        return self._form_of(Nearest, KernelForm(order=1))
