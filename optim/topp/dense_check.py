"""The checks of a path timing against its constraints: rows between grid points, along a time law, exact peaks.

The profile (:func:`optim.topp.topp_profile`) meets the rows at the grid points only. These
checks read the rows elsewhere — at fractions :data:`CHECK_FRACTIONS` of every grid interval
or law piece — and say which uniform time dilation f each needs (:func:`dilation_needed`,
as f²) and how close each constraint comes to its bound (:func:`ratios`). For joint limits
:class:`Peaked` gives the composed trajectory's exact peaks (what
:meth:`planning.PathConstraint.exact_dilation` reads).
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from pinarms.optim.errors import InfeasibleProblem
from pinarms.optim.topp.time_law import law_eval
from pinarms.planning import Trajectory
from pinarms.planning.extrema import normalised_pieces, piece_extrema
from pinarms.planning.path_constraints import PathConstraint, PathRows, PathSamples

__all__ = ["CHECK_FRACTIONS", "Peaked", "rows_at", "row_names", "dilation_needed", "ratios", "law_rows", "law_check"]

#: Where each grid interval is re-checked, as fractions of its length.
CHECK_FRACTIONS = np.array([0.25, 0.5, 0.75, 1.0])


class Peaked:
    """A trajectory's exact per-joint peaks, each derivative order computed once, on first use.

    Stands for the trajectory in :meth:`PathConstraint.exact_dilation` (``n_joints`` and
    ``peaks()`` with ``velocity``, ``acceleration``, ``jerk``): every constraint shares one,
    and orders nobody asks for (jerk, mostly) are never computed.
    """

    def __init__(self, trajectory: Trajectory) -> None:
        self.n_joints = trajectory.n_joints
        self.trajectory = trajectory  # for constraints that need more than the peaks (joint torque)
        self._coefs = trajectory.coefficients
        self._h = trajectory.segment_durations
        self._normalised = None
        self._cache: dict[int, np.ndarray] = {}

    def _order(self, r: int) -> np.ndarray:
        if r not in self._cache:
            if self._normalised is None:
                self._normalised = normalised_pieces(self._coefs, self._h)
            values, _ = piece_extrema(self._normalised, self._h, (r,))
            self._cache[r] = np.abs(values[0]).max(axis=(0, 2))
        return self._cache[r]

    @property
    def velocity(self) -> np.ndarray:
        return self._order(1)

    @property
    def acceleration(self) -> np.ndarray:
        return self._order(2)

    @property
    def jerk(self) -> np.ndarray:
        return self._order(3)

    def peaks(self) -> "Peaked":
        return self


def rows_at(path: Any, constraints: Sequence[PathConstraint], s: np.ndarray, side: str) -> PathRows:
    """The rows of all ``constraints`` at path positions ``s``, pieces taken on ``side`` of a break."""
    samples = PathSamples.of(path, s, side)
    return PathRows.concatenate([c.rows(samples) for c in constraints])


def row_names(path: Any, constraints: Sequence[PathConstraint]) -> list[str]:
    """The constraint name of every row column (a constraint gives one or more rows)."""
    return [c.name for c in constraints for _ in range(c.rows(PathSamples.of(path, [0.0])).a.shape[1])]


def dilation_needed(rows: PathRows, u: np.ndarray, x: np.ndarray) -> np.ndarray:
    """f² (N, m) each row needs (1 where satisfied); inf where no dilation helps (a bound excluding 0)."""
    val = rows.values(u, x)
    with np.errstate(divide="ignore", invalid="ignore"):
        over = np.where(val > rows.hi, np.where(rows.hi > 0.0, val / rows.hi, np.inf), 1.0)
        under = np.where(val < rows.lo, np.where(rows.lo < 0.0, val / rows.lo, np.inf), 1.0)
    return np.maximum(np.maximum(over, under), 1.0)


def ratios(rows: PathRows, u: np.ndarray, x: np.ndarray, names: list[str]) -> dict[str, float]:
    """Largest value / bound per constraint name; for rows without u (speed limits on ṡ²) the
    square root, so that the ratio is one of speeds."""
    val = rows.values(u, x)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.maximum(np.where(rows.hi > 0.0, val / rows.hi, 0.0), np.where(rows.lo < 0.0, val / rows.lo, 0.0))
    first_order = np.all(rows.a == 0.0, axis=0)
    r = np.where(first_order[None, :], np.sqrt(np.maximum(r, 0.0)), r)
    out: dict[str, float] = {}
    for j, name in enumerate(names):
        out[name] = max(out.get(name, 0.0), float(np.max(r[:, j])) if r.shape[0] else 0.0)
    return out


def law_rows(path: Any, constraints: Sequence[PathConstraint], tb: np.ndarray,
             C: np.ndarray) -> tuple[PathRows, np.ndarray, np.ndarray]:
    """Rows of the constraints at 0, 1/4 … 1 of every law piece, with the law's (u, x) there.

    A piece's start is evaluated on the path piece that starts there, the other points on the
    one that ends there (what the law piece lies on; they differ at a stop).
    """
    h = np.diff(tb)
    parts = []
    for frac, side in ((np.array([0.0]), "right"), (np.concatenate([CHECK_FRACTIONS[:-1], [1.0 - 1e-9]]), "left")):
        t = (tb[:-1, None] + h[:, None] * frac).reshape(-1)
        s, sd, sdd = law_eval(tb, C, t)
        parts.append((rows_at(path, constraints, np.clip(s, 0.0, path.length), side), sdd, sd * sd))
    return PathRows.concatenate_points([p[0] for p in parts]), np.concatenate([p[1] for p in parts]), \
        np.concatenate([p[2] for p in parts])


def law_check(path: Any, constraints: Sequence[PathConstraint], tb: np.ndarray, C: np.ndarray) -> float:
    """f² the path constraints need on a law (dense rows)."""
    rows, u, x = law_rows(path, constraints, tb, C)
    need = dilation_needed(rows, u, x)
    if np.any(~np.isfinite(need)):
        raise InfeasibleProblem("a limit cannot be met at any speed on the smoothed timing (its bounds exclude 0)")
    return float(need.max())
