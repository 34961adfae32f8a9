"""Rest-to-rest point-to-point profiles: trapezoidal velocity and jerk-limited double-S.

Both follow Biagiotti & Melchiorri, *Trajectory Planning for Automatic Machines and
Robots* (Springer 2008): sec. 3.2.2 (trapezoidal, with the triangular case when the
cruise velocity cannot be reached) and sec. 3.4 (double-S, with the cases where the
maximum velocity and/or the maximum acceleration are not reached; for a rest-to-rest
motion these have closed forms).

Multi-joint motions are *synchronised*: every joint gets its own minimum-time profile,
the slowest joint sets the duration ``T``, and every other joint's profile is uniformly
time-scaled to last ``T`` (velocity / λ, acceleration / λ², jerk / λ³ with λ >= 1, so no
limit is exceeded). With ``synchronized=False`` each joint moves in its own minimum time
and then holds its target.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning import _inputs
from pinarms.planning.errors import TrajectoryError
from pinarms.planning.poly_pieces import pad_degree, taylor_shift
from pinarms.planning.trajectory import MAX_DURATION, Trajectory

__all__ = ["trapezoidal", "double_s", "double_s_phases", "trapezoidal_phases"]


def trapezoidal_phases(distance: float, vmax: float, amax: float) -> tuple[float, float]:
    """Acceleration time ``Ta`` and total time ``T`` (s) of a rest-to-rest trapezoidal move.

    ``distance`` >= 0 (rad or m). When ``distance < vmax²/amax`` the cruise velocity is not
    reached (triangular profile: ``Ta = sqrt(distance/amax)``, ``T = 2 Ta``).
    """
    if distance <= 0.0:
        return 0.0, 0.0
    if distance * amax >= vmax * vmax:
        Ta = vmax / amax
        return Ta, distance / vmax + Ta
    Ta = math.sqrt(distance / amax)
    return Ta, 2.0 * Ta


def double_s_phases(distance: float, vmax: float, amax: float, jmax: float) -> tuple[float, float, float]:
    """Jerk time ``Tj``, acceleration time ``Ta`` and cruise time ``Tv`` (s) of a rest-to-rest double-S.

    The deceleration mirrors the acceleration (``Td = Ta``), total time ``T = 2 Ta + Tv``.
    Cases (B&M sec. 3.4): amax reached or not while reaching vmax; if vmax is not reached
    (``Tv`` would be negative), ``Ta = (amax²/jmax + sqrt(amax⁴/jmax² + 4 amax distance)) / (2 amax)``;
    if then ``Ta < 2 Tj`` neither vmax nor amax is reached: ``Tj = (distance / (2 jmax))^(1/3)``, ``Ta = 2 Tj``.
    """
    if distance <= 0.0:
        return 0.0, 0.0, 0.0
    if vmax * jmax < amax * amax:
        Tj = math.sqrt(vmax / jmax)
        Ta = 2.0 * Tj
    else:
        Tj = amax / jmax
        Ta = Tj + vmax / amax
    Tv = distance / vmax - Ta
    if Tv >= 0.0:
        return Tj, Ta, Tv
    Tj = amax / jmax
    Ta = (amax * amax / jmax + math.sqrt(amax**4 / jmax**2 + 4.0 * amax * distance)) / (2.0 * amax)
    if Ta < 2.0 * Tj:
        Tj = (distance / (2.0 * jmax)) ** (1.0 / 3.0)
        Ta = 2.0 * Tj
    return Tj, Ta, 0.0


def _integrate_jerk_phases(q0: float, durations: list[float], jerks: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """Breaks (from 0) and cubic coefficients (k, 4) of constant-jerk phases starting at rest at q0."""
    total = sum(durations)
    keep = [(d, j) for d, j in zip(durations, jerks) if d > 1e-14 * max(total, 1e-300)]
    breaks = [0.0]
    coefs = []
    q, v, a = q0, 0.0, 0.0
    for d, j in keep:
        coefs.append([q, v, 0.5 * a, j / 6.0])
        q, v, a = q + v * d + 0.5 * a * d * d + j * d**3 / 6.0, v + a * d + 0.5 * j * d * d, a + j * d
        breaks.append(breaks[-1] + d)
    return np.array(breaks), np.array(coefs)


def _one_joint(breaks: np.ndarray, coefs: np.ndarray, q1: float, T_own: float, T: float, synchronized: bool) -> Trajectory:
    """Single-joint trajectory over [0, T]: scaled to T, or held at q1 after its own T_own."""
    if coefs.size == 0:  # no motion
        return Trajectory([0.0, T], np.array([[[q1]]]))
    if synchronized:
        lam = T / T_own
        with np.errstate(over="ignore", under="ignore", divide="ignore", invalid="ignore"):
            b = breaks * lam
            c = coefs / (lam ** np.arange(coefs.shape[1]))[None, :]
        b[-1] = T
        return Trajectory(b, c[:, :, None])  # refuses non-finite coefficients by name
    b = breaks.copy()
    c = coefs
    if T - T_own > 1e-12 * T:
        b = np.append(b, T)
        hold = np.zeros((1, coefs.shape[1]))
        hold[0, 0] = q1
        c = np.vstack([coefs, hold])
    else:
        b[-1] = T
    return Trajectory(b, c[:, :, None])


def _total(T: float) -> float:
    if not (math.isfinite(T) and T <= MAX_DURATION):
        raise TrajectoryError(f"the move would last {T:.3g} s with these limits, more than {MAX_DURATION:.0e} s: "
                              f"give limits of a physical motion")
    return T


def _endpoints(q0: Any, q1: Any) -> tuple[np.ndarray, np.ndarray]:
    a = _inputs.finite_array(q0, "q0")
    b = _inputs.finite_array(q1, "q1")
    a, b = np.atleast_1d(a), np.atleast_1d(b)
    if a.ndim != 1 or a.shape != b.shape:
        raise TrajectoryError(f"q0 and q1 must be (n_joints,) arrays of the same shape, got {a.shape} and {b.shape}")
    if np.all(a == b):
        raise TrajectoryError(f"q0 equals q1 ({a.tolist()}): there is no motion to plan")
    return a, b


def _quiet_floats(fn: Any) -> Any:
    """Run ``fn`` without float warnings: absurd limits (1e-300, 1e300) overflow the phase times,
    and the Trajectory built at the end refuses non-finite or over-long results by name."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with np.errstate(all="ignore"):
            return fn(*args, **kwargs)

    return wrapper


@_quiet_floats
def trapezoidal(q0: ArrayLike, q1: ArrayLike, vmax: ArrayLike, amax: ArrayLike, *, synchronized: bool = True) -> Trajectory:
    """Rest-to-rest trapezoidal-velocity move from ``q0`` to ``q1`` (rad or m), starting at t = 0.

    ``vmax`` (rad/s) and ``amax`` (rad/s²) are scalars or per joint. Pieces are quadratics.
    """
    a, b = _endpoints(q0, q1)
    n = a.size
    v = _inputs.per_joint(vmax, n, "vmax", positive=True)
    acc = _inputs.per_joint(amax, n, "amax", positive=True)
    profiles = []
    for j in range(n):
        d = abs(b[j] - a[j])
        Ta, T = trapezoidal_phases(d, v[j], acc[j])
        sign = math.copysign(1.0, b[j] - a[j])
        profiles.append((Ta, T, sign))
    T = _total(max(p[1] for p in profiles))
    parts = []
    for j, (Ta, Tj_total, sign) in enumerate(profiles):
        if Tj_total == 0.0:
            parts.append(_one_joint(np.array([0.0]), np.zeros((0, 3)), b[j], 0.0, T, synchronized))
            continue
        Tc = Tj_total - 2.0 * Ta
        pieces_d = [Ta, Tc, Ta]
        pieces_a = [sign * acc[j], 0.0, -sign * acc[j]]
        total = Tj_total
        keep = [(d, ac) for d, ac in zip(pieces_d, pieces_a) if d > 1e-14 * total]
        breaks = [0.0]
        coefs = []
        q, vel = a[j], 0.0
        for d, ac in keep:
            coefs.append([q, vel, 0.5 * ac])
            q, vel = q + vel * d + 0.5 * ac * d * d, vel + ac * d
            breaks.append(breaks[-1] + d)
        parts.append(_one_joint(np.array(breaks), np.array(coefs), b[j], Tj_total, T, synchronized))
    definition = {
        "kind": "trapezoidal",
        "q0": a.tolist(),
        "q1": b.tolist(),
        "vmax": v.tolist(),
        "amax": acc.tolist(),
        "synchronized": bool(synchronized),
    }
    return stack_joints(parts, definition)


@_quiet_floats
def double_s(q0: ArrayLike, q1: ArrayLike, vmax: ArrayLike, amax: ArrayLike, jmax: ArrayLike, *, synchronized: bool = True) -> Trajectory:
    """Rest-to-rest jerk-limited (double-S) move from ``q0`` to ``q1`` (rad or m), starting at t = 0.

    ``vmax`` (rad/s), ``amax`` (rad/s²), ``jmax`` (rad/s³): scalars or per joint. Pieces are
    cubics (constant jerk per phase, up to seven phases).
    """
    a, b = _endpoints(q0, q1)
    n = a.size
    v = _inputs.per_joint(vmax, n, "vmax", positive=True)
    acc = _inputs.per_joint(amax, n, "amax", positive=True)
    jer = _inputs.per_joint(jmax, n, "jmax", positive=True)
    own = []
    for j in range(n):
        d = abs(b[j] - a[j])
        if d == 0.0:
            own.append((np.array([0.0]), np.zeros((0, 4)), 0.0))
            continue
        Tj, Ta, Tv = double_s_phases(d, v[j], acc[j], jer[j])
        s = math.copysign(1.0, b[j] - a[j]) * jer[j]
        durations = [Tj, Ta - 2.0 * Tj, Tj, Tv, Tj, Ta - 2.0 * Tj, Tj]
        jerks = [s, 0.0, -s, 0.0, -s, 0.0, s]
        breaks, coefs = _integrate_jerk_phases(a[j], durations, jerks)
        own.append((breaks, coefs, 2.0 * Ta + Tv))
    T = _total(max(o[2] for o in own))
    parts = [_one_joint(br, co, b[j], Tt, T, synchronized) for j, (br, co, Tt) in enumerate(own)]
    definition = {
        "kind": "double_s",
        "q0": a.tolist(),
        "q1": b.tolist(),
        "vmax": v.tolist(),
        "amax": acc.tolist(),
        "jmax": jer.tolist(),
        "synchronized": bool(synchronized),
    }
    return stack_joints(parts, definition)


def stack_joints(parts: list[Trajectory], definition: dict | None = None) -> Trajectory:
    """Combine single-joint trajectories with the same time range into one multi-joint trajectory.

    The breaks are the union of all parts' breaks (instants closer than 1e-12 of the
    duration are merged); each part is re-expanded about the union breaks.
    """
    t0, t1 = parts[0].start_time, parts[0].end_time
    tol = 1e-12 * max(1.0, abs(t0), abs(t1))
    for p in parts[1:]:
        if abs(p.start_time - t0) > tol or abs(p.end_time - t1) > tol:
            raise TrajectoryError(
                f"cannot stack trajectories over different times: [{t0}, {t1}] vs [{p.start_time}, {p.end_time}] s"
            )
    allb = np.sort(np.concatenate([p.knot_times for p in parts]))
    keep = np.concatenate([[True], np.diff(allb) > tol])
    breaks = allb[keep]
    breaks[0], breaks[-1] = t0, t1
    if breaks.size >= 2 and breaks[-1] - breaks[-2] <= tol:
        breaks = np.delete(breaks, -2)
    mid = 0.5 * (breaks[:-1] + breaks[1:])
    width = max(p.degree for p in parts) + 1
    cols = []
    for p in parts:
        knots = p.knot_times
        seg = np.clip(np.searchsorted(knots, mid, side="right") - 1, 0, p.n_segments - 1)
        c = pad_degree(p.coefficients, width)[seg]
        cols.append(taylor_shift(c, breaks[:-1] - knots[seg]))
    return Trajectory(breaks, np.concatenate(cols, axis=2), definition)
