"""Seeded random placements of a cylinder and a box, for tests of the cover's cylinder–box bounds against coal."""

from __future__ import annotations

import numpy as np


def _rotation(rng: np.random.Generator) -> np.ndarray:
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    return R * np.sign(np.linalg.det(R))


def cylinder_and_box(rng: np.random.Generator, shortest: float) -> tuple:
    """``(r, h, half, Rb, pb, Rc, pc)``: a cylinder of radius ``r`` and half length ``h`` (at least
    ``shortest``) at ``(Rc, pc)``, a box of half sides ``half`` at ``(Rb, pb)``, near each other [m]."""
    r, h = rng.uniform(0.02, 0.1), rng.uniform(shortest, 0.2)
    half = rng.uniform(0.05, 0.3, 3)
    Rb = _rotation(rng)
    pb = rng.normal(size=3) * 0.3
    Rc = _rotation(rng)
    pc = pb + rng.normal(size=3) * 0.4
    return r, h, half, Rb, pb, Rc, pc
