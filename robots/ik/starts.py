"""Starts of the numerical IK solver: a stored table of poses for the first start, ranked random restarts.

The first attempt starts from ``q_seed`` or, without one, from the configuration (of
:data:`TABLE_SIZE` drawn once within the limits, seed 0, stored with their frame poses) whose pose
is nearest the target; restarts from configurations drawn uniformly within the limits by a
seeded generator, :data:`POOL` at a time, nearest pose first. Distance:
``‖p − p_target‖ + 0.1 m/rad · ‖R − R_target‖_F`` (position only: the first term).

:class:`StartTable` is a base class of :class:`.numerical.NumericalIK`. Units: m, rad.
"""

from __future__ import annotations

import threading

import numpy as np
import pinocchio as pin

__all__ = ["StartTable", "TABLE_SIZE", "POOL", "ROT_WEIGHT", "LIMIT_PENALTY", "LIMIT_MARGIN"]

TABLE_SIZE = 256  # configurations stored with their poses for the first start (table_start)
POOL = 32  # random starts drawn at once and ranked by their distance to the target
ROT_WEIGHT = 0.1  # [m/rad] weight of the rotation distance when ranking starts
GRID_TABLE_SIZE = 32768  # configurations of the compiled solver's start table (grid_table)
_PER_CELL = 2  # mean rows per cell of the grid over the positions' bounding box
#: at most this many rows in a target's own cell on average (else the cells are made finer): over
#: 2 000 seeded targets, ur5 (10.7 with 2 rows per box cell) solved 7 % faster at 5.9, aubo_i3
#: (7.9) the same at 4.5-6, panda (5.7) 7 % slower at 3.4
_SEEN = 6.0
_GRID_SEED = (0x5EED, 0x7AB1E, GRID_TABLE_SIZE)  # seed sequence of the grid table's draws
#: [m] added to a grid-table row's cost when a joint sits at its limit, falling linearly to 0 at
#: :data:`LIMIT_MARGIN` from it: a start near a limit often descends to a solution beyond it
LIMIT_PENALTY = 0.2
LIMIT_MARGIN = 0.6  # [rad] (at most a quarter of the range; prismatic joints: a tenth of the range)
_TABLES: dict[str, tuple] = {}  # grid tables by the digest of the chain and limits they were made for
_TABLES_KEPT = 8  # the most recent ones (≈ 5 MB each)
_TABLES_LOCK = threading.Lock()


def _cells(p: np.ndarray, lo: np.ndarray, extent: np.ndarray, size: float) -> tuple:
    """``(dims, key (n,), counts)``: the grid of cubes of ``size`` [m] from ``lo`` over ``extent``, each
    position's cell and the rows per cell."""
    dims = np.maximum(np.ceil(extent / size).astype(np.int64), 1)
    cells = np.minimum(((p - lo) / size).astype(np.int64), dims - 1)
    key = (cells[:, 0] * dims[1] + cells[:, 1]) * dims[2] + cells[:, 2]
    return dims, key, np.bincount(key, minlength=int(np.prod(dims)))


class StartTable:
    """The start table and the ranked restarts (see the module docstring)."""

    def _start_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:data:`TABLE_SIZE` configurations drawn within the limits (seed 0) with their frame poses, made once."""
        table = self._table
        if table is None:
            q = np.random.default_rng(0).uniform(self.lower, self.upper, size=(TABLE_SIZE, self.nq))
            T = self.robot.fk(q, self._frame)
            p = np.ascontiguousarray(T[:, :3, 3])
            R = np.ascontiguousarray(T[:, :3, :3].reshape(-1, 9))
            table = self._table = (q, p, np.einsum("ij,ij->i", p, p), R)  # one assignment: safe across threads
        return table

    def _grid_table(self, key: str | None = None) -> tuple:
        """The compiled solver's start table: :data:`GRID_TABLE_SIZE` configurations drawn within the limits
        (a fixed seed of its own, so that no user's seeded draws coincide with its rows) with their frame poses, rows sorted by the cell of a grid over their positions.

        Returns ``(q, p, |p|², unit quaternions (n, 4) (w, x, y, z), cell_start, grid, penalty)`` as :func:`._chain.grid_index` reads it:
        the rows of cell ``c`` are ``cell_start[c]:cell_start[c + 1]``; ``grid = (x0, y0, z0, 1/size,
        nx, ny, nz)``, the cell size giving about 2 rows per cell of the positions' bounding box;
        ``penalty (n,)`` [m] is :meth:`_limit_penalty` of each row. With ``key`` (a digest of
        everything the table depends on: the chain to the frame and the limits), a table made for the
        same key in this process is reused (read only; the :data:`_TABLES_KEPT` latest are kept).
        """
        table = _TABLES.get(key) if key is not None else None
        if table is None:
            table = self._make_grid_table()
            if key is not None:
                with _TABLES_LOCK:
                    while len(_TABLES) >= _TABLES_KEPT:
                        del _TABLES[next(iter(_TABLES))]
                    _TABLES[key] = table
        return table

    def _make_grid_table(self) -> tuple:
        """The table of :meth:`_grid_table`, drawn and sorted."""
        q = np.random.default_rng(_GRID_SEED).uniform(self.lower, self.upper, size=(GRID_TABLE_SIZE, self.nq))
        T = self.robot.fk(q, self._frame)
        p = T[:, :3, 3]
        lo, hi = p.min(axis=0), p.max(axis=0)
        extent = np.maximum(hi - lo, 1e-6)
        size = max(float(np.prod(extent) * _PER_CELL / GRID_TABLE_SIZE) ** (1.0 / 3.0), 1e-3)
        dims, key, counts = _cells(p, lo, extent, size)
        seen = float(counts.dot(counts)) / GRID_TABLE_SIZE  # rows of its own cell a target drawn like the rows sees
        if seen > _SEEN:  # a workspace filling little of its box: finer cells, fewer rows scanned per look-up
            size = max(size * (_SEEN / seen) ** (1.0 / 3.0), 1e-3)
            dims, key, counts = _cells(p, lo, extent, size)
        order = np.argsort(key, kind="stable")
        cell_start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        p = np.ascontiguousarray(p[order])
        from scipy.spatial.transform import Rotation  # here: scipy.spatial takes a second to import

        wxyz = Rotation.from_matrix(T[order, :3, :3]).as_quat()[:, [3, 0, 1, 2]]  # scipy: (x, y, z, w)
        grid = np.array([lo[0], lo[1], lo[2], 1.0 / size, dims[0], dims[1], dims[2]], dtype=float)
        q = np.ascontiguousarray(q[order])
        return (q, p, np.einsum("ij,ij->i", p, p), np.ascontiguousarray(wxyz), cell_start, grid, self._limit_penalty(q))

    def _limit_penalty(self, q: np.ndarray) -> np.ndarray:
        """Start cost ``(N,)`` [m] of configurations ``q (N, nq)`` near a joint limit.

        ``LIMIT_PENALTY · max_j max(0, 1 − d_j / m_j)`` with ``d_j`` the distance of joint ``j``
        to its nearer limit and ``m_j`` its margin: :data:`LIMIT_MARGIN` for a revolute joint (at
        most a quarter of its range), a tenth of the range for a prismatic one. Continuous joints
        and those whose range spans a full turn (shifted by 2π, never stopped) have none. Over
        2 000 seeded targets it raised the share of first starts that end within the limits from
        79 to 84 % (AUBO-i3) and from 80 to 88 % (panda); the UR5 (±2π) is unchanged.
        """
        span = self.upper - self.lower
        revolute = self._window_turns > 0.0
        margin = np.where(revolute, np.minimum(LIMIT_MARGIN, 0.25 * span), 0.1 * span)
        counted = ~self.unbounded & ~self.full_turn & (margin > 0.0)
        if not counted.any():
            return np.zeros(q.shape[0])
        d = np.minimum(q - self.lower, self.upper - q)[:, counted]
        short = np.maximum(0.0, 1.0 - d / margin[counted])
        return np.ascontiguousarray(LIMIT_PENALTY * short.max(axis=1))

    def table_start(self, target: np.ndarray, position_only: bool = False) -> np.ndarray:
        """The stored configuration whose frame pose is nearest ``target (4, 4)``: a copy ``(nq,)``.

        Distance ``‖p − p_target‖ + 0.1 m/rad · ‖R − R_target‖_F`` (position only: the first
        term) over :data:`TABLE_SIZE` configurations drawn once within the limits; starting there
        saves 2-4 iterations over the middle of the ranges.
        """
        q, p, pp, R = self._start_table()
        pt = target[:3, 3]
        d2 = pp - 2.0 * p.dot(pt) + pt.dot(pt)
        cost = np.sqrt(np.maximum(d2, 0.0))
        if not position_only:
            rt = target[:3, :3].reshape(9)
            cost += ROT_WEIGHT * np.sqrt(np.maximum(6.0 - 2.0 * R.dot(rt), 0.0))
        return q[int(np.argmin(cost))].copy()

    def _ranked_starts(self, rng: np.random.Generator, target: np.ndarray, position_only: bool) -> np.ndarray:
        """:data:`POOL` uniform draws within the limits, closest to the target first.

        Distance: ``‖p − p_target‖ + 0.1 m/rad · ‖R − R_target‖_F`` (position only: the first term).
        """
        q = rng.uniform(self.lower, self.upper, size=(POOL, self.nq))
        model, data, fid = self.model, self.data, self.frame_id
        p = np.empty((POOL, 3))
        R = np.empty((POOL, 3, 3))
        for k in range(POOL):  # one Pinocchio FK each: faster than the batched numpy FK for 32 rows
            pin.forwardKinematics(model, data, self._pin_q(q[k]))
            M = pin.updateFramePlacement(model, data, fid)
            p[k] = M.translation
            R[k] = M.rotation
        cost = np.linalg.norm(p - target[:3, 3], axis=1)
        if not position_only:
            cost = cost + ROT_WEIGHT * np.linalg.norm((R - target[:3, :3]).reshape(-1, 9), axis=1)
        return q[np.argsort(cost, kind="stable")]

