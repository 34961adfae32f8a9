"""The rows of the TOPP-RA loops as bounds on the state x.

Both passes of :mod:`pinarms.optim.topp.profile` reduce, at each grid point, rows ``c x <= slope y +
offset`` (y: the neighbouring set's end in step 1, the state itself in step 2) to a min and
a max. :func:`row_bounds` writes the rows as upper and lower bounds on x, each row that does
not apply with a neutral offset, so that the compiled loops (:mod:`._profile_kernel`) reduce
whole rows.
"""

from __future__ import annotations

import numpy as np

__all__ = ["row_bounds"]


def row_bounds(c: np.ndarray, slope: np.ndarray, offset: np.ndarray) -> tuple[np.ndarray, ...]:
    """Rows ``c x <= slope y + offset`` as ``x <= Su y + Ou`` (c > 0) and ``x >= Sl y + Ol`` (c < 0).

    Rows that do not apply get the neutral offset (+inf for upper, -inf for lower bounds), so
    that a step of the loops is a min and a max over whole rows. ``c == 0`` rows are returned
    as ``0 <= slope y + offset`` conditions (``Zs``, ``Zo``; neutral +inf where they do not apply).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.where(c != 0.0, 1.0 / np.where(c != 0.0, c, 1.0), 0.0)
        up = c > 0.0
        dn = c < 0.0
        zero = (c == 0.0) & np.isfinite(offset)
        Su = np.where(up, slope * inv, 0.0)
        Ou = np.where(up, offset * inv, np.inf)
        Sl = np.where(dn, slope * inv, 0.0)
        Ol = np.where(dn, offset * inv, -np.inf)
        Zs = np.where(zero, slope, 0.0)
        Zo = np.where(zero, offset, np.inf)
    Ou[np.isnan(Ou)] = np.inf
    Ol[np.isnan(Ol)] = -np.inf
    return Su, Ou, Sl, Ol, Zs, Zo
