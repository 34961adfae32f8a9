"""The clearance along a planned motion (:class:`ClearanceProfile`) and the shortcutters a plan names.

Distances in m (the world frame), joint coordinates in rad or m, times in s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from pinarms.planning import Trajectory
from pinarms.robots.cell.ladder import interval_bound
from pinarms.robots.cell.speed_bound import travel_stops

if TYPE_CHECKING:
    from pinarms.optim.motion.checker import MotionChecker
    from pinarms.robots.cell import Cell

__all__ = ["ClearanceProfile", "SIMPLIFIER", "FAST_SIMPLIFIER", "clearance_profile", "cell_trajectory",
           "pair_speeds", "sample_times"]

#: What shortcuts a path found by OMPL (said in every result).
SIMPLIFIER = "OMPL PathSimplifier (reduceVertices, partialShortcutPath, ropeShortcutPath), edges proven by pinarms"
#: What shortcuts a path found by the compiled search (:mod:`.fast`).
FAST_SIMPLIFIER = "random shortcuts then vertex removal, edges proven on the sphere cover (compiled)"


@dataclass(frozen=True, eq=False)
class ClearanceProfile:
    """coal's exact distances along a timed motion, dense where they come close (:func:`clearance_profile`).

    Attributes:
        times: ``(M,)`` [s]; ``environment``: ``(M,)`` smallest distance [m] between a planned
            arm and a fixture or another arm; ``environment_pair``: its pair index into
            ``pairs`` (−1 when there is none); ``own``: ``(M,)`` smallest distance between
            two links of one planned arm [m].
        pairs: the pairs checked (those involving a planned arm); ``required``: the margin [m].

    The smallest distance of the whole motion lies at most ``required / 2`` below
    ``min_environment`` (and ``min_own``): the samples are placed to prove it.

    ``viz.plot_clearance(path, profile)`` draws it over time.
    """

    times: np.ndarray
    environment: np.ndarray
    environment_pair: np.ndarray
    own: np.ndarray
    pairs: tuple
    required: float = 0.0

    # what viz.plot_clearance reads: viz.plot_clearance("clearance.png", plan.clearance)
    @property
    def clearance(self) -> np.ndarray:
        """``environment`` (the name the clearance plot reads)."""
        return self.environment

    @property
    def exact(self) -> np.ndarray:
        """Every sample is an exact distance (coal)."""
        return np.ones(self.times.size, dtype=bool)

    @property
    def min_clearance_pair(self) -> str | None:
        """``"body_a – body_b"`` of the closest pair to the environment."""
        pair = self.min_pair
        return None if pair is None else f"{pair[0]} – {pair[1]}"

    @property
    def min_environment(self) -> float:
        """Smallest distance to a fixture or another arm over the motion [m]."""
        return float(np.min(self.environment)) if self.environment.size else float("inf")

    @property
    def min_time(self) -> float:
        """When it occurs [s]."""
        return float(self.times[int(np.argmin(self.environment))]) if self.environment.size else 0.0

    @property
    def min_pair(self) -> tuple[str, str] | None:
        """``(body_a, body_b)`` of that pair."""
        if not self.environment.size:
            return None
        k = int(self.environment_pair[int(np.argmin(self.environment))])
        return None if k < 0 else self.pairs[k].bodies

    @property
    def min_own(self) -> float:
        """Smallest distance between two links of one planned arm [m]."""
        return float(np.min(self.own)) if self.own.size else float("inf")

    @property
    def curves(self) -> dict[str, np.ndarray]:
        """What the clearance plot draws: ``{"<arm> ↔ fixtures, other arms": environment, "<arm>: own links": own}``
        (a curve without any pair left out)."""
        arms = " + ".join(dict.fromkeys(p.owner_a for p in self.pairs if p.kind == "self")) or "planned arm"
        out = {f"{arms} ↔ fixtures, other arms": self.environment, f"{arms}: own links": self.own}
        return {k: v for k, v in out.items() if v.size and np.isfinite(v).any()}

    @property
    def curve_pairs(self) -> dict[str, str]:
        """``{curve: "body_a ↔ body_b"}``: the environment curve's closest pair (what the plot names)."""
        name = next(iter(self.curves), None)
        return {} if name is None or self.min_pair is None else {name: f"{self.min_pair[0]} ↔ {self.min_pair[1]}"}


def cell_trajectory(cell: Cell, arms: Sequence[str], trajectory: Trajectory, hold: np.ndarray) -> Trajectory:
    """A trajectory of the planned arms' joints as one of the whole cell (the other arms held at ``hold``)."""
    C = trajectory.coefficients
    out = np.zeros((C.shape[0], C.shape[1], cell.nq))
    out[:, 0, :] = hold
    cols = np.concatenate([np.arange(cell.nq)[cell.arm(a).q_slice] for a in arms])
    out[:, :, cols] = C
    return Trajectory(trajectory.knot_times, out)


#: Travel between two samples of the first pass of :func:`clearance_profile`, in margins.
COARSE = 8.0
#: Most halvings of an interval of the first pass (each halves its time; an interval is closed at
#: the latest once its time times the fastest pair's speed bound is at most the margin).
MAX_HALVINGS = 30


def clearance_profile(checker: MotionChecker, trajectory: Trajectory, *, samples: int | None = None) -> ClearanceProfile:
    """Exact distances (coal) along ``trajectory`` (planned arms' joints; time last for none).

    A first pass samples every :data:`COARSE` margins of *travel* (:func:`sample_times`: how
    far any point of the planned arms can move, from the trajectory's exact speeds and
    acceleration peaks). Each pair's distance changes at most at its own speed bound on each
    interval (only the joints between its two bodies count, each at its larger end speed plus
    its acceleration peak's share, :func:`_interval_speeds`), so between two samples it stays
    at least ``(d_a + d_b − v_k Δt) / 2``
    (``d`` its distance or a lower bound of it at the samples); an interval where that could
    fall more than ``margin / 2`` below the smallest sampled distance (of the environment, or
    of the own links) is halved, level by level. So the smallest distance of the motion lies
    at most ``margin / 2`` below the reported minimum (as with a sample every margin of
    travel), and the samples are dense only where the distance comes close. Each sample's
    smallest distances are exact (:class:`_Distances`). ``samples``: that many uniform
    intervals in time instead (no halving).
    """
    peaks = np.abs(np.asarray(trajectory.peaks().velocity, dtype=float))
    dist = _Distances(checker, peaks)
    if samples:
        t = np.linspace(trajectory.start_time, trajectory.end_time, int(samples) + 1)
        env, env_k, own = dist.at(trajectory, t)[:3]
        return ClearanceProfile(t, env, env_k, own, checker.pairs, checker.margin)
    t = sample_times(trajectory, checker.levers, COARSE * checker.margin, float(checker.moving_speed))
    env, env_k, own, bounds, rates = dist.at(trajectory, t)
    acc = np.abs(np.asarray(trajectory.peaks().acceleration, dtype=float))
    for _ in range(MAX_HALVINGS):
        open_ = _open_intervals(t, bounds, _interval_speeds(dist, rates, peaks, acc, np.diff(t)), dist, env, own,
                                checker.margin / 2.0)
        if not open_.any():
            break
        mid = 0.5 * (t[:-1][open_] + t[1:][open_])
        parts = (t, env, env_k, own, bounds, rates), (mid, *dist.at(trajectory, mid))
        order = np.argsort(np.concatenate([parts[0][0], parts[1][0]]), kind="stable")
        t, env, env_k, own, bounds, rates = (np.concatenate([x, y])[order] for x, y in zip(*parts))
    return ClearanceProfile(t, env, env_k, own, checker.pairs, checker.margin)


def _interval_speeds(dist: "_Distances", rates: np.ndarray, peaks: np.ndarray, acc: np.ndarray,
                     dt: np.ndarray) -> np.ndarray:
    """``(len(dt), P)`` bounds [m/s] of each pair's distance rate on each interval between samples.

    A joint's speed on an interval is at most its larger end speed plus ``max|q̈| Δt / 2`` (the
    exact acceleration peak) and at most its exact peak; a pair's rate is the levers' sum of
    those over the joints between its geometries (:func:`pair_speeds`), plus the other arms'
    timed motions whole.
    """
    joint = np.minimum(np.maximum(rates[:-1], rates[1:]) + acc * dt[:, None] / 2.0, peaks)
    c = dist.checker
    # einsum, not BLAS: a few joints, and BLAS threads stall on a busy machine
    return np.einsum("ij,jk->ik", joint * c.levers, dist.paths_t) + float(c.moving_speed)


def _open_intervals(t: np.ndarray, bounds: np.ndarray, speeds: np.ndarray, dist: "_Distances", env: np.ndarray,
                    own: np.ndarray, tol: float) -> np.ndarray:
    """``(len(t) - 1,)`` bool: the intervals where some pair's bound may fall ``tol`` below its kind's smallest sample."""
    pair_bound = interval_bound(bounds[:-1], bounds[1:], speeds * np.diff(t)[:, None])
    out = np.zeros(t.size - 1, dtype=bool)
    for mask, curve in ((~dist.own, env), (dist.own, own)):
        finite = np.isfinite(curve)
        if mask.any() and finite.any():
            out |= pair_bound[:, mask].min(axis=1) < float(curve[finite].min()) - tol
    return out


#: Fewest and most intervals of :func:`sample_times` (a longer motion: more travel per interval).
MIN_INTERVALS, MAX_INTERVALS = 20, 4000


def sample_times(trajectory: Trajectory, levers: np.ndarray, margin: float, extra_speed: float = 0.0) -> np.ndarray:
    """Times [s] along ``trajectory`` with at most ``margin`` [m] of travel between two (module rule).

    Travel speed ``v(t) = Σ_j |q̇_j(t)| ℓ_j + extra_speed``; on a grid step ``h`` it is at most
    the larger end value plus ``A h / 2`` (``A = Σ_j max|q̈_j| ℓ_j``, the exact acceleration
    peaks) and at most the cap ``Σ_j max|q̇_j| ℓ_j + extra_speed`` (the exact velocity peaks);
    the grid step is ``margin`` over the cap, then the samples are kept greedily. At least
    :data:`MIN_INTERVALS` uniform intervals; at most :data:`MAX_INTERVALS` (then uniform, each
    with more travel).
    """
    t0, t1 = float(trajectory.start_time), float(trajectory.end_time)
    peaks = trajectory.peaks()
    cap = float(np.abs(np.asarray(peaks.velocity, dtype=float)) @ levers) + extra_speed
    n = int(np.clip(np.ceil(cap * (t1 - t0) / margin), MIN_INTERVALS, MAX_INTERVALS))
    grid = np.linspace(t0, t1, n + 1)
    if n == MIN_INTERVALS or n == MAX_INTERVALS:
        return grid
    qd = np.asarray(trajectory.sample(grid)[1], dtype=float).reshape(grid.size, -1)
    v = np.abs(qd) @ levers + extra_speed
    h = np.diff(grid)
    A = float(np.abs(np.asarray(peaks.acceleration, dtype=float)) @ levers)
    step = np.minimum(np.maximum(v[:-1], v[1:]) + A * h / 2.0, cap)
    budget = np.concatenate([[0.0], np.cumsum(step * h)])
    times = grid[travel_stops(budget, margin)]
    return times if times.size > MIN_INTERVALS else np.linspace(t0, t1, MIN_INTERVALS + 1)


def pair_speeds(checker: MotionChecker, peaks: np.ndarray) -> np.ndarray:
    """``(P,)`` bounds [m/s] of how fast the distance of each of the checker's pairs changes, from the
    planned joints' speed peaks ``peaks (n,)`` [rad/s or m/s].

    Only the joints on the kinematic path between the pair's two geometries move one relative
    to the other (a geometry of a held arm or a fixture does not move): the distance changes at
    most at ``Σ_{j on the path} |q̇_j| ℓ_j`` (the checker's levers ``ℓ``); the other arms' own
    timed motions (``checker.moving_speed``) are added whole.
    """
    return _pair_paths(checker) @ (np.asarray(peaks, dtype=float) * checker.levers) + float(checker.moving_speed)


def _pair_paths(checker: Any) -> np.ndarray:
    """``(P, n)``: how many joints of each planned column lie on the kinematic path between each pair's geometries."""
    model, gm = checker.model, checker.geometry
    nj = model.njoints
    supports = np.zeros((nj, nj), dtype=bool)  # supports[j, i]: joint i is on the way from the root to joint j
    for j in range(1, nj):
        supports[j, [int(i) for i in model.supports[j] if int(i) > 0]] = True
    to_col = np.zeros((nj, len(checker.cols)))  # joint -> planned column (a mimic joint: its master's)
    where = {int(c): i for i, c in enumerate(checker.cols)}
    for j in range(1, nj):
        i = where.get(int(model.joints[j].idx_v), -1)
        if i >= 0:
            to_col[j, i] = 1.0
    parent = np.array([int(g.parentJoint) for g in gm.geometryObjects], dtype=int)
    first = np.array([int(cp.first) for cp in gm.collisionPairs], dtype=int)
    second = np.array([int(cp.second) for cp in gm.collisionPairs], dtype=int)
    path = supports[parent[first]] ^ supports[parent[second]]
    return path.astype(float) @ to_col


class _Distances:
    """Exact smallest distances of a checker's pairs along one trajectory, for the environment and the own
    links in one pass per configuration (:meth:`at`, samples in time order).

    coal's distance of a pair is computed only when its lower bound is below an upper bound of
    the smallest distance of its kind; both bounds come from the pair's last exact distance
    ``d`` at time ``s``: ``d ∓ v_k |t − s|`` (``v_k`` from :func:`pair_speeds`); a pair never
    computed has no bound. So each sample's smallest distances are exact, not sampled.
    """

    def __init__(self, checker: Any, peaks: np.ndarray) -> None:
        self.checker = checker
        self.paths = _pair_paths(checker)
        self.paths_t = np.ascontiguousarray(self.paths.T)
        self.speed = self.paths @ (np.asarray(peaks, dtype=float) * checker.levers) + float(checker.moving_speed)
        self.own = np.array([p.kind == "self" for p in checker.pairs], dtype=bool)
        # each pair's last exact distance as a lower and an upper bound (none yet: -inf, inf), its time
        # and the row it was computed at
        self.last_low = np.full(self.own.size, -np.inf)
        self.last_high = np.full(self.own.size, np.inf)
        self.last_t = np.zeros(self.own.size)
        self.stamp = np.full(self.own.size, -1)
        self.row = -1
        self.calls = 0  # coal distance calls

    def _bounds(self, Q: np.ndarray) -> np.ndarray:
        """``(N, P)`` numpy lower bounds of the pairs' distances (:func:`pinarms.robots.cell.collision.pair_lower_bounds`)."""
        from pinarms.robots.cell.collision import pair_lower_bounds

        c = self.checker
        lb = np.full((Q.shape[0], self.own.size), -np.inf)
        known = c.pair_index >= 0
        if known.any():
            lb[:, known] = pair_lower_bounds(c.cell, Q, int(c.pair_index.max()) + 1)[:, c.pair_index[known]]
        return lb

    def at(self, trajectory: Trajectory, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Smallest distance to the environment [m] and its pair (−1: none), and between own links [m], at ``t``
        (increasing); and ``(len(t), P)`` each pair's distance where computed, else a lower bound of it [m]."""
        c = self.checker
        sampled = trajectory.sample(t)
        X = np.asarray(sampled[0], dtype=float).reshape(t.size, -1)
        rates = np.abs(np.asarray(sampled[1], dtype=float).reshape(t.size, -1))
        if c.timed:
            X = np.column_stack([X, t])
        Q = c.full(X)
        qp = c.to_pinocchio(Q)
        N = t.size
        geo = self._bounds(Q)
        env, env_k, own_d = np.full(N, np.inf), np.full(N, -1, dtype=int), np.full(N, np.inf)
        bounds = np.empty((N, self.own.size))
        kinds = (np.flatnonzero(~self.own), np.flatnonzero(self.own))
        for i in range(N):
            c.place_geometry(qp[i])
            self.row += 1
            slack = self.speed * np.abs(t[i] - self.last_t)
            low = np.maximum(geo[i], self.last_low - slack)
            high = self.last_high + slack
            best = [(np.inf, -1), (np.inf, -1)]
            for kind, idx in enumerate(kinds):
                if idx.size:
                    best[kind] = self._smallest(idx, low[idx], float(high[idx].min()), float(t[i]))
            (env[i], env_k[i]), own_d[i] = best[0], best[1][0]
            bounds[i] = np.where(self.stamp == self.row, self.last_low, low)  # exact where just computed
        return env, env_k, own_d, bounds, rates

    def _smallest(self, idx: np.ndarray, low: np.ndarray, high: float, t: float) -> tuple[float, int]:
        """The smallest exact distance over pairs ``idx`` (bounds ``low``; ``high`` bounds their minimum) and its pair."""
        c = self.checker
        cand = np.flatnonzero(low <= high)
        cand = cand[np.argsort(low[cand], kind="stable")]
        best, arg = np.inf, -1
        for r in cand:
            if low[r] >= best:
                break
            k = int(idx[r])
            d = c.pair_distance(k)
            self.calls += 1
            self.last_low[k] = self.last_high[k] = d
            self.last_t[k], self.stamp[k] = t, self.row
            if d < best:
                best, arg = d, k
        return best, arg
