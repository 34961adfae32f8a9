"""Exact extrema of piecewise polynomials, for one trajectory or a whole population.

On a polynomial piece the extrema of ``|d^r q / dt^r|`` lie at the piece ends or at real
roots of the next derivative. Pieces are handled in normalised time ``s = tau / h`` in
[0, 1] (all coefficients comparable), where the roots are found for all pieces, joints and
derivative orders at once: closed form up to degree 3 (Cardano / trigonometric for
cubics), batched companion-matrix eigenvalues above. The r-th derivative in real time is
the r-th derivative in ``s`` divided by ``h**r``.

:class:`pinarms.planning.Trajectory` uses :func:`piece_extrema` for its peaks and limit checks;
optimisers that time many trajectories at once (a GA population, finite-difference
Jacobians) call :func:`piece_peaks_batch` / :func:`peaks_batch` on the coefficient arrays
returned by the ``*_batch`` constructors, so that one numpy pass peaks every piece of every
individual.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning import _inputs
from pinarms.planning.errors import TrajectoryError

__all__ = ["COMPILED", "piece_extrema", "piece_peaks_batch", "peaks_batch", "normalised_pieces", "derivative_coefficients"]

#: Pieces whose next derivatives have degree <= 4 (degree <= 6 for velocities and up) take the compiled loop
#: (:mod:`pinarms.planning.extrema_kernel`, the same operations); ``False``: the numpy route for every
#: piece (the code before it, for benchmarks that time both).
COMPILED = True

#: Relative size below which a leading polynomial coefficient counts as zero in the root
#: search (in normalised piece time s in [0, 1], where all coefficients are comparable).
_ROOT_RTOL = 1e-12


def derivative_coefficients(coefs: np.ndarray, order: int, axis: int) -> np.ndarray:
    """Coefficients (ascending powers along ``axis``) of the ``order``-th derivative; same length, zero padded."""
    c = np.moveaxis(np.asarray(coefs, dtype=float), axis, -1)
    width = c.shape[-1]
    out = np.zeros_like(c)
    if order < width:
        k = np.arange(order, width)
        falling = np.ones(width - order)
        for r in range(order):
            falling *= k - r
        out[..., : width - order] = c[..., order:] * falling
    return np.moveaxis(out, -1, axis)


@functools.lru_cache(maxsize=64)
def _derivative_matrices(width: int, orders: tuple[int, ...]) -> np.ndarray:
    """Right-multiplication matrices (o, W, 2W-1) from ascending coefficients (.., W) to derivatives.

    ``c @ M[i]`` holds, side by side, the coefficients of the ``orders[i]``-th derivative
    (first W columns) and of the next derivative (last W-1 columns; its always-zero top
    coefficient dropped). For W = 1 the second block is one zero column.
    """
    eye = np.eye(width)
    blocks = []
    for r in orders:
        nxt = derivative_coefficients(eye, r + 1, axis=1)[:, : max(width - 1, 1)]
        if width == 1:
            nxt = np.zeros((1, 1))
        blocks.append(np.concatenate([derivative_coefficients(eye, r, axis=1), nxt], axis=1))
    M = np.stack(blocks)
    M.flags.writeable = False
    return M


def _horner(coefs: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Evaluate rows of ascending coefficients (B, D+1) at points (B, C) -> (B, C)."""
    out = np.zeros(s.shape)
    for k in range(coefs.shape[1] - 1, -1, -1):
        out = out * s + coefs[:, k : k + 1]
    return out


_THIRDS = (2.0 * np.pi / 3.0) * np.arange(3)


def _cubic_roots(R: np.ndarray) -> np.ndarray:
    """Real parts of the three roots of cubics with ascending coefficients R (k, 4), R[:, 3] != 0.

    Closed form (Cardano for one real root, trigonometric for three); a complex pair
    contributes its real part. Root errors only matter to second order for the extremum
    values evaluated there. Both branches are computed for all rows (fewer numpy calls).
    """
    inv = 1.0 / R[:, 3]
    B3 = R[:, 2] * inv / 3.0
    C = R[:, 1] * inv
    p = C - 3.0 * B3 * B3
    q = B3 * (2.0 * B3 * B3 - C) + R[:, 0] * inv
    disc = 0.25 * q * q + p * p * p / 27.0
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.cbrt(-0.5 * q - np.copysign(np.sqrt(np.maximum(disc, 0.0)), q))
        y1 = np.where(u != 0.0, u - p / (3.0 * u), 0.0)
        mag = 2.0 * np.sqrt(np.maximum(-p, 0.0) / 3.0)
        arg = np.where(mag > 0.0, -4.0 * q / (mag * mag * mag), 1.0)
    theta = np.arccos(np.minimum(np.maximum(arg, -1.0), 1.0)) / 3.0
    three = mag[:, None] * np.cos(theta[:, None] - _THIRDS)
    one = np.stack([y1, -0.5 * y1, -0.5 * y1], axis=1)
    return np.where((disc > 0.0)[:, None], one, three) - B3[:, None]


def _candidate_points(R: np.ndarray) -> np.ndarray:
    """Points of [0, 1] where the polynomials with ascending coefficients ``R`` (B, D+1) may vanish.

    Returns (B, max(D, 1)): the real parts of all roots, clipped to [0, 1], zero padded.
    Extra candidates are harmless (the caller evaluates the function there and takes the
    extreme), so complex roots keep their real part and no root is ever missed. Leading
    coefficients below ``_ROOT_RTOL`` times the row's largest one are dropped (their roots
    lie far outside [0, 1]). Closed forms up to degree 3, companion-matrix eigenvalues above.
    """
    B, width = R.shape
    D = width - 1
    out = np.zeros((B, max(D, 1)))
    if D == 0 or B == 0:
        return out
    mag = np.abs(R)
    threshold = _ROOT_RTOL * mag.max(axis=1)
    significant = mag > threshold[:, None]
    degree = D - np.argmax(significant[:, ::-1], axis=1)
    degree[threshold == 0.0] = 0
    for d in range(1, D + 1):
        rows = np.flatnonzero(degree == d)
        if rows.size == 0:
            continue
        Rr = R[rows, : d + 1]
        if d == 1:
            out[rows, 0] = -Rr[:, 0] / Rr[:, 1]
        elif d == 2:
            a, b, c = Rr[:, 2], Rr[:, 1], Rr[:, 0]
            sq = np.sqrt(np.maximum(b * b - 4.0 * a * c, 0.0))
            q = -0.5 * (b + np.copysign(sq, b))
            out[rows, 0] = q / a
            safe_q = np.where(q != 0.0, q, 1.0)
            out[rows, 1] = np.where(q != 0.0, c / safe_q, 0.0)
        elif d == 3:
            out[rows, :3] = _cubic_roots(Rr)
        else:
            monic = Rr[:, :d] / Rr[:, d : d + 1]
            companion = np.zeros((rows.size, d, d))
            companion[:, np.arange(1, d), np.arange(d - 1)] = 1.0
            companion[:, :, d - 1] = -monic
            out[rows, :d] = np.linalg.eigvals(companion).real
    return np.minimum(np.maximum(out, 0.0), 1.0)


def normalised_pieces(coefficients: np.ndarray, durations: np.ndarray) -> np.ndarray:
    """Coefficients in normalised piece time: (..., m, K+1, n) in tau and (..., m) s -> (..., m, n, K+1) in s."""
    width = coefficients.shape[-2]
    cn = coefficients * (durations[..., None] ** np.arange(width))[..., None]
    return np.ascontiguousarray(np.swapaxes(cn, -1, -2))


def piece_extrema(normalised: np.ndarray, durations: np.ndarray, orders: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Candidate extrema of the derivatives ``orders`` on every piece.

    Args:
        normalised: (M, n, W) coefficients of M pieces and n joints in normalised time
            ``s in [0, 1]`` (ascending powers; see :func:`normalised_pieces`).
        durations: (M,) piece durations h (s).
        orders: derivative orders r (0 = position).

    Returns:
        ``(values, s)``: ``values`` (len(orders), M, n, C) holds the r-th derivative in real
        time (unit / s^r) at the piece ends and at every root of the next derivative;
        ``s`` (len(orders) * M * n, C) the normalised instants. Max/min over the last axis
        are the exact extrema of each piece.
    """
    M, n, width = normalised.shape
    o = len(orders)
    if COMPILED and o and width - min(orders) <= 6 and M * n:  # every next derivative of degree <= 4: compiled
        from pinarms.planning.extrema_kernel import extrema_values

        return extrema_values(np.ascontiguousarray(normalised, dtype=float), np.ascontiguousarray(durations, dtype=float),
                              np.asarray(orders, dtype=np.int64))
    D = _derivative_matrices(width, tuple(orders))  # (o, W, 2W-1): [derivative r | derivative r+1]
    PR = np.matmul(normalised.reshape(M * n, width), D)  # (o, M*n, 2W-1), coefficients in s
    scale = np.repeat(durations[None, :] ** -np.asarray(orders, dtype=float)[:, None], n, axis=1)
    P = PR[:, :, :width] * scale[:, :, None]  # d^r q / dt^r = h^-r d^r q / ds^r
    roots = _candidate_points(PR[:, :, width:].reshape(o * M * n, -1))
    B = roots.shape[0]
    s = np.empty((B, roots.shape[1] + 2))
    s[:, 0] = 0.0
    s[:, 1] = 1.0
    s[:, 2:] = roots
    values = _horner(P.reshape(B, width), s).reshape(o, M, n, -1)
    return values, s


def _batch_inputs(times: Any, coefficients: Any) -> tuple[np.ndarray, np.ndarray]:
    t = _inputs.knot_times_batch(times)
    c = _inputs.finite_array(coefficients, "coefficients")
    P, m = t.shape[0], t.shape[1] - 1
    if c.ndim != 4 or c.shape[:2] != (P, m) or c.shape[2] < 1 or c.shape[3] < 1:
        raise TrajectoryError(
            f"coefficients must have shape ({P}, {m}, degree+1, n_joints) for times of shape {t.shape}, "
            f"got {c.shape}"
        )
    return t, c


def piece_peaks_batch(times: ArrayLike, coefficients: ArrayLike) -> np.ndarray:
    """Exact peaks of |velocity|, |acceleration|, |jerk| per individual, piece and joint.

    Args:
        times: (P, m+1) knot times (s) of P trajectories, each row strictly increasing.
        coefficients: (P, m, K+1, n_joints) piece coefficients in ascending powers of the
            time since each piece's start (as returned by the ``*_batch`` constructors and
            stored by :class:`pinarms.planning.Trajectory`).

    Returns:
        (P, 3, m, n_joints): maxima of |qd|, |qdd|, |qddd| on each piece (unit/s, /s², /s³).
    """
    t, c = _batch_inputs(times, coefficients)
    P, m, _, n = c.shape
    if P == 0:
        return np.zeros((0, 3, m, n))
    h = np.diff(t, axis=1)
    cn = normalised_pieces(c, h).reshape(P * m, n, -1)
    values, _ = piece_extrema(cn, h.reshape(-1), (1, 2, 3))
    top = np.abs(values).max(axis=3).reshape(3, P, m, n)
    return np.moveaxis(top, 0, 1)


def peaks_batch(times: ArrayLike, coefficients: ArrayLike) -> np.ndarray:
    """Exact whole-trajectory peaks (P, 3, n_joints): |velocity|, |acceleration|, |jerk| maxima.

    Same arguments as :func:`piece_peaks_batch`; row p equals
    ``Trajectory(times[p], coefficients[p]).peaks()`` (velocity, acceleration, jerk).
    """
    return piece_peaks_batch(times, coefficients).max(axis=2)
