"""A task map read by its cells across the belt: the same bits as TaskMap.rows, else TaskMap.rows itself."""

import numpy as np
import pytest

from pinarms.optim.line.map_rows import CellRows, map_rows
from pinarms.optim.line.task_maps import TaskMap


def read(m, grid, w):
    """:func:`map_rows` of every item into new tables."""
    tA, tC = np.empty((w.size, grid[0].size)), np.empty((w.size, grid[0].size))
    map_rows(m, grid, w, np.arange(w.size), tA, tC)
    return tA, tC


def branchy_map(seed: int) -> TaskMap:
    """Two IK branches with random times and holes, an uneven grid across the belt."""
    rng = np.random.default_rng(seed)
    du = np.linspace(-0.3, 0.3, 9)
    w = np.sort(np.concatenate([[-0.15, 0.15], rng.uniform(-0.14, 0.14, 4)]))
    A = 0.3 + rng.random((2, du.size, w.size))
    C = 0.2 + 2.0 * rng.random((2, du.size, w.size))
    A[rng.random(A.shape) < 0.15] = np.nan
    C[np.isnan(A)] = np.nan
    best = np.nanargmin(np.where(np.isfinite(A + C), A + C, np.inf), axis=0)
    pick = lambda T: np.take_along_axis(T, best[None], 0)[0]  # noqa: E731
    return TaskMap("m", du, w, pick(A), pick(C), 0.5, 0.1, 0.2, 0.1, branches=(0, 1), branch_approach=A,
                   branch_leave=C)


@pytest.mark.parametrize("seed", range(4))
def test_cells_give_the_same_bits_as_the_map(seed):
    m = branchy_map(seed)
    grid = m.sim_grid()
    rng = np.random.default_rng(seed + 10)
    w = np.concatenate([rng.uniform(-0.16, 0.16, 3000), m.w, [-0.2, 0.2, np.nextafter(0.15, 1.0)]])
    ref = m.rows(w, grid)
    fast = CellRows(m, grid).rows(w)
    assert np.isfinite(ref[0]).any() and np.isnan(ref[0]).any()
    for a, b in zip(ref, fast):
        assert np.array_equal(a, b, equal_nan=True)
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(ref, read(m, grid, w)))
    compiled = np.full((w.size, grid[0].size), -1.0), np.full((w.size, grid[0].size), -1.0)
    CellRows(m, grid).fill(w, np.arange(w.size), *compiled)
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(ref, compiled))


def test_a_map_the_cells_do_not_reproduce_is_read_itself():
    class Scaled(TaskMap):
        """A map of another kind: its rows are not its cells' (the approach scaled by the item's w)."""

        def rows(self, w, grid=None):
            a, c = super().rows(w, grid)
            return a * (1.0 + np.asarray(w)[:, None]), c

    base = branchy_map(1)
    m = Scaled(**{k: getattr(base, k) for k in ("station", "du", "w", "approach", "leave", "track", "release",
                                                  "speed", "mass", "branches", "branch_approach", "branch_leave")})
    grid = m.sim_grid()
    w = np.random.default_rng(3).uniform(-0.15, 0.15, 500)
    ref = m.rows(w, grid)
    assert not np.array_equal(CellRows(m, grid).rows(w)[0], ref[0], equal_nan=True)
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(ref, read(m, grid, w)))


def yaw_map(seed: int) -> TaskMap:
    """``branchy_map``'s grid with five yaw layers of random times (holes too), yaw 0 the middle one."""
    base = branchy_map(seed)
    rng = np.random.default_rng(seed + 20)
    yaw = np.array([-np.pi / 2, -0.9, 0.0, 0.4, np.pi / 2])
    A = 0.3 + rng.random((yaw.size, *base.branch_approach.shape))
    C = 0.2 + 2.0 * rng.random(A.shape)
    A[rng.random(A.shape) < 0.1] = np.nan
    C[np.isnan(A)] = np.nan
    A[2], C[2] = base.branch_approach, base.branch_leave
    return TaskMap("m", base.du, base.w, base.approach, base.leave, 0.5, 0.1, 0.2, 0.1, branches=(0, 1),
                   branch_approach=base.branch_approach, branch_leave=base.branch_leave, yaw=yaw, yaw_approach=A,
                   yaw_leave=C, yaw_spread=0.5)


@pytest.mark.parametrize("seed", range(3))
def test_cells_of_a_yaw_map_give_the_same_bits_as_the_map(seed, monkeypatch):
    m = yaw_map(seed)
    grid = m.sim_grid()
    rng = np.random.default_rng(seed + 30)
    w = np.concatenate([rng.uniform(-0.16, 0.16, 3000), m.w, m.w])
    yaw = np.concatenate([rng.uniform(-4.0, 4.0, 3000), np.zeros(m.w.size), np.full(m.w.size, 0.4)])
    ref = m.rows(w, grid, yaw)
    assert np.isfinite(ref[0]).any() and np.isnan(ref[0]).any()
    cells = CellRows(m, grid)
    assert cells.ends.shape[0] == m.yaw.size
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(ref, cells.rows(w, yaw)))
    compiled = np.full((w.size, grid[0].size), -1.0), np.full((w.size, grid[0].size), -1.0)
    cells.fill(w, np.arange(w.size), *compiled, yaw=yaw)
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(ref, compiled))
    # map_rows takes the cells (fast) path and gives the map's rows for a part of the items
    sel = np.arange(0, w.size, 3)
    tA, tC = np.full((w.size, grid[0].size), -1.0), np.full((w.size, grid[0].size), -1.0)
    filled = []
    fill = CellRows.fill
    monkeypatch.setattr(CellRows, "fill", lambda self, ww, s, *a, **k: (filled.append(s.size), fill(self, ww, s, *a, **k)))
    map_rows(m, grid, w, sel, tA, tC, yaw=yaw)
    assert filled[-1] == sel.size  # the items went through the cells (the fast path), after the check
    assert np.array_equal(tA[sel], ref[0][sel], equal_nan=True) and np.array_equal(tC[sel], ref[1][sel], equal_nan=True)
    assert np.all(np.delete(tA, sel, axis=0) == -1.0)
    # yaw not given: the yaw-0 layer
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(m.rows(w, grid), cells.rows(w)))
