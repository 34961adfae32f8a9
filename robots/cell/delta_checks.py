"""The checks of a cell with deltas: the tree's pairs (:mod:`.collision`) and the deltas' pairs (:mod:`.delta_pairs`) together.

A cell's pairs fall in two disjoint sets: those of its tree's collision geometries (fixtures,
serial arms: :attr:`Cell.pairs`, checked by Pinocchio and coal) and those with a delta's body
(:attr:`Cell.delta_pairs`: no delta body is in the tree). :meth:`Cell.in_collision`,
:meth:`Cell.collisions` and :meth:`Cell.clearance` of a cell with deltas call these functions,
which run both and merge: a configuration touches when either set touches; the
:class:`~.collision.Collisions` and :class:`~.collision.Clearance` list the tree's pairs first
(as without deltas), then the deltas' pairs, and the clearance is the smaller of the two exact
minima with its pair.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms.robots.cell import collision
from pinarms.robots.cell.collision import Clearance, Collisions
from pinarms.robots.cell.delta_pairs import delta_pair_set

__all__ = ["in_collision", "collisions", "clearance"]


def in_collision(cell: Any, q: Any, *, margin: float = 0.0, threads: int = 1) -> bool | np.ndarray:
    """See :meth:`Cell.in_collision` (a cell with deltas)."""
    tree = collision.in_collision(cell, q, margin=margin, threads=threads)
    arr, single = cell.robot.check_q(q)
    hit = np.atleast_1d(np.array(tree, dtype=bool)).copy()
    rows = np.flatnonzero(~hit)
    if rows.size:
        touching = delta_pair_set(cell).touching(arr[rows], float(margin))
        hit[rows] = [bool(t) for t in touching]
    return bool(hit[0]) if single else hit


def collisions(cell: Any, q: Any, *, margin: float = 0.0) -> Collisions:
    """See :meth:`Cell.collisions` (a cell with deltas): the tree's pairs, then the deltas'."""
    tree = collision.collisions(cell, q, margin=margin)
    arr, _ = cell.robot.check_q(q)
    dps = delta_pair_set(cell)
    extra = dps.touching(arr, tree.margin)
    n0 = len(tree.pairs)
    touching = tuple(t + tuple(n0 + k for k in e) for t, e in zip(tree.touching, extra))
    hit = np.array([bool(t) for t in touching], dtype=bool)
    return Collisions(tree.pairs + dps.pairs, hit, touching, tree.margin, tree.single)


def clearance(cell: Any, q: Any, *, margin: float = 0.0) -> Clearance:
    """See :meth:`Cell.clearance` (a cell with deltas): the smaller of the tree's and the deltas' exact minima."""
    tree = collision.clearance(cell, q, margin=margin)
    arr, single = cell.robot.check_q(q)
    dps = delta_pair_set(cell)
    dist, pair, pa, pb = dps.clearance(arr)
    t_dist = np.atleast_1d(np.asarray(tree.distance, dtype=float))
    t_pair = np.atleast_1d(np.asarray(tree.pair))
    t_pa, t_pb = np.atleast_2d(tree.point_a), np.atleast_2d(tree.point_b)
    use = dist < t_dist
    n0 = len(tree.pairs)
    out_d = np.where(use, dist, t_dist)
    out_k = np.where(use, pair + n0, t_pair)
    out_a = np.where(use[:, None], pa, t_pa)
    out_b = np.where(use[:, None], pb, t_pb)
    pairs = tree.pairs + dps.pairs
    if single:
        return Clearance(float(out_d[0]), int(out_k[0]), out_a[0], out_b[0], tree.margin, pairs)
    return Clearance(out_d, out_k, out_a, out_b, tree.margin, pairs)
