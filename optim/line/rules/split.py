"""Split: a fixed load split, arm ``k`` of ``n`` takes only every ``n``-th item (``index mod n == k``;
FANUC's percentage split with equal shares), first in window among them."""

from __future__ import annotations

import numpy as np

from pinarms.optim.line.rules.base import KernelForm
from pinarms.optim.line.rules.first import FirstInWindow

__all__ = ["Split"]


class Split(FirstInWindow):
    """First in window among the items whose index is the arm's position modulo the arms."""

    name = "split"

    def takes(self, arm: int, n_arms: int, index: np.ndarray, w: np.ndarray, width: float) -> np.ndarray:
        return index % n_arms == arm

    def kernel_form(self) -> KernelForm | None:
        return self._form_of(Split, KernelForm(order=0, share=2))
