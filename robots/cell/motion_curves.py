"""The clearance of each moving arm over time, per group of pairs (:func:`moving_arm_curves`).

What a clearance-over-time plot shows: a moving arm against everything else, one curve
per group of pairs:

- ``"<arm> ↔ fixtures"``: the arm's links against every fixture;
- ``"<arm> ↔ <other arm>"``: the arm's links against another arm's (once per two arms);
- ``"<arm>: own links"``: two links of the arm.

Pairs between two shapes that do not move (an idle arm's own links, an idle arm against a
fixture) are left out: their distance is constant over the motion and says nothing about it.
Each value is coal's exact smallest distance over the group's candidate pairs (every pair of
:meth:`Cell.pairs_for` ``(inf)``, the out-of-reach pairs at their proven bounds), so no pair is
missed because it was proven far.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from pinarms.robots.cell.collision import exact_min_distance, pair_lower_bounds

from pinarms.robots.cell.cell_model import CellModel

__all__ = ["moving_arm_groups", "moving_arm_curves"]

#: Configurations whose pair bounds are computed together.
ROWS = 2048


def moving_arm_groups(cell: "CellModel", arms: Sequence[str]) -> dict[str, np.ndarray]:
    """``{group name: candidate pair indices}`` of the pairs involving one of the moving ``arms`` (module doc).

    Groups in the order of ``arms``: fixtures, each other arm, own links; empty groups left out.
    """
    moving = list(dict.fromkeys(arms))
    arm_names = {a.name for a in cell.arms}
    groups: dict[str, list[int]] = {}
    for k, p in enumerate(cell.candidates):
        a, b = p.owner_a, p.owner_b
        if a not in moving and b in moving:
            a, b = b, a
        if a not in moving:
            continue  # two shapes that do not move
        if p.kind == "self":
            name = f"{a}: own links"
        elif b in arm_names:
            first, second = sorted((a, b), key=lambda n: moving.index(n) if n in moving else len(moving))
            name = f"{first} ↔ {second}"
        else:
            name = f"{a} ↔ fixtures"
        groups.setdefault(name, []).append(k)
    order = []
    for arm in moving:
        order += [f"{arm} ↔ fixtures"] + [n for n in groups if n.startswith(f"{arm} ↔ ") and n != f"{arm} ↔ fixtures"]
        order.append(f"{arm}: own links")
    return {n: np.asarray(groups[n], dtype=int) for n in dict.fromkeys(order) if n in groups}


def moving_arm_curves(cell: "CellModel", arms: Sequence[str], Q: np.ndarray) -> tuple[dict[str, np.ndarray], dict]:
    """``{group name: (N,) exact smallest distance [m]}`` at the cell configurations ``Q (N, nq)``, and
    ``{group name: CollisionPair}`` the closest pair of each group over all of ``Q``.

    One coal pass per group and configuration, the pairs in increasing order of their lower
    bound, stopped once the next bound is no smaller than the smallest distance found.
    """
    groups = moving_arm_groups(cell, arms)
    N, n_all, n0 = Q.shape[0], len(cell.candidates), len(cell.pairs)
    curves = {name: np.empty(N) for name in groups}
    closest = {name: np.empty(N, dtype=int) for name in groups}
    for start in range(0, N, ROWS):
        rows = Q[start:start + ROWS]
        lb = pair_lower_bounds(cell, rows)
        lb[:, n0:] = np.maximum(lb[:, n0:], cell.reach_bounds)
        for name, idx in groups.items():
            masked = np.full_like(lb, np.inf)
            masked[:, idx] = lb[:, idx]
            d, k, _, _ = exact_min_distance(cell, rows, lb=masked, n=n_all)
            curves[name][start:start + rows.shape[0]], closest[name][start:start + rows.shape[0]] = d, k
    pairs = {name: cell.candidates[int(closest[name][int(np.argmin(d))])] for name, d in curves.items() if N}
    return curves, pairs
