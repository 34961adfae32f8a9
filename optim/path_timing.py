"""Time-optimal timing of a geometric path under a list of constraints: a ``Trajectory`` out.

:func:`time_optimal` takes a :class:`planning.JointPath` ``q(s)`` (a Cartesian line's
joint image, a joint spline, ...) and :mod:`planning.path_constraints` objects, and
returns a :class:`PathTiming` whose ``trajectory`` is a :class:`planning.Trajectory` like
every other (sampling, exact peaks, limit checks, sessions, plots, viewer).

1. **Sections.** The path is cut at its stops (tangent discontinuities): each section is
   timed from rest to rest (the path's ends may have given speeds ``ṡ``).
2. **Grid.** The path's own breaks, each piece cut in equal steps so that the whole path
   has about ``grid`` intervals (at least one per piece).
3. **Profile.** :func:`optim.reachability.reachability_profile` (TOPP-RA) on the rows of
   all constraints at the grid points: ``ṡ²`` at the grid points, constant ``s̈`` between.
4. **Check and refine.** The limits hold at the grid points; between them the rows are
   evaluated at 1/4, 1/2, 3/4 and the end of every interval with the profile's (u, x).
   Intervals where a row exceeds its bound by more than ``rtol`` (relative, in the
   squared-speed sense) are split in two and the profile is recomputed (``max_rounds``).
   What remains (< ``rtol``) is removed by a uniform **time dilation** ``f`` (ṡ → ṡ/f,
   s̈ → s̈/f²), taken from the dense check and, for joint limits, from the trajectory's
   *exact* peaks: the returned trajectory satisfies every joint limit exactly (f is
   reported; 1 + rtol/2 at most from the dense check).
5. **Trajectory, exactly.** On each interval ``s(t) = s_i + ṡ_i τ + s̈_i τ²/2`` and the path
   piece is a polynomial of degree D in s, so ``q(t) = q(s(t))`` is a polynomial of degree
   2D in τ: it is composed exactly (no refit), and the Trajectory's peaks and checks are
   those of the timed path itself.

The result is the time-optimal bang–bang profile: joint accelerations jump where the
active limit changes (jerk is not limited; see :func:`time_optimal`'s ``jerk``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from pinarms.optim.errors import InfeasibleProblem, InvalidSettings
from pinarms.optim.reachability import feasible_states, reachability_profile
from pinarms.planning import Trajectory
from pinarms.planning.path_constraints import PathConstraint, PathRows, PathSamples

__all__ = ["PathTiming", "time_optimal", "CHECK_FRACTIONS"]

#: Where each grid interval is re-checked, as fractions of its length.
CHECK_FRACTIONS = np.array([0.25, 0.5, 0.75, 1.0])


@dataclass(frozen=True, eq=False)
class PathTiming:
    """A time-optimal timing of a path (see the module docstring).

    Attributes:
        path: the :class:`planning.JointPath` timed.
        constraints: the constraint objects used.
        trajectory: q(t), a :class:`planning.Trajectory` (degree 2D pieces, one per grid interval).
        s: grid (G,) [path unit], every section's grid end to end (a stop appears twice).
        sd: ṡ at the grid points (G,), after dilation.
        sdd: s̈ on each grid interval (G-1,) (0 on the zero-length joins at stops).
        t: instants (G,) [s] at the grid points.
        dilation: the uniform time dilation f >= 1 applied after the check.
        rounds: grid refinements made.
        ratios: per constraint name, the largest value / bound found by the dense check (<= 1).
    """

    path: Any = field(repr=False)
    constraints: tuple = field(repr=False)
    trajectory: Trajectory = field(repr=False)
    s: np.ndarray = field(repr=False)
    sd: np.ndarray = field(repr=False)
    sdd: np.ndarray = field(repr=False)
    t: np.ndarray = field(repr=False)
    dilation: float = 1.0
    rounds: int = 0
    ratios: dict = field(default_factory=dict)

    @property
    def duration(self) -> float:
        """Total time [s]."""
        return float(self.t[-1])

    def state(self, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Path position s, speed ṡ and acceleration s̈ at instants ``t`` (N,) [s]."""
        tt = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        k = np.clip(np.searchsorted(self.t, tt, side="right") - 1, 0, self.t.size - 2)
        tau = tt - self.t[k]
        u = self.sdd[k]
        return self.s[k] + self.sd[k] * tau + 0.5 * u * tau * tau, self.sd[k] + u * tau, u

    def tool_speed(self, t: Any) -> tuple[np.ndarray, np.ndarray]:
        """tcp linear [m/s] and angular [rad/s] speed at instants ``t`` (needs ``path.robot``)."""
        s, sd, _ = self.state(t)
        _, d1, _ = self.path.tool_derivatives(s)
        return np.linalg.norm(d1[:, :3], axis=1) * sd, np.linalg.norm(d1[:, 3:], axis=1) * sd

    def as_dict(self) -> dict[str, Any]:
        """JSON-able summary (SI units)."""
        return {"duration_s": self.duration, "dilation": self.dilation, "rounds": self.rounds,
                "grid_points": int(self.s.size), "constraints": [c.name for c in self.constraints],
                "peak_ratios": dict(self.ratios)}


class _Peaked:
    """A trajectory's joint count and exact peaks, computed once for every constraint's exact check."""

    def __init__(self, trajectory: Trajectory) -> None:
        self.n_joints = trajectory.n_joints
        self._trajectory = trajectory
        self._peaks = None

    def peaks(self):
        if self._peaks is None:
            self._peaks = self._trajectory.peaks()
        return self._peaks


def _grid(path: Any, a: float, b: float, total: float, n: int, kappa: float) -> np.ndarray:
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
        g = np.sort(np.concatenate([g, 0.5 * (g[:-1] + g[1:])[bad]]))
    return g


def _rows(path: Any, constraints: Sequence[PathConstraint], s: np.ndarray, side: str) -> PathRows:
    samples = PathSamples.of(path, s, side)
    return PathRows.concatenate([c.rows(samples) for c in constraints])


def _dilation_needed(rows: PathRows, u: np.ndarray, x: np.ndarray) -> np.ndarray:
    """f² (N, m) each row needs (1 where satisfied); inf where no dilation helps (a bound excluding 0)."""
    val = rows.values(u, x)
    with np.errstate(divide="ignore", invalid="ignore"):
        over = np.where(val > rows.hi, np.where(rows.hi > 0.0, val / rows.hi, np.inf), 1.0)
        under = np.where(val < rows.lo, np.where(rows.lo < 0.0, val / rows.lo, np.inf), 1.0)
    return np.maximum(np.maximum(over, under), 1.0)


def _ratios(rows: PathRows, u: np.ndarray, x: np.ndarray, names: list[str]) -> dict[str, float]:
    val = rows.values(u, x)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.maximum(np.where(rows.hi > 0.0, val / rows.hi, 0.0), np.where(rows.lo < 0.0, val / rows.lo, 0.0))
    out: dict[str, float] = {}
    for j, name in enumerate(names):
        out[name] = max(out.get(name, 0.0), float(np.max(r[:, j])) if r.shape[0] else 0.0)
    return out


def _section(path: Any, constraints: Sequence[PathConstraint], grid: np.ndarray, x0: float, x1: float,
             rtol: float, max_rounds: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, int, dict]:
    """Profile of one section with the check-and-refine loop: (s, x, u, f², rounds, ratios)."""
    names: list[str] = []
    for c in constraints:
        names.extend([c.name] * c.rows(PathSamples.of(path, grid[:1])).a.shape[1])
    rounds = 0
    while True:
        rows = _rows(path, constraints, grid, "right")
        prof = reachability_profile(rows.a, rows.b, rows.lo, rows.hi, grid, x0, x1)
        h = np.diff(grid)
        sc = (grid[:-1, None] + h[:, None] * CHECK_FRACTIONS).reshape(-1)
        uc = np.repeat(prof.u, CHECK_FRACTIONS.size)
        xc = (prof.x[:-1, None] + 2.0 * prof.u[:, None] * h[:, None] * CHECK_FRACTIONS).reshape(-1)
        xc = np.maximum(xc, 0.0)
        crow = _rows(path, constraints, sc, "left")
        need = _dilation_needed(crow, uc, xc).reshape(h.size, -1).max(axis=1)
        if np.any(~np.isfinite(need)):
            k = int(np.argmax(~np.isfinite(need)))
            raise InfeasibleProblem(f"at s = {grid[k]:.6g} a limit cannot be met at any speed (its bounds exclude 0, "
                                    "e.g. gravity beyond a torque limit)")
        bad = need > 1.0 + rtol
        if not bad.any() or rounds >= max_rounds:
            break
        rounds += 1
        grid = np.sort(np.concatenate([grid, grid[:-1][bad] + 0.5 * h[bad]]))
    return grid, prof.x, prof.u, float(need.max()), rounds, _ratios(crow, uc, xc, names)


def _compose(path: Any, s: np.ndarray, sd: np.ndarray, u: np.ndarray, dt: np.ndarray) -> np.ndarray:
    """Coefficients (M, 2D+1, n) in τ of q(s(t)) on each interval (module docstring, step 5)."""
    breaks, C = path.breaks, path.coefficients  # (K, D+1, n)
    mid = 0.5 * (s[:-1] + s[1:])
    k = np.clip(np.searchsorted(breaks, mid, side="right") - 1, 0, C.shape[0] - 1)
    D = C.shape[1] - 1
    M = s.size - 1
    quad = np.stack([s[:-1] - breaks[k], sd[:-1], 0.5 * u], axis=1)  # σ(τ) ascending, (M, 3)
    width = 2 * D + 1
    power = np.zeros((M, width))
    power[:, 0] = 1.0
    out = C[k, 0][:, None, :] * power[:, :, None]
    for d in range(1, D + 1):
        nxt = np.zeros((M, width))
        for j in range(3):
            nxt[:, j:] += quad[:, j : j + 1] * power[:, : width - j]
        power = nxt
        out = out + C[k, d][:, None, :] * power[:, :, None]
    return out


def time_optimal(path: Any, constraints: Sequence[PathConstraint], *, grid: int = 100, kappa: float = 0.02,
                 start_speed: float = 0.0, end_speed: float = 0.0, rtol: float = 1e-3,
                 max_rounds: int = 8) -> PathTiming:
    """Time-optimal timing of ``path`` under ``constraints`` (module docstring).

    Args:
        path: a :class:`planning.JointPath` (q(s) piecewise polynomial, with ``stops``).
        constraints: :class:`planning.path_constraints.PathConstraint` objects, e.g.
            ``[JointVelocityConstraint(v), JointAccelerationConstraint(a), ToolSpeedConstraint(0.5)]``.
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
    cons = tuple(constraints)
    if not cons or not all(isinstance(c, PathConstraint) for c in cons):
        raise InvalidSettings("constraints must be a non-empty list of planning.path_constraints.PathConstraint objects")
    if not (hasattr(path, "sample") and hasattr(path, "breaks") and hasattr(path, "coefficients")):
        raise InvalidSettings(f"path must be a planning.JointPath, got {type(path).__name__}")
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or grid < 1:
        raise InvalidSettings(f"grid must be a positive number of intervals, got {grid!r}")
    for name, value in (("start_speed", start_speed), ("end_speed", end_speed)):
        if not (isinstance(value, (int, float, np.floating)) and np.isfinite(value) and value >= 0.0):
            raise InvalidSettings(f"{name} must be a finite ṡ >= 0, got {value!r}")
    if not (isinstance(rtol, (int, float)) and 0.0 < rtol < 0.5):
        raise InvalidSettings(f"rtol must be in (0, 0.5), got {rtol!r}")
    sections = path.sections()
    L = path.length
    results = []
    if not (isinstance(kappa, (int, float)) and 0.0 < kappa <= 1.0):
        raise InvalidSettings(f"kappa must be in (0, 1], got {kappa!r}")
    for i, (a, b) in enumerate(sections):
        g = _grid(path, a, b, L, grid, kappa)
        x0 = start_speed**2 if i == 0 else 0.0
        x1 = end_speed**2 if i == len(sections) - 1 else 0.0
        results.append(_section(path, cons, g, x0, x1, rtol, max_rounds))
    f2 = max(1.0, max(r[3] for r in results))
    s_all, sd_all, u_all, dt_all, coefs = [], [], [], [], []
    for g, x, u, _, _, _ in results:
        sd = np.sqrt(np.maximum(x, 0.0) / f2)
        uu = u / f2
        dt = 2.0 * np.diff(g) / (sd[:-1] + sd[1:])
        s_all.append(g), sd_all.append(sd), u_all.append(uu), dt_all.append(dt)
        coefs.append(_compose(path, g, sd, uu, dt))
    breaks = np.concatenate([[0.0], np.cumsum(np.concatenate(dt_all))])
    traj = Trajectory(breaks, np.concatenate(coefs, axis=0))
    f_exact = max(c.exact_dilation(_Peaked(traj)) for c in cons)
    if f_exact > 1.0 + 1e-12:  # between the check points: scale once more, exactly
        f2 *= f_exact**2
        traj = traj.scaled(f_exact)
        traj = Trajectory(traj.knot_times, traj.coefficients)
        sd_all = [v / f_exact for v in sd_all]
        u_all = [v / f_exact**2 for v in u_all]
    # join the sections: a stop is a repeated grid point (zero speed, zero-length join)
    scale = f_exact if f_exact > 1.0 + 1e-12 else 1.0
    t_parts, offset = [], 0.0
    for dt in dt_all:
        t_parts.append(offset + np.concatenate([[0.0], np.cumsum(dt * scale)]))
        offset = float(t_parts[-1][-1])
    s = np.concatenate(s_all)
    sd = np.concatenate(sd_all)
    sdd = np.concatenate([np.concatenate([uu, [0.0]]) for uu in u_all])[:-1]
    t_grid = np.concatenate(t_parts)
    ratios: dict[str, float] = {}
    for r in results:
        for k, v in r[5].items():
            ratios[k] = max(ratios.get(k, 0.0), v / f2)
    return PathTiming(path, cons, traj, s, sd, sdd, t_grid, float(np.sqrt(f2)), int(sum(r[4] for r in results)), ratios)
