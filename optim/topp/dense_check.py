"""The checks of a path timing against its constraints: rows between grid points, along a time law, exact peaks.

The profile (:func:`pinarms.optim.topp.topp_profile`) meets the rows at the grid points only. These
checks read the rows elsewhere — at fractions :data:`CHECK_FRACTIONS` of every grid interval
or law piece — and say which uniform time dilation f each needs (:func:`dilation_needed`,
as f²) and how close each constraint comes to its bound (:func:`ratios`). For joint limits
:class:`Peaked` gives the composed trajectory's exact peaks (what
:meth:`pinarms.planning.PathConstraint.exact_dilation` reads).
"""

from __future__ import annotations

from functools import lru_cache
from math import comb
from typing import Sequence, TYPE_CHECKING

import numpy as np

from pinarms.optim.errors import InfeasibleProblem
from pinarms.optim.topp.time_law import law_eval
from pinarms.planning import Trajectory
from pinarms.planning.extrema import derivative_coefficients, normalised_pieces, piece_extrema
from pinarms.planning.path_constraints import PathConstraint, PathRows, PathSamples

if TYPE_CHECKING:
    from pinarms.planning.joint_path import JointPath

__all__ = ["CHECK_FRACTIONS", "Peaked", "rows_at", "rows_at_sets", "row_names", "dilation_needed", "ratios", "law_rows", "law_check"]

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
        self._peaks_of_order: dict[int, np.ndarray] = {}

    def _order(self, r: int) -> np.ndarray:
        if r not in self._peaks_of_order:
            if self._normalised is None:
                self._normalised = normalised_pieces(self._coefs, self._h)
            self._peaks_of_order[r] = _exact_peaks(self._normalised, self._h, r)
        return self._peaks_of_order[r]

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


@lru_cache(maxsize=16)
def _to_bernstein(width: int) -> np.ndarray:
    """(W, W): ascending power coefficients on [0, 1] times it are the Bernstein coefficients of degree W − 1."""
    d = width - 1
    out = np.zeros((width, width))
    for k in range(width):
        for i in range(k, width):
            out[k, i] = comb(i, k) / comb(d, k)
    return out


def _exact_peaks(normalised: np.ndarray, h: np.ndarray, r: int) -> np.ndarray:
    """Per joint, the exact peak of ``|d^r q / dt^r|`` over every piece (n,).

    A piece whose bound ``h^-r max_i |b_i|`` (b: the derivative's Bernstein coefficients in
    normalised time s ∈ [0, 1]; the polynomial lies in their convex hull) is below the largest value some piece takes at one of
    its ends cannot hold the peak: only the other (piece, joint) rows get their exact extrema
    (roots of the next derivative), the same arithmetic row by row as for all of them.
    """
    M, n, width = normalised.shape
    deriv = derivative_coefficients(normalised, r, axis=-1)  # (M, n, W) in s
    scale = (h ** -float(r))[:, None]
    ends = np.maximum(np.abs(deriv[:, :, 0]), np.abs(deriv.sum(axis=-1))) * scale  # |p(0)|, |p(1)|
    floor = ends.max(axis=0)  # (n,): reached at some piece end
    bound = np.abs(deriv @ _to_bernstein(width)).max(axis=-1) * scale * (1.0 + 1e-9) + 1e-300
    keep_piece, keep_joint = np.nonzero(bound >= floor[None, :])
    peaks = np.zeros(n)  # the piece reaching ``floor`` is kept: every peak comes from piece_extrema
    if keep_piece.size:
        sel = normalised[keep_piece, keep_joint][:, None, :]  # (K, 1, W)
        values, _ = piece_extrema(sel, h[keep_piece], (r,))
        np.maximum.at(peaks, keep_joint, np.abs(values[0, :, 0]).max(axis=-1))
    return peaks


def rows_at(path: JointPath, constraints: Sequence[PathConstraint], s: np.ndarray, side: str) -> PathRows:
    """The rows of all ``constraints`` at path positions ``s``, pieces taken on ``side`` of a break."""
    return rows_at_sets(path, constraints, [(s, side)])[0]


def rows_at_sets(path: JointPath, constraints: Sequence[PathConstraint], sets: Sequence[tuple[np.ndarray, str]]) -> list[PathRows]:
    """:func:`rows_at` at several ``(s, side)`` at once: the joint torque rows of all in one batched call
    (:mod:`.torque_rows`; the same rows, bit for bit)."""
    from pinarms.optim.topp.torque_rows import rows_of_samplings

    return rows_of_samplings(constraints, [PathSamples.of(path, s, side) for s, side in sets])


def row_names(path: JointPath, constraints: Sequence[PathConstraint]) -> list[str]:
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


def law_rows(path: JointPath, constraints: Sequence[PathConstraint], tb: np.ndarray,
             C: np.ndarray) -> tuple[PathRows, np.ndarray, np.ndarray]:
    """Rows of the constraints at 0, 1/4 … 1 of every law piece, with the law's (u, x) there.

    A piece's start is evaluated on the path piece that starts there, the other points on the
    one that ends there (what the law piece lies on; they differ at a stop).
    """
    h = np.diff(tb)
    sets, u, x = [], [], []
    for frac, side in ((np.array([0.0]), "right"), (np.concatenate([CHECK_FRACTIONS[:-1], [1.0 - 1e-9]]), "left")):
        t = (tb[:-1, None] + h[:, None] * frac).reshape(-1)
        s, sd, sdd = law_eval(tb, C, t)
        sets.append((np.clip(s, 0.0, path.length), side))
        u.append(sdd)
        x.append(sd * sd)
    return PathRows.concatenate_points(rows_at_sets(path, constraints, sets)), np.concatenate(u), np.concatenate(x)


def law_check(path: JointPath, constraints: Sequence[PathConstraint], tb: np.ndarray, C: np.ndarray) -> float:
    """f² the path constraints need on a law (dense rows)."""
    rows, u, x = law_rows(path, constraints, tb, C)
    need = dilation_needed(rows, u, x)
    if np.any(~np.isfinite(need)):
        raise InfeasibleProblem("a limit cannot be met at any speed on the smoothed timing (its bounds exclude 0)")
    return float(need.max())
