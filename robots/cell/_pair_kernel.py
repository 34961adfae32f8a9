"""Compiled per-pair screen of :mod:`.cover` (numba): which pairs the cover proves apart, state by state.

:func:`.cover_kernel.screen_kernel` answers per configuration (every pair proven, or not);
:func:`pair_screen_kernel` answers per pair, so that the exact check (coal) needs to look
only at the pairs the cover leaves open. The same tests in the same order (the group's two
bounding spheres, a fixture's exact shape, each pair's bounding spheres, its distance table where it
has one, then its covers),
through :mod:`.cover_kernel`'s own helpers. Cached on disk like the other kernels.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from pinarms.compiled import drop_stale_caches, jit

from pinarms.robots.cell import box_kernel, cover_kernel
from pinarms.robots.cell.box_kernel import fixture_distance
from pinarms.robots.cell.cover_kernel import pair_proven, place_world, spheres_apart

__all__ = ["compiled_entry", "pair_screen_kernel", "pair_screener"]

# this kernel calls the cover's: its changes must compile it again (pinarms.compiled)
drop_stale_caches([Path(box_kernel.__file__), Path(cover_kernel.__file__), Path(__file__)],
                  "pair_kernels.sha256")


@jit
def pair_screen_kernel(Q, fk, cov, grp, work, out):
    """``out[i, k]`` (``(N, P)`` bool, the pairs in the groups' order): True where the cover proves pair
    ``k`` more than its threshold ``t[k]`` apart at cell configuration ``Q[i]``; False: inconclusive.

    ``fk``, ``cov``, ``grp``, ``work``: as :func:`.cover_kernel.excess_one` (:meth:`Cover.group_arrays`
    with the thresholds). A group proven on its two bounding spheres, or on its link's bounding sphere
    against its fixture's exact shape, at its largest threshold proves all its pairs."""
    exact, FR, Fp, size = cov[4], cov[5], cov[6], cov[7]
    hrad, group_start, group_a, group_b, group_fixed, group_t = grp[2], grp[3], grp[4], grp[5], grp[6], grp[7]
    for i in range(Q.shape[0]):
        place_world(Q[i], fk, cov, grp[0], grp[1], work)
        HW = work[5]
        for g in range(group_t.shape[0]):
            a = group_a[g]
            whole = spheres_apart(HW, hrad, a, group_b[g], group_t[g])
            fixed = group_fixed[g]
            if not whole and fixed >= 0:
                whole = fixture_distance(HW[a, 0], HW[a, 1], HW[a, 2], exact[fixed], FR, Fp, size, fixed) \
                    - hrad[a] > group_t[g]
            for k in range(group_start[g], group_start[g + 1]):
                out[i, k] = whole or pair_proven(cov, grp, work, k)

def compiled_entry(kernel, args: tuple):
    """``kernel``'s compiled code for arguments like ``(Q (N, nq) float, *args, out (N, P) bool)``, called
    without numba's matching of argument types (tens of µs for nested tuples of arrays); the dispatcher
    itself where numba does not expose it."""
    probe = (np.zeros((0, 1)), *args, np.zeros((0, 0), dtype=np.bool_))
    try:
        kernel(*probe)  # compiled (or loaded from the disk cache) for these types
        signature = tuple(kernel.typeof_pyval(a) for a in probe)
        return kernel.overloads[signature].entry_point
    except (AttributeError, KeyError, TypeError):
        return kernel


def pair_screener(cover: Any, pairs: Any, threshold: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """:meth:`.cover.Cover.pair_screen` of ``cover`` for ``pairs`` (:meth:`.cover.Cover.prepare`) at
    ``threshold`` [m], its arrays prepared once: a function of the configurations ``Q (N, nq)`` (and,
    optionally, other thresholds ``(P,)`` [m]) returning ``(N, P)`` bool in the order the pairs were given."""
    P = pairs.pair_a.size
    args = (cover.fk, cover.kernel_arrays(), cover.group_arrays(pairs, threshold), cover.work(pairs))
    order = pairs.order
    kernel = compiled_entry(pair_screen_kernel, args)

    def screen(Q: np.ndarray, threshold: np.ndarray | None = None) -> np.ndarray:
        Q = np.ascontiguousarray(np.atleast_2d(Q), dtype=float)
        if Q.shape[0] == 0 or P == 0:
            return np.ones((Q.shape[0], P), dtype=np.bool_)
        got = np.empty((Q.shape[0], P), dtype=np.bool_)
        grp = args[2] if threshold is None else cover.group_arrays(pairs, threshold)
        kernel(Q, args[0], args[1], grp, args[3], got)
        out = np.empty_like(got)
        out[:, order] = got
        return out

    return screen
