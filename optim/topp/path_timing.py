"""Time-optimal timing of a geometric path under a list of constraints: a ``Trajectory`` out.

:func:`time_optimal` takes a :class:`pinarms.planning.JointPath` ``q(s)`` (a Cartesian line's
joint image, a joint spline, ...) and :mod:`pinarms.planning.path_constraints` objects, and
returns a :class:`PathTiming` whose ``trajectory`` is a :class:`pinarms.planning.Trajectory` like
every other (sampling, exact peaks, limit checks, sessions, plots, viewer).

1. **Sections.** The path is cut at its stops (tangent discontinuities): each section is
   timed from rest to rest (the path's ends may have given speeds ``ṡ``).
2. **Grid.** The path's own breaks, each piece cut in equal steps so that the whole path
   has about ``grid`` intervals, then intervals halved until the tangent ``q'`` changes by
   at most ``kappa`` (2 %) of its size across each (dense where the path bends).
3. **Profile.** :func:`pinarms.optim.topp.topp_profile` (TOPP-RA, interpolation
   discretisation) on the rows of all constraints: ``ṡ²`` at the grid points, constant
   ``s̈`` between.
4. **Check and refine.** Between grid points the rows are evaluated at 1/4, 1/2, 3/4 and
   the end of every interval with the profile's (u, x). Intervals where a row exceeds its
   bound by more than ``rtol`` (relative, in the squared-speed sense) are split in two and
   the profile is recomputed (``max_rounds``). What remains is removed by a uniform **time
   dilation** ``f`` (ṡ → ṡ/f, s̈ → s̈/f²), from the dense check and, for joint limits, from
   the trajectory's *exact* peaks: the returned trajectory satisfies every joint limit
   exactly (``dilation`` reports f; 1 + rtol/2 at most from the dense check).
5. **Trajectory, exactly.** The time law s(t) is a piecewise polynomial (quadratic on each
   grid interval) and the path piece a polynomial of degree D in s, so ``q(t) = q(s(t))``
   is a polynomial in t on each piece: it is composed exactly (no refit), and the
   Trajectory's peaks and checks are those of the timed path itself.

**Jerk** (``jerk=``): the time-optimal profile above is bang–bang (joint accelerations
jump). With a jerk limit the result is a **smoothed** one, not a jerk-limited optimum (that
problem is not convex): s(t) is averaged over a sliding window τ,
``s_τ(t) = (1/τ) ∫_{t−τ}^{t} s``, which makes s̈ continuous and bounds s⃛ by the jumps of s̈
over τ (still at rest at both ends; τ longer in time). τ starts at the largest jump of a
joint acceleration divided by its jerk limit, and a few multiples are tried; each result is
slowed uniformly until every joint limit — velocity, acceleration and jerk, exact peaks —
and every path constraint (dense check) holds, and the shortest is kept.

Where each step lives: :mod:`.grid` (steps 2–4 on one section), :mod:`.profile` (step 3, the
TOPP-RA algorithm written here rather than toppra's: measured as fast on the same grid and
rows, bit-reproducible, every constraint object as rows; figures and command there, toppra
stays the cross-check in the tests), :mod:`.dense_check` (the checks of steps 4 and the
jerk smoothing), :mod:`.time_law` (step 5 and the smoothing of the law).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.optim.caps import (MAX_PATH_GRID, MAX_PATH_ROUNDS, MAX_TIME_SCALED_SAMPLES, MIN_PATH_KAPPA,
                               MIN_PATH_RTOL, count_setting)
from pinarms.optim.errors import InfeasibleProblem, InvalidSettings, SettingOutOfRange
from pinarms.optim.ga.problem import check_limit
from pinarms.optim.topp.dense_check import CHECK_FRACTIONS, Peaked, law_check, law_rows, ratios, row_names, \
    rows_at_sets
from pinarms.optim.topp.grid import path_grid, refined_section
from pinarms.optim.topp.time_law import (acceleration_jumps, assemble, bang_bang, compose_law, law_eval, scaled_law,
                                         smoothed)
from pinarms.planning import Trajectory
from pinarms.planning.path_constraints import PathConstraint, PathRows

if TYPE_CHECKING:
    from pinarms.planning.joint_path import JointPath

__all__ = ["PathTiming", "time_optimal", "time_scaled", "SHAPES", "CHECK_FRACTIONS", "SMOOTHING_FACTORS"]

#: Rest-to-rest shapes σ(τ) of :func:`time_scaled`, ascending coefficients in τ ∈ [0, 1]
#: (cubic: zero end velocity; quintic: zero end velocity and acceleration).
SHAPES = {"cubic": (0.0, 0.0, 3.0, -2.0), "quintic": (0.0, 0.0, 0.0, 10.0, -15.0, 6.0)}

#: Multiples of the first smoothing window tried under a jerk limit.
SMOOTHING_FACTORS = (1.0, 1.6, 2.5)


@dataclass(frozen=True, eq=False)
class PathTiming:
    """A timing of a path (see the module docstring).

    Attributes:
        path: the :class:`pinarms.planning.JointPath` timed.
        constraints: the constraint objects used.
        trajectory: q(t), a :class:`pinarms.planning.Trajectory` (q(s(t)) composed exactly).
        law_breaks: (P+1,) instants [s] of the pieces of the time law s(t).
        law_coefficients: (P, k+1) s(t) on each piece, ascending powers of the time since its
            start (k = 2: the time-optimal profile; k = 3: smoothed under a jerk limit).
        grid: the reachability grid (G,) [path unit], sections end to end (a stop appears twice).
        dilation: the uniform time dilation f >= 1 applied after the checks.
        smoothing: the averaging window τ [s] (0 without a jerk limit).
        rounds: grid refinements made.
        ratios: per constraint name, the largest value / bound of the dense check (<= 1; for
            speed limits the ratio of speeds, not of their squares): the rows at 0, 1/4 … 1 of
            every law piece, evaluated on first use (a planner that never reads them does not
            pay for them; the limits themselves were checked before the timing was returned).
    """

    path: Any = field(repr=False)
    constraints: tuple = field(repr=False)
    trajectory: Trajectory = field(repr=False)
    law_breaks: np.ndarray = field(repr=False)
    law_coefficients: np.ndarray = field(repr=False)
    grid: np.ndarray = field(repr=False)
    dilation: float = 1.0
    smoothing: float = 0.0
    rounds: int = 0
    given_ratios: dict | None = field(default=None, repr=False)

    @property
    def ratios(self) -> dict:
        """Largest value / bound per constraint name (class docstring), computed once on first use."""
        if self.given_ratios is None:
            rows, u, x = law_rows(self.path, self.constraints, self.law_breaks, self.law_coefficients)
            object.__setattr__(self, "given_ratios", ratios(rows, u, x, row_names(self.path, self.constraints)))
        return self.given_ratios

    @property
    def duration(self) -> float:
        """Total time [s]."""
        return float(self.law_breaks[-1] - self.law_breaks[0])

    def state(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Path position s, speed ṡ and acceleration s̈ at instants ``t`` (N,) [s]."""
        return law_eval(self.law_breaks, self.law_coefficients, np.atleast_1d(np.asarray(t, dtype=float)))

    def time_at(self, s: ArrayLike) -> np.ndarray:
        """First instants [s] at which the path reaches ``s`` (N,) (bisection on the monotone law)."""
        target = np.atleast_1d(np.asarray(s, dtype=float))
        lo = np.full(target.shape, self.law_breaks[0])
        hi = np.full(target.shape, self.law_breaks[-1])
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            below = self.state(mid)[0] < target
            lo = np.where(below, mid, lo)
            hi = np.where(below, hi, mid)
        return hi

    def tool_speed(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """tcp linear [m/s] and angular [rad/s] speed at instants ``t`` (needs ``path.robot``)."""
        s, sd, _ = self.state(t)
        _, d1, _ = self.path.tool_derivatives(s)
        return np.linalg.norm(d1[:, :3], axis=1) * sd, np.linalg.norm(d1[:, 3:], axis=1) * sd

    def as_dict(self) -> dict[str, Any]:
        """JSON-able summary (SI units)."""
        return {"duration_s": self.duration, "dilation": self.dilation, "smoothing_s": self.smoothing,
                "rounds": self.rounds, "grid_points": int(self.grid.size),
                "constraints": [c.name for c in self.constraints], "peak_ratios": dict(self.ratios)}


def _checked_constraints(constraints: Sequence[PathConstraint]) -> tuple:
    """``constraints`` as a tuple, or InvalidSettings when it is empty or holds something else."""
    cons = tuple(constraints)
    if not cons or not all(isinstance(c, PathConstraint) for c in cons):
        raise InvalidSettings("constraints must be a non-empty list of planning.path_constraints.PathConstraint objects")
    return cons


def _checked_settings(path: Any, jerk: Any, grid: int, kappa: float, start_speed: float, end_speed: float,
                      rtol: float, max_rounds: int) -> np.ndarray | None:
    """Refuse bad settings of :func:`time_optimal` (named errors); the jerk limit (n,) or None."""
    if not (hasattr(path, "sample") and hasattr(path, "breaks") and hasattr(path, "coefficients")):
        raise InvalidSettings(f"path must be a planning.JointPath, got {type(path).__name__}")
    count_setting(grid, "grid (intervals over the path)", 1, MAX_PATH_GRID)
    count_setting(max_rounds, "max_rounds (grid refinements)", 0, MAX_PATH_ROUNDS)
    for name, value in (("start_speed", start_speed), ("end_speed", end_speed)):
        if not (isinstance(value, (int, float, np.floating)) and np.isfinite(value) and value >= 0.0):
            raise InvalidSettings(f"{name} must be a finite ṡ >= 0, got {value!r}")
    if not (isinstance(rtol, (int, float)) and MIN_PATH_RTOL <= rtol < 0.5):
        raise SettingOutOfRange(f"rtol must be in [{MIN_PATH_RTOL:g}, 0.5), got {rtol!r}")
    if not (isinstance(kappa, (int, float)) and MIN_PATH_KAPPA <= kappa <= 1.0):
        raise SettingOutOfRange(f"kappa must be in [{MIN_PATH_KAPPA:g}, 1], got {kappa!r}")
    if jerk is None:
        return None
    try:
        jmax = check_limit(jerk, path.n_joints, "jerk limit [rad/s³ or m/s³]", required=True)  # in LIMIT_RANGE
    except Exception as exc:
        raise InvalidSettings(str(exc)) from None
    if start_speed or end_speed:
        raise InvalidSettings("a jerk limit is applied from rest to rest: start_speed and end_speed must be 0")
    return jmax


def _profiled_sections(path: Any, cons: tuple, grid: int, kappa: float, start_speed: float, end_speed: float,
                       rtol: float, max_rounds: int) -> list[tuple]:
    """Steps 1–4 on every section between stops: (s, x, u, f², rounds, {}) each (the reported ratios are
    those of the final law, :attr:`PathTiming.ratios`)."""
    sections = path.sections()
    L = path.length
    results = []
    for i, (a, b) in enumerate(sections):
        g = path_grid(path, a, b, L, grid, kappa)
        x0 = start_speed**2 if i == 0 else 0.0
        x1 = end_speed**2 if i == len(sections) - 1 else 0.0
        results.append(refined_section(path, cons, g, x0, x1, rtol, max_rounds, with_ratios=False))
    return results


def _smoothest_under_jerk(path: Any, cons: tuple, laws: list, traj: Trajectory,
                          jmax: np.ndarray) -> tuple[float, float, np.ndarray, np.ndarray]:
    """The bang–bang laws smoothed over each window of :data:`SMOOTHING_FACTORS` (module docstring, jerk),
    each slowed until every limit holds; the shortest as (window τ [s], its slow-down f, tb, C)."""
    tau0 = float(np.max(acceleration_jumps(traj) / jmax))
    best = None
    for factor in SMOOTHING_FACTORS:
        tau = tau0 * factor
        cand = [smoothed(t, c, tau) for t, c in laws]
        ctb, cC, ctraj = assemble(path, cand)
        g2 = law_check(path, cons, ctb, cC)
        peaked = Peaked(ctraj)
        fj = max(1.0, float(np.max(peaked.jerk / jmax)) ** (1.0 / 3.0), np.sqrt(g2),
                 max(c.exact_dilation(peaked) for c in cons))
        if best is None or ctraj.duration * fj < best[0]:
            best = (ctraj.duration * fj, tau, fj, ctb, cC)
    _, smoothing, fj, tb, C = best
    return smoothing, fj, tb, C


def _exact_dilation(cons: tuple, traj: Trajectory, jmax: np.ndarray | None) -> float:
    """The uniform slow-down the trajectory's exact joint peaks still need (1 when none)."""
    peaked = Peaked(traj)
    f_exact = max(c.exact_dilation(peaked) for c in cons)
    if jmax is not None:
        f_exact = max(f_exact, float(np.max(peaked.jerk / jmax)) ** (1.0 / 3.0))
    return f_exact


def _slowed(path: Any, tb: np.ndarray, C: np.ndarray, f: float) -> tuple[np.ndarray, np.ndarray, Trajectory]:
    """The law slowed uniformly by f and its trajectory composed again."""
    tb, C = scaled_law(tb, C, f)
    return tb, C, Trajectory(tb, compose_law(path, tb, C))


def time_optimal(path: JointPath, constraints: Sequence[PathConstraint], *, jerk: ArrayLike | None = None, grid: int = 100,
                 kappa: float = 0.02, start_speed: float = 0.0, end_speed: float = 0.0, rtol: float = 1e-3,
                 max_rounds: int = 8) -> PathTiming:
    """Time-optimal timing of ``path`` under ``constraints`` (module docstring).

    Args:
        path: a :class:`pinarms.planning.JointPath` (q(s) piecewise polynomial, with ``stops``).
        constraints: :class:`pinarms.planning.path_constraints.PathConstraint` objects, e.g.
            ``[JointVelocityConstraint(v), JointAccelerationConstraint(a), ToolSpeedConstraint(0.5)]``.
        jerk: joint jerk limit(s) [rad/s³ or m/s³] (scalar or per joint): a smoothed result
            (module docstring), only from rest to rest (``start_speed = end_speed = 0``).
        grid: about how many uniform grid intervals over the whole path (the path's breaks
            always belong to it); more is closer to the continuous optimum and slower.
        kappa: intervals are halved until the tangent q' changes by at most this fraction of
            its size across each (dense grid where the path bends, e.g. near a singularity).
        start_speed, end_speed: path speeds ṡ [path unit/s] at the start and the end (default at rest).
        rtol: relative excess of a row between grid points that triggers a refinement; the
            rest is removed by the dilation.
        max_rounds: grid refinements at most.

    Returns:
        :class:`PathTiming` (``.trajectory``, ``.duration``, ``.state(t)``, ``.tool_speed(t)``).

    Raises:
        InfeasibleProblem: the limits cannot be met along the path (names where).
        InvalidSettings: bad arguments.
    """
    cons = _checked_constraints(constraints)
    jmax = _checked_settings(path, jerk, grid, kappa, start_speed, end_speed, rtol, max_rounds)
    results = _profiled_sections(path, cons, grid, kappa, start_speed, end_speed, rtol, max_rounds)
    f2 = max(1.0, max(r[3] for r in results))
    laws = [bang_bang(g, x, u, f2) for g, x, u, _, _, _ in results]
    tb, C, traj = assemble(path, laws)
    smoothing = 0.0
    f = np.sqrt(f2)
    if jmax is not None:
        smoothing, fj, tb, C = _smoothest_under_jerk(path, cons, laws, traj, jmax)
        tb, C, traj = _slowed(path, tb, C, fj)
        f *= fj
    f_exact = _exact_dilation(cons, traj, jmax)
    if f_exact > 1.0 + 1e-12:  # between the check points (or past a rounding): slow once more, exactly
        tb, C, traj = _slowed(path, tb, C, f_exact)
        f *= f_exact
    grid_all = np.concatenate([r[0] for r in results])
    return PathTiming(path, cons, traj, tb, C, grid_all, float(f), float(smoothing), int(sum(r[4] for r in results)))


def time_scaled(path: JointPath, constraints: Sequence[PathConstraint], *, shape: str = "quintic",
                samples: int = 2001) -> PathTiming:
    """The path timed by a fixed rest-to-rest shape ``s(t) = a + L σ(t / T)``, T as short as the limits allow.

    The classic alternative to the time-optimal profile: a smooth law (``"quintic"``:
    ``σ = 10τ³ − 15τ⁴ + 6τ⁵``, zero velocity and acceleration at both ends; ``"cubic"``),
    the same shape on every section between stops. With ``u = L σ''/T²`` and
    ``x = L² σ'²/T²`` every row ``a u + b x`` scales as ``1/T²``, so the shortest T follows
    from the rows at ``samples`` instants of τ; the exact joint peaks of the composed
    trajectory then fix the last digits (:attr:`PathTiming.dilation`).

    Raises:
        InfeasibleProblem: a row's bounds exclude 0 (no T satisfies it).
        InvalidSettings: an unknown shape, bad arguments.
    """
    cons = _checked_constraints(constraints)
    if shape not in SHAPES:
        raise InvalidSettings(f"shape must be one of {sorted(SHAPES)}, got {shape!r}")
    count_setting(samples, "samples (instants of the time scaling)", 3, MAX_TIME_SCALED_SAMPLES)
    sig = np.array(SHAPES[shape])
    tau = np.linspace(0.0, 1.0, int(samples))
    laws, grids = [], []
    for a, b in path.sections():
        s, law = _shaped_section(path, cons, sig, tau, a, b)
        laws.append(law)
        grids.append(s)
    tb, C, traj = assemble(path, laws)
    f = max(c.exact_dilation(Peaked(traj)) for c in cons)
    if f > 1.0 + 1e-12:
        tb, C, traj = _slowed(path, tb, C, f)
    return PathTiming(path, cons, traj, tb, C, np.concatenate(grids), float(f), 0.0, 0)


def _shaped_section(path: Any, cons: tuple, sig: np.ndarray, tau: np.ndarray, a: float,
                    b: float) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]:
    """The section [a, b] under the shape σ (coefficients ``sig``) with the shortest T its rows allow:
    the positions s at the instants ``tau`` and the law (tb, C)."""
    d1 = np.polynomial.polynomial.polyval(tau, sig[1:] * np.arange(1, sig.size))
    d2 = np.polynomial.polynomial.polyval(tau, sig[2:] * np.arange(2, sig.size) * np.arange(1, sig.size - 1))
    L = b - a
    s = a + L * np.polynomial.polynomial.polyval(tau, sig)
    rows = PathRows.concatenate_points(rows_at_sets(path, cons, [(s[:1], "right"), (s[1:], "left")]))
    val = rows.values(L * d2, (L * d1) ** 2)  # a u + b x at T = 1; at T it is val / T²
    with np.errstate(divide="ignore", invalid="ignore"):
        up = np.where(val > 0.0, np.where(rows.hi > 0.0, val / rows.hi, np.where(np.isinf(rows.hi), 0.0, np.inf)), 0.0)
        dn = np.where(val < 0.0, np.where(rows.lo < 0.0, val / rows.lo, np.where(np.isinf(rows.lo), 0.0, np.inf)), 0.0)
    need = np.maximum(up, dn)
    if np.any(~np.isfinite(need)):
        raise InfeasibleProblem(f"a limit cannot be met at any speed on the section [{a:.6g}, {b:.6g}]")
    T = float(np.sqrt(need.max()))
    coef = L * sig / T ** np.arange(sig.size)
    coef[0] += a
    return s, (np.array([0.0, T]), coef[None])
