"""Bands: arm ``k`` of ``n`` takes only the items in band ``k`` of ``n`` equal bands across the belt
(Schneider's balancing by band), first in window within its band."""

from __future__ import annotations

import numpy as np

from pinarms.optim.line.rules.base import KernelForm
from pinarms.optim.line.rules.first import FirstInWindow

__all__ = ["Bands"]


class Bands(FirstInWindow):
    """First in window among the items of the arm's band across the belt (upstream arm: the band at
    ``w = -width/2``)."""

    name = "bands"
    needs_width = True

    def takes(self, arm: int, n_arms: int, index: np.ndarray, w: np.ndarray, width: float) -> np.ndarray:
        band = np.clip(((w + width / 2.0) / width * n_arms).astype(int), 0, n_arms - 1)
        return band == arm

    def kernel_form(self) -> KernelForm | None:
        return self._form_of(Bands, KernelForm(order=0, share=1))
