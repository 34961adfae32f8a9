"""Sphere fits of a point cloud (a workspace's reach): least squares on the points or on their hull.

Part of the reach family (:mod:`pinarms.robots.reach.workspace` re-exports every name). Units: m.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput

__all__ = ["SPHERE_COVERAGE_MIN", "SphereFit", "fit_sphere", "fit_sphere_to_hull", "hull_points", "direction_coverage",
           "direction_cells", "as_points"]

#: :attr:`SphereFit.coverage` below which a sphere fit is flagged as not describing the cloud.
SPHERE_COVERAGE_MIN = 0.5


@dataclass(frozen=True)
class SphereFit:
    """A sphere fitted to points [m].

    Attributes:
        centre: ``(3,)`` centre in the base frame [m].
        radius: [m].
        rms_residual: root mean square of ``|p − centre| − radius`` over the fitted points [m].
        max_residual: largest ``| |p − centre| − radius |`` over the fitted points [m].
        n_points: number of points the fit used (hull points for :func:`fit_sphere_to_hull`).
        method: ``"algebraic"`` or ``"outer-hull"``.
        coverage: share of the equal-area direction cells around ``centre`` that hold
            samples (see :func:`hull_points`): near 1 when the cloud surrounds the centre;
            below :data:`SPHERE_COVERAGE_MIN` the samples cover only a patch of the sphere
            (a slab or a box seen from far away) and the fit says little about the
            workspace, however small its residual.
    """

    centre: np.ndarray
    radius: float
    rms_residual: float
    max_residual: float
    n_points: int
    method: str
    coverage: float = float("nan")

    @property
    def meaningful(self) -> bool:
        """Whether the samples surround the centre well enough for the sphere to describe them."""
        return bool(self.coverage >= SPHERE_COVERAGE_MIN)

    @property
    def relative_rms(self) -> float:
        """``rms_residual / radius``: 0 for a perfect sphere."""
        return self.rms_residual / self.radius if self.radius > 0 else float("inf")


def fit_sphere(points: ArrayLike) -> SphereFit:
    """Linear least-squares sphere through ``points (N, 3)``.

    Solves ``|p|² = 2 c·p + (r² − |c|²)`` for ``c`` and ``r`` (the algebraic fit): exact for
    points on a sphere, and the usual first step for points near one.
    """
    P = as_points(points, "points")
    if P.shape[0] < 4:
        raise InvalidInput(f"a sphere fit needs at least 4 points, got {P.shape[0]}")
    A = np.column_stack([2.0 * P, np.ones(P.shape[0])])
    b = np.einsum("ij,ij->i", P, P)
    sol, *_ = np.linalg.lstsq(A, b, rcond=None)
    centre = sol[:3]
    radius = float(np.sqrt(max(sol[3] + centre @ centre, 0.0)))
    res = np.linalg.norm(P - centre, axis=1) - radius
    return SphereFit(centre, radius, float(np.sqrt(np.mean(res**2))), float(np.max(np.abs(res))), P.shape[0], "algebraic",
                     direction_coverage(P, centre))


def direction_cells(points: np.ndarray, centre: np.ndarray, n_bins: int | None) -> tuple[np.ndarray, np.ndarray, int]:
    """Equal-area direction cell of every point seen from ``centre``, its distance, and the cell count.

    Directions are cut into ``n_z`` bands of ``cos(polar angle)`` times ``2 n_z`` azimuth
    sectors. By default ``n_bins ≈ N / 30`` (between 32 and 2048 cells), so that each cell
    holds about 30 samples.
    """
    N = points.shape[0]
    if n_bins is None:
        n_bins = int(np.clip(N // 30, 32, 2048))
    n_z = max(2, int(round(np.sqrt(n_bins / 2.0))))
    n_az = 2 * n_z
    d = points - centre
    r = np.sqrt(np.einsum("ij,ij->i", d, d))
    with np.errstate(invalid="ignore", divide="ignore"):
        cz = np.where(r > 0, d[:, 2] / r, 0.0)
    iz = np.minimum(((cz + 1.0) * 0.5 * n_z).astype(int), n_z - 1)
    iaz = np.minimum(((np.arctan2(d[:, 1], d[:, 0]) + np.pi) / (2 * np.pi) * n_az).astype(int), n_az - 1)
    return iz * n_az + iaz, r, n_z * n_az


def hull_points(points: np.ndarray, centre: np.ndarray, n_bins: int | None = None) -> np.ndarray:
    """The farthest point from ``centre`` in each direction cell (indices into ``points``).

    Cells as in :func:`direction_cells`: equal-area, about 30 samples each by default.
    """
    cell, r, n_cells = direction_cells(points, centre, n_bins)
    rmax = np.full(n_cells, -1.0)
    np.maximum.at(rmax, cell, r)
    is_max = r == rmax[cell]
    idx = np.flatnonzero(is_max)
    # one point per cell (ties are rare; keep the first)
    _, first = np.unique(cell[idx], return_index=True)
    return idx[first]


def direction_coverage(points: ArrayLike, centre: ArrayLike, n_bins: int | None = None) -> float:
    """Share of the direction cells around ``centre`` [m] that hold at least one of ``points``."""
    P = as_points(points, "points")
    cell, _, n_cells = direction_cells(P, np.asarray(centre, dtype=float), n_bins)
    return float(np.unique(cell).size / n_cells)


def fit_sphere_to_hull(points: ArrayLike, n_bins: int | None = None, iterations: int = 3) -> SphereFit:
    """Sphere fitted to the outer hull of a point cloud [m].

    Start from the algebraic fit of all points, take the farthest sample in each
    direction cell around the current centre (:func:`hull_points`), fit the algebraic
    sphere to those, and repeat ``iterations`` times. The residuals are those of the hull
    points: they measure how spherical the boundary is. With few samples the hull lies
    inside the true boundary (the outer shell is sparse), so the radius is biased low.
    """
    P = as_points(points, "points")
    if isinstance(iterations, bool) or not isinstance(iterations, (int, np.integer)) or iterations < 1:
        raise InvalidInput(f"iterations must be an integer >= 1, got {iterations!r}")
    if n_bins is not None and (isinstance(n_bins, bool) or not isinstance(n_bins, (int, np.integer)) or n_bins < 8):
        raise InvalidInput(f"n_bins must be None (automatic) or an integer >= 8 direction cells, got {n_bins!r}")
    fit = fit_sphere(P)
    for _ in range(int(iterations)):
        idx = hull_points(P, fit.centre, n_bins)
        if idx.size < 4:
            break
        fit = fit_sphere(P[idx])
    return SphereFit(fit.centre, fit.radius, fit.rms_residual, fit.max_residual, fit.n_points, "outer-hull",
                     direction_coverage(P, fit.centre, n_bins))


def as_points(points: ArrayLike, what: str) -> np.ndarray:
    """``points`` as an (N, 3) float array [m] (one (3,) point as one row); ``what`` names them in the error.

    Raises:
        InvalidInput: not numbers, or another shape.
    """
    try:
        P = np.asarray(points, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be numbers, got {points!r}") from exc
    if P.ndim == 1 and P.shape == (3,):
        P = P[None, :]
    if P.ndim != 2 or P.shape[1] != 3:
        raise InvalidInput(f"{what} must have shape (N, 3) [m], got {P.shape}")
    if not np.all(np.isfinite(P)):
        raise InvalidInput(f"{what} holds NaN or inf")
    return P
