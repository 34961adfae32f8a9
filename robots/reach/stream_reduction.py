"""The reductions of a streamed workspace: what a task returns and how the folds merge them.

A :class:`Reduction` holds the bounding box, the manipulability sum and maximum, the
near-singular count, a voxel block (dense while a task accumulates, shipped sparse), the
radial shells around a fixed centre and the farthest sample of every direction cell.
:func:`add_block` folds a block of samples into it, :func:`sparse_voxels` packs its voxels for
shipping and :func:`merge` folds a task's reduction into the accumulator; merging in task
order gives the same result bit for bit whoever ran the tasks
(:mod:`pinarms.robots.reach.workspace_stream`). Units: m.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pinarms.robots.reach.sphere_fit import direction_cells

__all__ = ["Reduction", "ReductionSpec", "add_block", "merge", "sparse_voxels"]


@dataclass(frozen=True)
class ReductionSpec:
    """What every task of a stream shares: the frame, the grid, the shells' centre and width, the direction cells."""

    frame: str
    voxel_size: float
    centre: np.ndarray
    width: float
    n_dir_bins: int
    singular_threshold: float
    block: int


@dataclass
class Reduction:
    """What one task returns and what the folds accumulate (voxels sparse or dense)."""

    n: int = 0
    bbox_min: np.ndarray = field(default_factory=lambda: np.full(3, np.inf))
    bbox_max: np.ndarray = field(default_factory=lambda: np.full(3, -np.inf))
    sum_w: float = 0.0
    max_w: float = -np.inf
    n_singular: int = 0
    # voxels: dense block ``[lo, lo + shape)`` of global integer indices
    vox_lo: np.ndarray | None = None
    vox_count: np.ndarray | None = None
    vox_sum: np.ndarray | None = None
    vox_min: np.ndarray | None = None
    #: what a task ships instead of the dense block: occupied voxels (see :func:`sparse_voxels`)
    vox_sparse: tuple | None = None
    # radial shells around the centre
    shell_count: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    shell_sum_w: np.ndarray = field(default_factory=lambda: np.zeros(0))
    shell_singular: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    # direction cells around the centre: farthest sample and samples per cell
    hull_r: np.ndarray | None = None
    hull_point: np.ndarray | None = None
    hull_count: np.ndarray | None = None


def _grow(acc: Reduction, lo: np.ndarray, hi: np.ndarray) -> None:
    """Make the dense voxel block of ``acc`` cover global indices ``lo … hi`` (inclusive)."""
    if acc.vox_lo is None:
        shape = tuple(int(v) for v in hi - lo + 1)
        acc.vox_lo = lo.copy()
        acc.vox_count = np.zeros(shape, np.int64)
        acc.vox_sum = np.zeros(shape)
        acc.vox_min = np.full(shape, np.inf)
        return
    old_lo, old_hi = acc.vox_lo, acc.vox_lo + np.array(acc.vox_count.shape) - 1
    new_lo, new_hi = np.minimum(old_lo, lo), np.maximum(old_hi, hi)
    if np.array_equal(new_lo, old_lo) and np.array_equal(new_hi, old_hi):
        return
    shape = tuple(int(v) for v in new_hi - new_lo + 1)
    at = tuple(slice(int(a), int(a) + n) for a, n in zip(old_lo - new_lo, acc.vox_count.shape))
    for name, fill, dtype in (("vox_count", 0, np.int64), ("vox_sum", 0.0, float), ("vox_min", np.inf, float)):
        grown = np.full(shape, fill, dtype)
        grown[at] = getattr(acc, name)
        setattr(acc, name, grown)
    acc.vox_lo = new_lo


def add_block(acc: Reduction, P: np.ndarray, w: np.ndarray, c: np.ndarray, spec: ReductionSpec) -> None:
    """Fold one block of samples (points ``P (m, 3)``, manipulability ``w``, inverse condition ``c``)."""
    m = P.shape[0]
    singular = c < spec.singular_threshold
    Pt = np.ascontiguousarray(P.T)  # (3, m): reductions over samples run on contiguous rows
    acc.n += m
    acc.bbox_min = np.minimum(acc.bbox_min, Pt.min(axis=1))
    acc.bbox_max = np.maximum(acc.bbox_max, Pt.max(axis=1))
    acc.sum_w += float(np.sum(w))
    acc.max_w = max(acc.max_w, float(np.max(w)))
    acc.n_singular += int(np.count_nonzero(singular))
    # voxels on the global grid
    ijk = np.floor(Pt / spec.voxel_size).astype(np.int64)
    _grow(acc, ijk.min(axis=1), ijk.max(axis=1))
    nx, ny, nz = acc.vox_count.shape
    lo = acc.vox_lo
    flat = ((ijk[0] - lo[0]) * ny + (ijk[1] - lo[1])) * nz + (ijk[2] - lo[2])
    size = acc.vox_count.size
    acc.vox_count.reshape(-1)[:] += np.bincount(flat, minlength=size)
    acc.vox_sum.reshape(-1)[:] += np.bincount(flat, weights=w, minlength=size)
    np.minimum.at(acc.vox_min.reshape(-1), flat, w)
    # radial shells around the centre
    d0, d1, d2 = Pt[0] - spec.centre[0], Pt[1] - spec.centre[1], Pt[2] - spec.centre[2]
    r = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    shell = (r / spec.width).astype(np.int64)
    k = int(shell.max()) + 1
    _pad_shells(acc, k)
    acc.shell_count[:k] += np.bincount(shell, minlength=k)
    acc.shell_sum_w[:k] += np.bincount(shell, weights=w, minlength=k)
    acc.shell_singular[:k] += np.bincount(shell, weights=singular, minlength=k).astype(np.int64)
    # direction cells: the farthest sample per cell, first sample on ties
    cell, rc, n_cells = direction_cells(P, spec.centre, spec.n_dir_bins)
    if acc.hull_r is None:
        acc.hull_r = np.full(n_cells, -1.0)
        acc.hull_point = np.zeros((n_cells, 3))
        acc.hull_count = np.zeros(n_cells, np.int64)
    rmax = np.full(n_cells, -1.0)
    np.maximum.at(rmax, cell, rc)
    idx = np.flatnonzero(rc == rmax[cell])
    cells, first = np.unique(cell[idx], return_index=True)
    better = rmax[cells] > acc.hull_r[cells]
    acc.hull_r[cells[better]] = rmax[cells[better]]
    acc.hull_point[cells[better]] = P[idx[first[better]]]
    acc.hull_count += np.bincount(cell, minlength=n_cells)


def _pad_shells(acc: Reduction, k: int) -> None:
    if acc.shell_count.size < k:
        extra = k - acc.shell_count.size
        acc.shell_count = np.concatenate([acc.shell_count, np.zeros(extra, np.int64)])
        acc.shell_sum_w = np.concatenate([acc.shell_sum_w, np.zeros(extra)])
        acc.shell_singular = np.concatenate([acc.shell_singular, np.zeros(extra, np.int64)])


def sparse_voxels(acc: Reduction) -> tuple:
    """The occupied voxels of ``acc``, compact for shipping (24 bytes per voxel).

    ``(lo (3,), shape (3,), flat index in that block (int32), count (int32), sum and min of
    manipulability (float64))``.
    """
    flat = np.flatnonzero(acc.vox_count.reshape(-1))
    index = flat.astype(np.int32) if acc.vox_count.size < 2**31 else flat
    count = acc.vox_count.reshape(-1)[flat]
    count = count.astype(np.int32) if count.size and count.max() < 2**31 else count
    return (acc.vox_lo.copy(), np.array(acc.vox_count.shape), index, count,
            acc.vox_sum.reshape(-1)[flat], acc.vox_min.reshape(-1)[flat])


def merge(acc: Reduction, part: Reduction) -> None:
    """Fold a task's reduction into the accumulator (the caller keeps task order)."""
    acc.n += part.n
    acc.bbox_min = np.minimum(acc.bbox_min, part.bbox_min)
    acc.bbox_max = np.maximum(acc.bbox_max, part.bbox_max)
    acc.sum_w += part.sum_w
    acc.max_w = max(acc.max_w, part.max_w)
    acc.n_singular += part.n_singular
    lo, shape, index, count, total, wmin = part.vox_sparse
    if index.shape[0]:
        ijk = np.column_stack(np.unravel_index(index.astype(np.int64), tuple(int(v) for v in shape))) + lo
        _grow(acc, ijk.min(axis=0), ijk.max(axis=0))
        flat = np.ravel_multi_index((ijk - acc.vox_lo).T, acc.vox_count.shape)
        acc.vox_count.reshape(-1)[flat] += count
        acc.vox_sum.reshape(-1)[flat] += total
        acc.vox_min.reshape(-1)[flat] = np.minimum(acc.vox_min.reshape(-1)[flat], wmin)
    k = part.shell_count.size
    _pad_shells(acc, k)
    acc.shell_count[:k] += part.shell_count
    acc.shell_sum_w[:k] += part.shell_sum_w
    acc.shell_singular[:k] += part.shell_singular
    if acc.hull_r is None:
        acc.hull_r, acc.hull_point, acc.hull_count = part.hull_r.copy(), part.hull_point.copy(), part.hull_count.copy()
    else:
        better = part.hull_r > acc.hull_r  # strict: an earlier task keeps a tie
        acc.hull_r[better] = part.hull_r[better]
        acc.hull_point[better] = part.hull_point[better]
        acc.hull_count += part.hull_count
