"""The checks of a cell with deltas: the tree's pairs (:mod:`.collision`) and the deltas' pairs (:mod:`.delta_pairs`) together.

A cell's pairs fall in two disjoint sets: those of its tree's collision geometries (fixtures,
serial arms: :attr:`Cell.pairs`, checked by Pinocchio and coal) and those with a delta's body
(:attr:`Cell.delta_pairs`: no delta body is in the tree). :meth:`Cell.in_collision`,
:meth:`Cell.collisions` and :meth:`Cell.clearance` of a cell with deltas call these functions,
which run both and merge: a configuration touches when either set touches; the
:class:`~.collision.Collisions` and :class:`~.collision.Clearance` list the tree's pairs first
(as without deltas), then the deltas' pairs, and the clearance is the smaller of the two exact
minima with its pair. :meth:`Cell.check_motion` runs the tree's continuous check
(:func:`~.motion.check_motion`) and the deltas' (:func:`~.delta_motion.check_delta_pairs`, the
speed of a delta's bodies bounded from the closed form) over the same window, and merges their
reports (:func:`merge_checks`).
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np

from pinarms.robots.cell import collision
from pinarms.robots.cell.collision import Clearance, Collisions
from pinarms.robots.cell.motion_report import MotionCheck
from pinarms.robots.cell.delta_pairs import delta_pair_set

__all__ = ["in_collision", "collisions", "clearance", "check_motion", "merge_checks", "tree_only"]


def in_collision(cell: Any, q: Any, *, margin: float = 0.0, threads: int = 1) -> bool | np.ndarray:
    """See :meth:`Cell.in_collision` (a cell with deltas)."""
    tree = collision.in_collision(cell, q, margin=margin, threads=threads)
    arr, single = cell.robot.check_q(q)
    hit = np.atleast_1d(np.array(tree, dtype=bool)).copy()
    rows = np.flatnonzero(~hit)
    if rows.size:
        hit[rows] = delta_pair_set(cell).any_touching(arr[rows], float(margin))
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


def tree_only(cell: Any) -> Any:
    """The same cell seen without its deltas (their joints stay in the vector, their pairs are not checked): what
    the tree's own checks run on, so that their inner calls (:meth:`Cell.in_collision`, ...) stay on the tree's pairs."""
    view = copy.copy(cell)
    view.deltas = ()
    return view


def check_motion(cell: Any, motions: Any, *, margin: float = 0.01, clearance: float = 0.0,
                 window: tuple[float, float] | None = None, hold: Any = None, curve: bool = False,
                 cover: bool = True) -> MotionCheck:
    """See :meth:`Cell.check_motion` (a cell with deltas): the tree's check and the deltas', merged."""
    from pinarms.robots.cell import motion
    from pinarms.robots.cell.delta_motion import check_delta_pairs
    from pinarms.robots.cell.timeline import arm_motions

    tree = motion.check_motion(tree_only(cell), motions, margin=margin, clearance=clearance, window=window, hold=hold,
                               curve=curve, cover=cover)
    hold_q = cell.hold if hold is None else cell.robot.check_q(hold)[0][0]
    deltas = check_delta_pairs(cell, arm_motions(cell, motions), hold_q, tree.window, tree.margin, tree.required)
    return merge_checks(tree, deltas)


def merge_checks(tree: MotionCheck, deltas: MotionCheck) -> MotionCheck:
    """One report of two checks of one window over disjoint pairs: verdicts both, the smaller minimum and bound,
    the earlier contact, the samples of both (sorted by time; ``pair_index`` into ``tree.pairs + deltas.pairs``)."""
    n0 = len(tree.pairs)
    first = [c for c in (tree.first_contact, deltas.first_contact) if c is not None]
    t_min = tree if tree.min_clearance <= deltas.min_clearance else deltas
    times = np.concatenate([tree.times, deltas.times])
    order = np.argsort(times, kind="stable")
    index = np.concatenate([tree.pair_index, np.where(deltas.pair_index >= 0, deltas.pair_index + n0, -1)])
    return MotionCheck(
        collision_free=tree.collision_free and deltas.collision_free, clear=tree.clear and deltas.clear,
        first_contact=min(first, key=lambda c: c.time) if first else None,
        max_depth=max(tree.max_depth, deltas.max_depth), min_clearance=t_min.min_clearance,
        min_clearance_time=t_min.min_clearance_time, min_clearance_pair=t_min.min_clearance_pair,
        lower_bound=min(tree.lower_bound, deltas.lower_bound), times=times[order],
        clearance=np.concatenate([tree.clearance, deltas.clearance])[order], pair_index=index[order],
        exact=np.concatenate([tree.exact, deltas.exact])[order], dt=min(tree.dt, deltas.dt),
        speed_bound=max(tree.speed_bound, deltas.speed_bound), margin=tree.margin, required=tree.required,
        window=tree.window, pairs=tree.pairs + deltas.pairs, curves=tree.curves, curve_pairs=tree.curve_pairs)
