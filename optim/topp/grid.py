"""The reachability grid of a path section, and the profile on it checked and refined (path_timing, steps 2–4).

:func:`path_grid` places the grid points (the path's breaks, equal steps, halved where the
tangent bends); :func:`refined_section` runs :func:`pinarms.optim.topp.topp_profile` on it, checks
the rows between grid points and splits the intervals that exceed them, until they pass or
the rounds run out. A grid never grows past :data:`pinarms.optim.caps.MAX_PATH_GRID_POINTS`.
"""

from __future__ import annotations

from typing import Any, Sequence, TYPE_CHECKING

import numpy as np

from pinarms.optim.caps import MAX_PATH_GRID_POINTS
from pinarms.optim.errors import InfeasibleProblem, SettingOutOfRange
from pinarms.optim.topp.dense_check import CHECK_FRACTIONS, dilation_needed, ratios, rows_at_sets
from pinarms.optim.topp.profile import topp_profile
from pinarms.planning.path_constraints import PathConstraint, PathRows, PathSamples

if TYPE_CHECKING:
    from pinarms.planning.joint_path import JointPath

__all__ = ["path_grid", "refined_section"]


def path_grid(path: JointPath, a: float, b: float, total: float, n: int, kappa: float) -> np.ndarray:
    """Grid of [a, b]: the path breaks inside, each piece cut in steps of about total / n, then
    intervals halved until the tangent q' changes by at most ``kappa`` of its size across each."""
    breaks = np.asarray(path.breaks)
    inner = breaks[(breaks > a) & (breaks < b)]
    edges = np.concatenate([[a], inner, [b]])
    step = total / max(n, 1)
    parts = [np.array([a])]
    for lo, hi in zip(edges[:-1], edges[1:]):
        k = max(1, int(np.ceil((hi - lo) / step - 1e-9)))
        parts.append(lo + (hi - lo) * np.arange(1, k + 1) / k)
    g = np.concatenate(parts)
    g[-1] = b
    for _ in range(20):
        _, dq, _ = path.sample(g[:-1], "right")
        _, dq_end, _ = path.sample(g[1:], "left")
        size = np.maximum(np.abs(dq).max(axis=1), np.abs(dq_end).max(axis=1))
        bad = np.abs(dq_end - dq).max(axis=1) > kappa * size
        if not bad.any():
            break
        g = _grown(np.sort(np.concatenate([g, 0.5 * (g[:-1] + g[1:])[bad]])), "kappa")
    return g


def _grown(grid: np.ndarray, what: str) -> np.ndarray:
    """``grid`` unless refining made it larger than the cap (then a named error, never a runaway)."""
    if grid.size > MAX_PATH_GRID_POINTS:
        raise SettingOutOfRange(f"the path grid grew past {MAX_PATH_GRID_POINTS:,} points while refining: give a "
                                f"larger {what} or a smaller grid")
    return grid


#: The check fractions inside an interval; the last one, 1, is the interval's end (a grid point).
_INNER = CHECK_FRACTIONS[:-1]


def _inner_points(grid: np.ndarray) -> np.ndarray:
    """The check positions inside every interval of ``grid``: (intervals · len(_INNER),)."""
    h = np.diff(grid)
    return (grid[:-1, None] + h[:, None] * _INNER).reshape(-1)


def _taken(rows: PathRows, index: np.ndarray) -> PathRows:
    return PathRows(rows.a[index], rows.b[index], rows.lo[index], rows.hi[index], rows.labels)


def _merged(old: PathRows, keep: np.ndarray, fresh: PathRows) -> PathRows:
    """Rows at the points of a refined grid: ``old``'s rows where ``keep`` (in order), ``fresh`` elsewhere."""
    parts = []
    for k in ("a", "b", "lo", "hi"):
        o, f = getattr(old, k), getattr(fresh, k)
        out = np.empty((keep.size, o.shape[1]))
        out[keep] = o
        out[~keep] = f
        parts.append(out)
    return PathRows(*parts, old.labels)


def _on_break(path: Any, grid: np.ndarray) -> np.ndarray:
    """Which interval ends ``grid[1:]`` are inner breaks of the path (the same in every round: breaks stay grid points)."""
    return np.isin(grid[1:], np.asarray(path.breaks)[1:-1])


def _check_rows(path: Any, grid: np.ndarray, rows: PathRows, inner: PathRows,
                break_rows: PathRows | None) -> PathRows:
    """The rows at every check position, interval after interval: the ``inner`` ones, then the interval's
    end from the left — the grid point's own rows (the same piece) except on a path break, where
    ``break_rows`` (the rows at the section's inner breaks from the left, in order) are read."""
    ends = _taken(rows, np.arange(1, grid.size))
    on_break = _on_break(path, grid)
    if on_break.any():
        ends = _merged(_taken(ends, ~on_break), ~on_break, break_rows)
    k = _INNER.size
    parts = []
    for name in ("a", "b", "lo", "hi"):
        i, e = getattr(inner, name), getattr(ends, name)
        both = np.concatenate([i.reshape(grid.size - 1, k, -1), e[:, None, :]], axis=1)
        parts.append(both.reshape(-1, i.shape[1]))
    return PathRows(*parts, rows.labels)


def _refined_rows(path: Any, constraints: Sequence[PathConstraint], grid: np.ndarray, new: np.ndarray,
                  rows: PathRows, inner: PathRows) -> tuple[np.ndarray, PathRows, PathRows]:
    """The grid with the points ``new`` added, its rows and its inner check rows: the rows of the points
    and intervals kept are reused (their positions are the same floats), only the new ones are evaluated."""
    refined = _grown(np.sort(np.concatenate([grid, new])), "rtol")
    old_point = np.zeros(refined.size, dtype=bool)
    old_point[np.searchsorted(refined, grid)] = True
    # an interval whose two ends are old points was not split: its check rows are unchanged
    kept = np.repeat(old_point[:-1] & old_point[1:], _INNER.size)
    fresh = _inner_points(refined)[~kept]
    was = np.flatnonzero(np.repeat(np.diff(np.flatnonzero(old_point)) == 1, _INNER.size))
    at_points, at_inner = rows_at_sets(path, constraints, [(refined[~old_point], "right"), (fresh, "left")])
    return refined, _merged(rows, old_point, at_points), _merged(_taken(inner, was), kept, at_inner)


def refined_section(path: JointPath, constraints: Sequence[PathConstraint], grid: np.ndarray, x0: float, x1: float,
                    rtol: float, max_rounds: int,
                    with_ratios: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, int, dict]:
    """Profile of one section with the check-and-refine loop: (s, x, u, f², rounds, ratios).

    ``with_ratios=False``: the ratios per constraint are not computed (an empty dict).

    The rows depend on the positions only: a round re-evaluates them at the new grid points and in
    the split intervals alone (:func:`_refined_rows`; the same rows, bit for bit, as evaluating all),
    and the check at an interval's end reads the grid point's own rows (:func:`_check_rows`)."""
    rounds = 0
    breaks = grid[1:][_on_break(path, grid)]
    sets = [(grid, "right"), (_inner_points(grid), "left")] + ([(breaks, "left")] if breaks.size else [])
    rows, inner, *rest = rows_at_sets(path, constraints, sets)
    break_rows = rest[0] if rest else None
    while True:
        crow = _check_rows(path, grid, rows, inner, break_rows)
        prof = topp_profile(rows.a, rows.b, rows.lo, rows.hi, grid, x0, x1)
        h = np.diff(grid)
        uc = np.repeat(prof.u, CHECK_FRACTIONS.size)
        xc = (prof.x[:-1, None] + 2.0 * prof.u[:, None] * h[:, None] * CHECK_FRACTIONS).reshape(-1)
        xc = np.maximum(xc, 0.0)
        need = dilation_needed(crow, uc, xc).reshape(h.size, -1).max(axis=1)
        if np.any(~np.isfinite(need)):
            k = int(np.argmax(~np.isfinite(need)))
            raise InfeasibleProblem(f"at s = {grid[k]:.6g} a limit cannot be met at any speed (its bounds exclude 0, "
                                    "e.g. gravity beyond a torque limit)")
        bad = need > 1.0 + rtol
        if not bad.any() or rounds >= max_rounds:
            break
        rounds += 1
        grid, rows, inner = _refined_rows(path, constraints, grid, grid[:-1][bad] + 0.5 * h[bad], rows, inner)
    if not with_ratios:
        return grid, prof.x, prof.u, float(need.max()), rounds, {}
    names = [c.name for c in constraints for _ in range(c.rows(PathSamples.of(path, grid[:1])).a.shape[1])]
    return grid, prof.x, prof.u, float(need.max()), rounds, ratios(crow, uc, xc, names)
