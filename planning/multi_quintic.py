"""One quintic per segment, from positions, velocities and accelerations at the via points.

Each segment is the quintic Hermite polynomial matching ``(q, qd, qdd)`` at both of its
knots, so position, velocity and acceleration are continuous by construction. The via
velocities and accelerations are

* zero (the default, as in seed 001: the arm stops at P2 and P3),
* given arrays, or
* chosen by a documented rule:

  - ``velocities="heuristic"``: Biagiotti & Melchiorri, *Trajectory Planning for
    Automatic Machines and Robots* (Springer 2008), sec. 4.1: with segment slopes
    ``d_k = (q_k - q_{k-1}) / h_k``, the interior velocity is ``(d_k + d_{k+1}) / 2`` when
    both slopes have the same sign and 0 otherwise (so the joint stops where it turns
    back); end velocities are 0.
  - ``accelerations="continuous"``: interior accelerations solved so that the *jerk* is
    continuous at every interior knot (one tridiagonal system per joint; end
    accelerations 0). Per segment of duration h the jerk at its start is
    ``J0s - 9 a_0/h + 3 a_1/h`` and at its end ``J0e - 3 a_0/h + 9 a_1/h`` (J0 = jerk with
    zero accelerations), which gives for interior knot k:
    ``-3/h_{k-1} a_{k-1} + 9 (1/h_{k-1} + 1/h_k) a_k - 3/h_k a_{k+1} = J0s_k - J0e_{k-1}``.

:func:`multi_quintic_batch` computes the coefficients for P timings of the same via points
at once (closed form per segment, the rules per timing, one batched solve for the
accelerations); :func:`multi_quintic` is the same code with P = 1.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning import _inputs
from pinarms.planning.errors import TrajectoryError
from pinarms.planning.trajectory import Trajectory

__all__ = ["multi_quintic", "multi_quintic_batch", "multi_quintic_peaks_batch", "quintic_hermite_coefficients",
           "heuristic_velocities"]


def quintic_hermite_coefficients(
    h: np.ndarray, q0: np.ndarray, v0: np.ndarray, a0: np.ndarray, q1: np.ndarray, v1: np.ndarray, a1: np.ndarray
) -> np.ndarray:
    """Coefficients (..., m, 6, n) in ascending powers of tau (s) of the quintics matching both ends.

    ``h`` is (..., m) (s); the state arrays are (..., m, n) (rad, rad/s, rad/s²); leading
    batch axes broadcast (e.g. durations (P, m) with shared positions (m, n)).
    """
    H = np.asarray(h, dtype=float)[..., None]
    d = q1 - q0
    shape = np.broadcast_shapes(H.shape, d.shape, v0.shape, a0.shape, v1.shape, a1.shape)
    c = np.empty(shape[:-1] + (6, shape[-1]))
    c[..., 0, :] = q0
    c[..., 1, :] = v0
    c[..., 2, :] = 0.5 * a0
    c[..., 3, :] = (20.0 * d - (8.0 * v1 + 12.0 * v0) * H - (3.0 * a0 - a1) * H**2) / (2.0 * H**3)
    c[..., 4, :] = (-30.0 * d + (14.0 * v1 + 16.0 * v0) * H + (3.0 * a0 - 2.0 * a1) * H**2) / (2.0 * H**4)
    c[..., 5, :] = (12.0 * d - 6.0 * (v1 + v0) * H + (a1 - a0) * H**2) / (2.0 * H**5)
    return c


def heuristic_velocities(times: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """Via velocities by the sign-of-slopes rule (ends 0); see the module docstring.

    ``times`` (m+1,) or (P, m+1) (s), ``positions`` (m+1, n) -> (m+1, n) or (P, m+1, n).
    """
    slopes = np.diff(positions, axis=-2) / np.diff(times, axis=-1)[..., None]
    v = np.zeros(slopes.shape[:-2] + positions.shape[-2:])
    same = np.sign(slopes[..., :-1, :]) == np.sign(slopes[..., 1:, :])
    v[..., 1:-1, :] = np.where(same, 0.5 * (slopes[..., :-1, :] + slopes[..., 1:, :]), 0.0)
    return v


def _jerk_continuous_accelerations(h: np.ndarray, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Interior accelerations making the jerk continuous: h (P, m), q (m+1, n), v (P, m+1, n) -> (P, m+1, n)."""
    P, m, n = h.shape[0], h.shape[1], q.shape[1]
    acc = np.zeros((P, m + 1, n))
    if m < 2:
        return acc
    zero = np.zeros((m, n))
    c = quintic_hermite_coefficients(h, q[:-1], v[:, :-1], zero, q[1:], v[:, 1:], zero)
    H = h[:, :, None]
    jerk_start = 6.0 * c[:, :, 3]
    jerk_end = 6.0 * c[:, :, 3] + 24.0 * c[:, :, 4] * H + 60.0 * c[:, :, 5] * H**2
    k = np.arange(1, m)  # interior knots
    A = np.zeros((P, m - 1, m - 1))
    A[:, k - 1, k - 1] = 9.0 / h[:, k - 1] + 9.0 / h[:, k]
    A[:, k[1:] - 1, k[1:] - 2] = -3.0 / h[:, k[1:] - 1]
    A[:, k[:-1] - 1, k[:-1]] = -3.0 / h[:, k[:-1]]
    rhs = jerk_start[:, k] - jerk_end[:, k - 1]
    acc[:, 1:-1] = np.linalg.solve(A, rhs)
    return acc


def _via_values(spec: Any, rule: str, what: str, n_points: int, n_joints: int) -> np.ndarray | str:
    if spec is None or (isinstance(spec, str) and spec == "zero"):
        return np.zeros((n_points, n_joints))
    if isinstance(spec, str):
        if spec != rule:
            raise TrajectoryError(f"{what} must be None, 'zero', '{rule}' or an array, got {spec!r}")
        return spec
    return _inputs.per_point(spec, n_points, n_joints, what)


def _coefficients(t: np.ndarray, q: np.ndarray, velocities: Any, accelerations: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Coefficients (P, m, 6, n) and the via velocities and accelerations (P, m+1, n) for knot times (P, m+1)."""
    P = t.shape[0]
    n_points, n = q.shape
    h = np.diff(t, axis=1)
    v = _via_values(velocities, "heuristic", "velocities", n_points, n)
    v = heuristic_velocities(t, q) if isinstance(v, str) else np.broadcast_to(v, (P, n_points, n))
    a = _via_values(accelerations, "continuous", "accelerations", n_points, n)
    a = _jerk_continuous_accelerations(h, q, v) if isinstance(a, str) else np.broadcast_to(a, (P, n_points, n))
    coefs = quintic_hermite_coefficients(h, q[:-1], v[:, :-1], a[:, :-1], q[1:], v[:, 1:], a[:, 1:])
    return coefs, v, a


def multi_quintic_batch(times: ArrayLike, positions: ArrayLike, velocities: ArrayLike | None = None, accelerations: ArrayLike | None = None) -> np.ndarray:
    """Coefficients of :func:`multi_quintic` for P timings of the same via points at once.

    Args:
        times: (P, m+1) knot times (s), every row strictly increasing.
        positions: (m+1,) or (m+1, n_joints) via points shared by all rows (rad or m).
        velocities, accelerations: as :func:`multi_quintic`; the rules (``"heuristic"``,
            ``"continuous"``) are applied to each row's times, arrays are shared.

    Returns:
        (P, m, 6, n_joints) coefficients in ascending powers of the time since each piece's
        start; row p is ``multi_quintic(times[p], ...).coefficients`` (same code).
    """
    t = _inputs.knot_times_batch(times)
    q = _inputs.via_positions(positions, t.shape[1])
    return _coefficients(t, q, velocities, accelerations)[0]


def multi_quintic_peaks_batch(times: np.ndarray, positions: np.ndarray, heuristic: bool) -> np.ndarray:
    """Peaks (P, 3, n) of |velocity|, |acceleration|, |jerk| of P multi-quintic timings of the same via points.

    ``times`` (P, m+1) strictly increasing knot times (s, not checked: a timing optimiser's own),
    ``positions`` (m+1, n); via velocities by the sign-of-slopes rule (``heuristic``) or zero, via
    accelerations zero. Equals :func:`pinarms.planning.peaks_batch` of :func:`multi_quintic_batch`
    (``velocities="heuristic"`` or None) to rounding, without building the coefficient arrays: one
    compiled loop (:mod:`pinarms.planning.extrema_kernel`), for optimisers that peak one timing
    at a time.
    """
    from pinarms.planning.extrema_kernel import multi_quintic_peaks

    return multi_quintic_peaks(np.ascontiguousarray(times, dtype=float), np.ascontiguousarray(positions, dtype=float),
                               bool(heuristic))


def multi_quintic(times: ArrayLike, positions: ArrayLike, velocities: ArrayLike | None = None, accelerations: ArrayLike | None = None) -> Trajectory:
    """One quintic per segment through the via points.

    Args:
        times: knot times (s), (m+1,), strictly increasing.
        positions: (m+1,) or (m+1, n_joints) (rad or m).
        velocities: ``None``/``"zero"`` (stop at every via point, seed 001), ``"heuristic"``
            or an array (m+1,)/(m+1, n_joints) (rad/s).
        accelerations: ``None``/``"zero"``, ``"continuous"`` (continuous jerk) or an array (rad/s²).
    """
    t = _inputs.knot_times(times)
    q = _inputs.via_positions(positions, t.size)
    coefs, v, a = _coefficients(t[None], q, velocities, accelerations)

    def _spec(value: Any, arr: np.ndarray) -> Any:
        if isinstance(value, str) and value not in ("zero",):
            return value
        if value is None or (isinstance(value, str) and value == "zero"):
            return None
        return arr.tolist()

    definition = {
        "kind": "multi_quintic",
        "times": t.tolist(),
        "positions": q.tolist(),
        "velocities": _spec(velocities, v[0]),
        "accelerations": _spec(accelerations, a[0]),
    }
    return Trajectory(t, coefs[0], definition)
