"""Time-optimal timing of a geometric path under a list of constraints: a ``Trajectory`` out.

:func:`time_optimal` takes a :class:`planning.JointPath` ``q(s)`` (a Cartesian line's
joint image, a joint spline, ...) and :mod:`planning.path_constraints` objects, and
returns a :class:`PathTiming` whose ``trajectory`` is a :class:`planning.Trajectory` like
every other (sampling, exact peaks, limit checks, sessions, plots, viewer).

1. **Sections.** The path is cut at its stops (tangent discontinuities): each section is
   timed from rest to rest (the path's ends may have given speeds ``ṡ``).
2. **Grid.** The path's own breaks, each piece cut in equal steps so that the whole path
   has about ``grid`` intervals, then intervals halved until the tangent ``q'`` changes by
   at most ``kappa`` (2 %) of its size across each (dense where the path bends).
3. **Profile.** :func:`optim.topp.topp_profile` (TOPP-RA, interpolation
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
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from pinarms.optim.caps import (MAX_PATH_GRID, MAX_PATH_GRID_POINTS, MAX_PATH_ROUNDS, MAX_TIME_SCALED_SAMPLES,
                               MIN_PATH_KAPPA, MIN_PATH_RTOL, count_setting)
from pinarms.optim.errors import InfeasibleProblem, InvalidSettings, SettingOutOfRange
from pinarms.optim.topp.profile import topp_profile
from pinarms.planning import Trajectory
from pinarms.optim.ga.problem import check_limit
from pinarms.planning.path_constraints import PathConstraint, PathRows, PathSamples
from pinarms.planning.extrema import normalised_pieces, piece_extrema
from pinarms.planning.trajectory import taylor_shift

__all__ = ["PathTiming", "time_optimal", "time_scaled", "SHAPES", "CHECK_FRACTIONS", "SMOOTHING_FACTORS"]

#: Where each grid interval is re-checked, as fractions of its length.
CHECK_FRACTIONS = np.array([0.25, 0.5, 0.75, 1.0])
#: Rest-to-rest shapes σ(τ) of :func:`time_scaled`, ascending coefficients in τ ∈ [0, 1]
#: (cubic: zero end velocity; quintic: zero end velocity and acceleration).
SHAPES = {"cubic": (0.0, 0.0, 3.0, -2.0), "quintic": (0.0, 0.0, 0.0, 10.0, -15.0, 6.0)}

#: Multiples of the first smoothing window tried under a jerk limit.
SMOOTHING_FACTORS = (1.0, 1.6, 2.5)


@dataclass(frozen=True, eq=False)
class PathTiming:
    """A timing of a path (see the module docstring).

    Attributes:
        path: the :class:`planning.JointPath` timed.
        constraints: the constraint objects used.
        trajectory: q(t), a :class:`planning.Trajectory` (q(s(t)) composed exactly).
        law_breaks: (P+1,) instants [s] of the pieces of the time law s(t).
        law_coefficients: (P, k+1) s(t) on each piece, ascending powers of the time since its
            start (k = 2: the time-optimal profile; k = 3: smoothed under a jerk limit).
        grid: the reachability grid (G,) [path unit], sections end to end (a stop appears twice).
        dilation: the uniform time dilation f >= 1 applied after the checks.
        smoothing: the averaging window τ [s] (0 without a jerk limit).
        rounds: grid refinements made.
        ratios: per constraint name, the largest value / bound of the dense check (<= 1; for
            speed limits the ratio of speeds, not of their squares).
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
    ratios: dict = field(default_factory=dict)

    @property
    def duration(self) -> float:
        """Total time [s]."""
        return float(self.law_breaks[-1] - self.law_breaks[0])

    def state(self, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Path position s, speed ṡ and acceleration s̈ at instants ``t`` (N,) [s]."""
        return _law_eval(self.law_breaks, self.law_coefficients, np.atleast_1d(np.asarray(t, dtype=float)))

    def time_at(self, s: Any) -> np.ndarray:
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

    def tool_speed(self, t: Any) -> tuple[np.ndarray, np.ndarray]:
        """tcp linear [m/s] and angular [rad/s] speed at instants ``t`` (needs ``path.robot``)."""
        s, sd, _ = self.state(t)
        _, d1, _ = self.path.tool_derivatives(s)
        return np.linalg.norm(d1[:, :3], axis=1) * sd, np.linalg.norm(d1[:, 3:], axis=1) * sd

    def as_dict(self) -> dict[str, Any]:
        """JSON-able summary (SI units)."""
        return {"duration_s": self.duration, "dilation": self.dilation, "smoothing_s": self.smoothing,
                "rounds": self.rounds, "grid_points": int(self.grid.size),
                "constraints": [c.name for c in self.constraints], "peak_ratios": dict(self.ratios)}


class _Peaked:
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

    def peaks(self) -> "_Peaked":
        return self


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
        g = _grown(np.sort(np.concatenate([g, 0.5 * (g[:-1] + g[1:])[bad]])), "kappa")
    return g


def _grown(grid: np.ndarray, what: str) -> np.ndarray:
    """``grid`` unless refining made it larger than the cap (then a named error, never a runaway)."""
    if grid.size > MAX_PATH_GRID_POINTS:
        raise SettingOutOfRange(f"the path grid grew past {MAX_PATH_GRID_POINTS:,} points while refining: give a "
                                f"larger {what} or a smaller grid")
    return grid


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


def _section(path: Any, constraints: Sequence[PathConstraint], grid: np.ndarray, x0: float, x1: float,
             rtol: float, max_rounds: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, int, dict]:
    """Profile of one section with the check-and-refine loop: (s, x, u, f², rounds, ratios)."""
    names: list[str] = []
    for c in constraints:
        names.extend([c.name] * c.rows(PathSamples.of(path, grid[:1])).a.shape[1])
    rounds = 0
    while True:
        rows = _rows(path, constraints, grid, "right")
        prof = topp_profile(rows.a, rows.b, rows.lo, rows.hi, grid, x0, x1)
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
        grid = _grown(np.sort(np.concatenate([grid, grid[:-1][bad] + 0.5 * h[bad]])), "rtol")
    return grid, prof.x, prof.u, float(need.max()), rounds, _ratios(crow, uc, xc, names)



# ------------------------------------------------------------------------ time laws
def _law_eval(tb: np.ndarray, C: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """s, ṡ, s̈ of the piecewise polynomial law (breaks tb, ascending coefficients C) at instants t."""
    tt = np.clip(t, tb[0], tb[-1])
    k = np.clip(np.searchsorted(tb, tt, side="right") - 1, 0, C.shape[0] - 1)
    tau = tt - tb[k]
    c = C[k]
    deg = C.shape[1] - 1
    out = []
    for r in range(3):
        acc = np.zeros_like(tau)
        for d in range(deg, r - 1, -1):
            fall = np.prod(np.arange(d, d - r, -1)) if r else 1.0
            acc = acc * tau + fall * c[:, d]
        out.append(acc)
    return out[0], out[1], out[2]


def _polyval(C: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Row-wise values of ascending coefficients C (P, k+1) at x (P,)."""
    out = np.zeros(C.shape[0])
    for d in range(C.shape[1] - 1, -1, -1):
        out = out * x + C[:, d]
    return out


def _bang_bang(grid: np.ndarray, x: np.ndarray, u: np.ndarray, f2: float) -> tuple[np.ndarray, np.ndarray]:
    """The reachability profile as a law: one quadratic per grid interval, dilated by f = √f2."""
    sd = np.sqrt(np.maximum(x, 0.0) / f2)
    uu = u / f2
    dt = 2.0 * np.diff(grid) / (sd[:-1] + sd[1:])
    tb = np.concatenate([[0.0], np.cumsum(dt)])
    return tb, np.stack([grid[:-1], sd[:-1], 0.5 * uu], axis=1)


def _polyint(C: np.ndarray) -> np.ndarray:
    """Antiderivatives (zero at the piece start) of ascending coefficients (P, k+1) -> (P, k+2)."""
    out = np.zeros((C.shape[0], C.shape[1] + 1))
    out[:, 1:] = C / np.arange(1, C.shape[1] + 1)
    return out


def _smoothed(tb: np.ndarray, C: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """The law averaged over a trailing window τ: ``s_τ(t) = (1/τ) ∫_{t−τ}^{t} s`` on [t0, t_end + τ].

    (Module docstring, jerk.) The law is extended at rest before its start and after its end.
    """
    a, b = C[0, 0], _law_eval(tb, C, tb[-1:])[0][0]
    # the law at rest before its start and after its end, one piece each (length τ)
    eb = np.concatenate([[tb[0] - tau], tb, [tb[-1] + tau]])
    width = C.shape[1]
    EC = np.zeros((C.shape[0] + 2, width))
    EC[0, 0], EC[1:-1], EC[-1, 0] = a, C, b
    S = _polyint(EC)  # (P+2, k+2)
    lengths = np.diff(eb)
    ends = _polyval(S, lengths)
    S[:, 0] = np.concatenate([[0.0], np.cumsum(ends)[:-1]])  # continuous antiderivative
    new = np.unique(np.concatenate([tb, tb + tau]))
    new = new[(new >= tb[0]) & (new <= tb[-1] + tau)]
    out = np.zeros((new.size - 1, S.shape[1]))
    for sign, shift in ((1.0, 0.0), (-1.0, tau)):
        start = new[:-1] - shift
        k = np.clip(np.searchsorted(eb, start + 1e-15 * max(1.0, abs(tb[-1])), side="right") - 1, 0, S.shape[0] - 1)
        local = taylor_shift(S[k][:, :, None], start - eb[k])[:, :, 0]
        out += sign * local
    return new, out / tau


def _split(tb: np.ndarray, C: np.ndarray, s_breaks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cut law pieces where s(t) crosses a path break, so that each piece lies in one path piece."""
    s0 = C[:, 0]
    s1 = _polyval(C, np.diff(tb))
    cuts_t, cuts_k = [], []
    tol = 1e-12 * max(1.0, float(np.abs(s_breaks).max()) if s_breaks.size else 1.0)
    for sb in s_breaks:
        inside = np.flatnonzero((s0 < sb - tol) & (s1 > sb + tol))
        for i in inside:  # a monotone law crosses once: bisection
            lo, hi = 0.0, tb[i + 1] - tb[i]
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                if np.polyval(C[i, ::-1], mid) < sb:
                    lo = mid
                else:
                    hi = mid
            cuts_t.append(tb[i] + 0.5 * (lo + hi))
            cuts_k.append(i)
    if not cuts_t:
        return tb, C
    new = np.sort(np.concatenate([tb, cuts_t]))
    k = np.clip(np.searchsorted(tb, new[:-1], side="right") - 1, 0, C.shape[0] - 1)
    out = taylor_shift(C[k][:, :, None], new[:-1] - tb[k])[:, :, 0]
    return new, out


def _compose_law(path: Any, tb: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Coefficients (P, D·k+1, n) in the local time of q(s(t)) on each law piece (module docstring, step 5)."""
    breaks, Q = np.asarray(path.breaks), path.coefficients  # (K, D+1, n)
    h = np.diff(tb)
    mid = _polyval(C, 0.5 * h)
    k = np.clip(np.searchsorted(breaks, mid, side="right") - 1, 0, Q.shape[0] - 1)
    D = Q.shape[1] - 1
    deg = C.shape[1] - 1
    width = D * deg + 1
    sigma = C.copy()
    sigma[:, 0] -= breaks[k]
    P = C.shape[0]
    power = np.zeros((P, width))
    power[:, 0] = 1.0
    out = Q[k, 0][:, None, :] * power[:, :, None]
    for d in range(1, D + 1):
        nxt = np.zeros((P, width))
        for j in range(deg + 1):
            nxt[:, j:] += sigma[:, j : j + 1] * power[:, : width - j]
        power = nxt
        out = out + Q[k, d][:, None, :] * power[:, :, None]
    return out


def _law_rows(path: Any, constraints: Sequence[PathConstraint], tb: np.ndarray,
              C: np.ndarray) -> tuple[PathRows, np.ndarray, np.ndarray]:
    """Rows of the constraints at 0, 1/4 … 1 of every law piece, with the law's (u, x) there.

    A piece's start is evaluated on the path piece that starts there, the other points on the
    one that ends there (what the law piece lies on; they differ at a stop).
    """
    h = np.diff(tb)
    parts = []
    for frac, side in ((np.array([0.0]), "right"), (np.concatenate([CHECK_FRACTIONS[:-1], [1.0 - 1e-9]]), "left")):
        t = (tb[:-1, None] + h[:, None] * frac).reshape(-1)
        s, sd, sdd = _law_eval(tb, C, t)
        parts.append((_rows(path, constraints, np.clip(s, 0.0, path.length), side), sdd, sd * sd))
    return PathRows.concatenate_points([p[0] for p in parts]), np.concatenate([p[1] for p in parts]), \
        np.concatenate([p[2] for p in parts])


def _law_check(path: Any, constraints: Sequence[PathConstraint], tb: np.ndarray, C: np.ndarray) -> float:
    """f² the path constraints need on a law (dense rows)."""
    rows, u, x = _law_rows(path, constraints, tb, C)
    need = _dilation_needed(rows, u, x)
    if np.any(~np.isfinite(need)):
        raise InfeasibleProblem("a limit cannot be met at any speed on the smoothed timing (its bounds exclude 0)")
    return float(need.max())


def _assemble(path: Any, laws: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray, Trajectory]:
    """Sections' laws end to end (each cut at the path breaks) and the composed trajectory."""
    tbs, Cs, offset = [], [], 0.0
    width = max(C.shape[1] for _, C in laws)
    for tb, C in laws:
        tb, C = _split(tb, C, np.asarray(path.breaks)[1:-1])
        pad = np.zeros((C.shape[0], width))
        pad[:, : C.shape[1]] = C
        tbs.append(tb - tb[0] + offset)
        Cs.append(pad)
        offset = float(tbs[-1][-1])
    tb = np.concatenate([tbs[0]] + [t[1:] for t in tbs[1:]])
    C = np.concatenate(Cs)
    traj = Trajectory(tb, _compose_law(path, tb, C))
    return tb, C, traj


def _scaled_law(tb: np.ndarray, C: np.ndarray, f: float) -> tuple[np.ndarray, np.ndarray]:
    """The law slowed uniformly by f: t -> f t."""
    return tb[0] + (tb - tb[0]) * f, C / f ** np.arange(C.shape[1])


def _acceleration_jumps(traj: Trajectory) -> np.ndarray:
    """Largest jump (n,) of each joint's acceleration at the trajectory's breaks (from and to rest included)."""
    c = traj.coefficients
    h = traj.segment_durations
    k = np.arange(2, c.shape[1])
    start = 2.0 * c[:, 2] if c.shape[1] > 2 else np.zeros((c.shape[0], c.shape[2]))
    end = np.einsum("mkn,mk->mn", c[:, 2:], (k * (k - 1))[None] * h[:, None] ** (k - 2)[None]) if c.shape[1] > 2 \
        else np.zeros_like(start)
    jumps = np.concatenate([start[:1], start[1:] - end[:-1], -end[-1:]])
    return np.abs(jumps).max(axis=0)


def time_optimal(path: Any, constraints: Sequence[PathConstraint], *, jerk: Any = None, grid: int = 100,
                 kappa: float = 0.02, start_speed: float = 0.0, end_speed: float = 0.0, rtol: float = 1e-3,
                 max_rounds: int = 8) -> PathTiming:
    """Time-optimal timing of ``path`` under ``constraints`` (module docstring).

    Args:
        path: a :class:`planning.JointPath` (q(s) piecewise polynomial, with ``stops``).
        constraints: :class:`planning.path_constraints.PathConstraint` objects, e.g.
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
    cons = tuple(constraints)
    if not cons or not all(isinstance(c, PathConstraint) for c in cons):
        raise InvalidSettings("constraints must be a non-empty list of planning.path_constraints.PathConstraint objects")
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
    jmax = None
    if jerk is not None:
        try:
            jmax = check_limit(jerk, path.n_joints, "jerk limit [rad/s³ or m/s³]", required=True)  # in LIMIT_RANGE
        except Exception as exc:
            raise InvalidSettings(str(exc)) from None
        if start_speed or end_speed:
            raise InvalidSettings("a jerk limit is applied from rest to rest: start_speed and end_speed must be 0")
    sections = path.sections()
    L = path.length
    results = []
    for i, (a, b) in enumerate(sections):
        g = _grid(path, a, b, L, grid, kappa)
        x0 = start_speed**2 if i == 0 else 0.0
        x1 = end_speed**2 if i == len(sections) - 1 else 0.0
        results.append(_section(path, cons, g, x0, x1, rtol, max_rounds))
    f2 = max(1.0, max(r[3] for r in results))
    laws = [_bang_bang(g, x, u, f2) for g, x, u, _, _, _ in results]
    tb, C, traj = _assemble(path, laws)
    smoothing = 0.0
    f = np.sqrt(f2)
    if jmax is not None:
        tau0 = float(np.max(_acceleration_jumps(traj) / jmax))
        best = None
        for factor in SMOOTHING_FACTORS:
            tau = tau0 * factor
            cand = [_smoothed(t, c, tau) for t, c in laws]
            ctb, cC, ctraj = _assemble(path, cand)
            g2 = _law_check(path, cons, ctb, cC)
            peaked = _Peaked(ctraj)
            fj = max(1.0, float(np.max(peaked.jerk / jmax)) ** (1.0 / 3.0), np.sqrt(g2),
                     max(c.exact_dilation(peaked) for c in cons))
            if best is None or ctraj.duration * fj < best[0]:
                best = (ctraj.duration * fj, tau, fj, ctb, cC)
        _, smoothing, fj, tb, C = best
        tb, C = _scaled_law(tb, C, fj)
        traj = Trajectory(tb, _compose_law(path, tb, C))
        f *= fj
    peaked = _Peaked(traj)
    f_exact = max(c.exact_dilation(peaked) for c in cons)
    if jmax is not None:
        f_exact = max(f_exact, float(np.max(peaked.jerk / jmax)) ** (1.0 / 3.0))
    if f_exact > 1.0 + 1e-12:  # between the check points (or past a rounding): slow once more, exactly
        tb, C = _scaled_law(tb, C, f_exact)
        traj = Trajectory(tb, _compose_law(path, tb, C))
        f *= f_exact
    names = [c.name for c in cons for _ in range(c.rows(PathSamples.of(path, [0.0])).a.shape[1])]
    rows, u, x = _law_rows(path, cons, tb, C)
    ratios = _ratios(rows, u, x, names)
    grid_all = np.concatenate([r[0] for r in results])
    return PathTiming(path, cons, traj, tb, C, grid_all, float(f), float(smoothing),
                      int(sum(r[4] for r in results)), ratios)


def time_scaled(path: Any, constraints: Sequence[PathConstraint], *, shape: str = "quintic",
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
    cons = tuple(constraints)
    if not cons or not all(isinstance(c, PathConstraint) for c in cons):
        raise InvalidSettings("constraints must be a non-empty list of planning.path_constraints.PathConstraint objects")
    if shape not in SHAPES:
        raise InvalidSettings(f"shape must be one of {sorted(SHAPES)}, got {shape!r}")
    count_setting(samples, "samples (instants of the time scaling)", 3, MAX_TIME_SCALED_SAMPLES)
    sig = np.array(SHAPES[shape])
    tau = np.linspace(0.0, 1.0, int(samples))
    d1 = np.polynomial.polynomial.polyval(tau, sig[1:] * np.arange(1, sig.size))
    d2 = np.polynomial.polynomial.polyval(tau, sig[2:] * np.arange(2, sig.size) * np.arange(1, sig.size - 1))
    laws, grids = [], []
    for a, b in path.sections():
        L = b - a
        s = a + L * np.polynomial.polynomial.polyval(tau, sig)
        rows = PathRows.concatenate_points([_rows(path, cons, s[:1], "right"), _rows(path, cons, s[1:], "left")])
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
        laws.append((np.array([0.0, T]), coef[None]))
        grids.append(s)
    tb, C, traj = _assemble(path, laws)
    peaked = _Peaked(traj)
    f = max(c.exact_dilation(peaked) for c in cons)
    if f > 1.0 + 1e-12:
        tb, C = _scaled_law(tb, C, f)
        traj = Trajectory(tb, _compose_law(path, tb, C))
    names = [c.name for c in cons for _ in range(c.rows(PathSamples.of(path, [0.0])).a.shape[1])]
    rows, u, x = _law_rows(path, cons, tb, C)
    return PathTiming(path, cons, traj, tb, C, np.concatenate(grids), float(f), 0.0, 0, _ratios(rows, u, x, names))
