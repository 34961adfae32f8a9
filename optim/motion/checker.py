"""Validity of the planned arms of a cell: states, straight edges and timed motions, proven continuously.

:class:`MotionChecker` answers what a sampling planner asks, for the arms being planned
(one arm, or two arms in their joint space) while the other arms of the cell hold still
or follow their own timed trajectories (:class:`TimedArm`):

- **State** ``x`` (the planned arms' joint coordinates; with moving arms, the time last):
  inside the joint limits and every checked pair that involves a planned arm at least its
  margin apart — ``margin`` for arm–fixture and arm–arm pairs, ``self_margin`` for two
  links of one arm (an arm's own links are close by design). One Pinocchio call (coal with
  each pair's security margin, GJK started cold), stopping at the first pair too close.
- **Edge** ``x_a → x_b`` (a straight line in joint space): the continuous rule of
  :func:`pinarms.robots.cell.check_motion`, in joint space instead of time. Every point of the
  planned arms' geometry moves at most ``T = Σ_j |Δq_j| ℓ_j`` along the edge (the levers
  ``ℓ_j`` of :func:`pinarms.robots.cell.motion.joint_levers`). The smallest excess
  ``E = min_k (d_k − margin_k)`` is 1-Lipschitz in that travel, so between two samples with
  travel ``B`` between them ``E ≥ (E_a + E_b − B)/2`` (the rule and its ladder:
  :mod:`pinarms.robots.cell.ladder`). Samples whose pairs all pass with their margins raised by
  ``s`` have ``E ≥ s``; two such neighbours with ``B ≤ 2s`` prove the interval. The proof is a **ladder of batched screens**: the edge is first cut into
  pieces of at most ``step · 2^k`` travel (``k ≤`` :data:`COARSE_LEVELS`; ``step`` defaults
  to the margin: nothing thinner than the margin fits between two samples of the finest
  regular level), **all samples checked as one batch** by Pinocchio's C++ loop
  (``computeCollisionsInParallel``) with the margins raised by half the piece's budget; an
  interval not proven is halved and its ends screened with half the raise, down to
  ``step / 2^MAX_SPLITS``. A sample closer than the margins themselves ends the proof (the
  edge is invalid), and so does an interval unproven at the finest level. The samples of a
  level are checked coarse-first (ends, middle, quarters, ...) with Pinocchio's
  stop-at-first-collision, so an edge through an obstacle is rejected after a few samples.
- **Timed motion** (:meth:`MotionChecker.trajectory_valid`): samples uniform in time so
  that the planned arms' travel (exact velocity peaks times the levers) plus the moving
  arms' (:meth:`MotionChecker.moving_travel`, per time bin from their exact speeds and
  acceleration peaks) stays within a step between two, through the same proof.

**Per-pair route** (``pairwise``, the default; :mod:`.coal_batches`): the cover's verdict per
pair, coal only on the pairs it leaves open; clear only when every pair is proven by one of
them at its threshold. An edge's screens raise each pair's margin by its share of the travel.

Exact distances (:meth:`MotionChecker.excess`, coal) serve the reports: which pair is
closest, the clearance along a motion. Distances in m, the world frame; joint coordinates
in rad or m; time in s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Sequence, TYPE_CHECKING, TypeVar

import numpy as np
from numpy.typing import ArrayLike
import pinocchio as pin

from pinarms.optim.errors import InvalidSettings
from pinarms.optim.motion import coal_batches
from pinarms.optim.motion.coal_batches import (MAX_THREADS, CheckRoute, CoalBatches, check_threads, cold, set_margins,
                                               shared_coal)
from pinarms.optim.motion.proof import COARSE_LEVELS, MAX_SPLITS, LadderProof, Verdict, coarse_first
from pinarms.robots.cell.cover import link_cover, motion_pairs, pair_arrays
from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.robots.cell.cell import Cell

#: How far [rad or m] a timed motion's exact joint extremes may pass a joint limit in
#: :meth:`MotionChecker.trajectory_valid` (the rounding of a time scaling's re-expanded
#: polynomials, not a physical excursion).
TIMED_LIMIT_TOL = 1e-9

__all__ = ["MotionChecker", "TimedArm", "Verdict", "MAX_SPLITS", "MAX_THREADS", "COARSE_LEVELS", "check_threads",
           "coarse_first"]

T = TypeVar("T")


@dataclass(frozen=True)
class TimedArm:
    """An arm that follows its own trajectory while others are planned around it.

    Attributes:
        arm: the arm's name in the cell.
        trajectory: its :class:`pinarms.planning.Trajectory` (the arm's own joint order).
        offset: cell time [s] at which the trajectory's ``start_time`` is played; before
            and after, the arm holds the trajectory's first and last configuration.
    """

    arm: str
    trajectory: Any
    offset: float = 0.0

    def q_at(self, t: np.ndarray) -> np.ndarray:
        tr = self.trajectory
        tau = np.clip(np.asarray(t, dtype=float) - self.offset + tr.start_time, tr.start_time, tr.end_time)
        return np.asarray(tr.sample(tau)[0], dtype=float).reshape(np.size(t), -1)



def _refuse_delta_pairs(cell: Cell, arms: tuple[str, ...]) -> None:
    """InvalidInput when the checker would miss a pair with a delta's body (docs/cells.md, "A delta robot in a
    cell"): its bodies are not in the tree this checker proves on, so a planned arm that is a delta, or one that
    a delta's body may touch, is refused rather than proven against part of the cell."""
    deltas = getattr(cell, "deltas", ())
    if not deltas:
        return
    if any(d.name in arms for d in deltas) or any({p.owner_a, p.owner_b} & set(arms) for p in cell.delta_pairs):
        raise InvalidInput(f"cell {cell.name!r} holds a delta ({', '.join(d.name for d in deltas)}) whose bodies "
                           f"the motion checker of {', '.join(arms)} cannot see: check the motion with "
                           "Cell.check_motion (planning beside or for a delta is not supported)")


class MotionChecker(CoalBatches, LadderProof):
    """State, edge and path validity of the planned arms of ``cell`` (module docstring).

    Args:
        cell: a :class:`pinarms.robots.Cell`.
        arms: the planned arms' names (their coordinates, in this order, make ``x``).
        margin: clearance every pair with a fixture or another arm keeps [m] (> 0).
        self_margin: clearance between two links of one planned arm [m] (≥ 0).
        hold: cell configuration ``(nq,)`` of the arms not planned (default :attr:`Cell.hold`,
            each arm's hold pose); the planned arms' entries are ignored.
        moving: :class:`TimedArm` s that follow trajectories meanwhile: then ``x`` ends
            with the time [s] and their configuration at that time is used.
        step: largest travel [m] of any point between two samples of an edge (default
            ``margin``).
        route: threads, sphere-cover screen and per-pair route of the checks
            (:class:`.coal_batches.CheckRoute`; default ``CheckRoute()``: one thread, the cover,
            the default route).

    Raises:
        InvalidInput: an unknown arm, a bad hold configuration or margins.
    """

    def __init__(self, cell: Cell, arms: Sequence[str], *, margin: float = 0.01, self_margin: float = 0.0,
                 hold: ArrayLike | None = None, moving: Sequence[TimedArm] = (), step: float | None = None,
                 route: CheckRoute | None = None) -> None:
        from pinarms.robots.cell.motion import joint_levers

        route = CheckRoute() if route is None else route
        if not isinstance(route, CheckRoute):
            raise InvalidSettings(f"route must be a CheckRoute, got {type(route).__name__}")
        self.cell = cell
        names = [arms] if isinstance(arms, str) else list(arms)
        if not names or len(set(names)) != len(names):
            raise InvalidInput(f"arms must name distinct arms of the cell, got {arms!r}")
        self.arms = tuple(cell.arm(a).name for a in names)
        _refuse_delta_pairs(cell, self.arms)
        for name, value in (("margin", margin), ("self_margin", self_margin)):
            ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
            if not ok or not math.isfinite(float(value)) or float(value) < 0.0:
                raise InvalidInput(f"{name} must be a finite number >= 0 [m], got {value!r}")
        if float(margin) <= 0.0:
            raise InvalidInput("margin must be > 0 m: it also sets the step of the continuous edge check")
        self.margin = float(margin)
        self.self_margin = float(self_margin)
        self.step = self.margin if step is None else float(step)
        if not (math.isfinite(self.step) and self.step > 0.0):
            raise InvalidInput(f"step must be a positive length [m], got {step!r}")
        self.cols = np.concatenate([np.arange(cell.nq)[cell.arm(a).q_slice] for a in self.arms])
        self.n = int(self.cols.size)
        self.lower = np.asarray(cell.lower, dtype=float)[self.cols]
        self.upper = np.asarray(cell.upper, dtype=float)[self.cols]
        #: the planned columns that are continuous joints (any angle, the same pose every 2π): their
        #: search box is one turn until :meth:`span_turns` widens it around a query's ends
        self.continuous = np.asarray(cell.robot.continuous, dtype=bool)[self.cols]
        base = cell.hold if hold is None else cell.robot.check_q(hold)[0][0]
        self.hold = np.array(base, dtype=float)
        self.moving = tuple(moving)
        for m in self.moving:
            if m.arm in self.arms:
                raise InvalidInput(f"arm {m.arm!r} is both planned and moving on its own trajectory")
        self._moving_cols = [np.arange(cell.nq)[cell.arm(m.arm).q_slice] for m in self.moving]
        self.timed = bool(self.moving)
        levers = np.asarray(joint_levers(cell), dtype=float)
        self.levers = levers[self.cols]
        self.moving_speed = float(sum(np.abs(m.trajectory.peaks().velocity) @ levers[c]
                                      for m, c in zip(self.moving, self._moving_cols)))
        self._travel_t, self._travel_i = self._moving_travel(levers)
        # the pairs that involve a planned arm, each with its margin: every pair not proven farther than the
        # widest screen of either margin (Cell.pairs_for), less the constant ones at least their margin apart
        planned = set(self.arms)
        widest = max(self.margin, self.self_margin) + self.step * 2.0 ** (COARSE_LEVELS - 1)  # the coarsest screen
        chosen = motion_pairs(cell, widest, planned, self.self_margin, self.margin)
        where = {p: k for k, p in enumerate(cell.pairs)}
        # index into cell.pairs (-1: a pair the cell does not check at zero clearance, bounded exactly)
        self.pair_index = np.array([where.get(p, -1) for p in chosen], dtype=int)
        self.pairs = tuple(chosen)
        self.pair_margin = np.array([self.self_margin if p.kind == "self" else self.margin for p in self.pairs])
        self.model = cell.model
        self.threads = route.threads
        self._data = self.model.createData()
        shared = shared_coal(cell, self.pairs, self.pair_margin, self.threads)
        if "geometry" not in shared:
            gm = cell.collision_model.copy()
            gm.removeAllCollisionPairs()
            for p in self.pairs:
                gm.addCollisionPair(pin.CollisionPair(p.index_a, p.index_b))
            gd = cold(pin.GeometryData(gm))
            set_margins(gd, self.pair_margin)
            manager = pin.BroadPhaseManager_DynamicAABBTreeCollisionManager(self.model, gm, gd)
            shared.update(geometry=gm, gd=gd, manager=manager, gd_dist=cold(pin.GeometryData(gm)), pools={},
                          loop=None)
        self._shared = shared
        self.geometry = shared["geometry"]
        self._gd = shared["gd"]
        self._manager = shared["manager"]
        self._gd_dist = shared["gd_dist"]
        self._pools: dict[Any, Any] = shared["pools"]
        self._identity = self._pin_is_identity()
        self.counts = {"states": 0, "edges": 0, "configurations": 0, "exact": 0, "coal": 0, "coal_pairs": 0,
                       "timeouts": 0}
        #: ``time.perf_counter()`` after which proofs give up and call their edge not valid (a
        #: search's time limit; ``None``: never). Giving up never calls anything clear.
        self.deadline: float | None = None
        #: The sphere cover screening every check (:mod:`pinarms.robots.cell.cover`): what it proves clear is
        #: clear; the rest goes to coal. ``None`` (``cover=False``): coal for every configuration.
        self.cover = link_cover(cell) if route.cover else None
        self._cover_pairs = None if self.cover is None else self.cover.prepare(*pair_arrays(self.pairs))
        #: Whether coal computes only the pairs the cover leaves open (:meth:`pair_collides`).
        self.pairwise = bool(coal_batches.PAIRWISE if route.pairwise is None else route.pairwise) and self.cover is not None
        self._share: np.ndarray | None = None  # each pair's share of an edge's travel (_travel_share)
        self._pair_rows: np.ndarray | None = None
        self._screeners: dict[str, Any] = {}  # the cover's prepared per-pair screen (built on first use)
        self._memo: dict[str, Any] = {}  # what helpers build once per checker (memo)

    # ------------------------------------------------------------------ plumbing
    def _moving_travel(self, levers: np.ndarray, bins: int = 1024) -> tuple[np.ndarray, np.ndarray]:
        """Cumulative bound ``I(t)`` [m] of the moving arms' point travel, on a time grid.

        On each bin of width h the point speed is at most ``max(v_a, v_b) + A h / 2`` (``v``
        from the exact joint speeds at the bin ends times the levers, ``A`` from the exact
        acceleration peaks), and never more than the exact velocity peaks allow: the rule of
        :func:`pinarms.robots.cell.check_motion`. Outside its trajectory an arm holds still.
        """
        if not self.moving:
            return np.array([0.0, 1.0]), np.zeros(2)
        edges = []
        for m in self.moving:
            tr = m.trajectory
            edges.append(m.offset + np.linspace(0.0, tr.end_time - tr.start_time, bins + 1))
        grid = np.unique(np.concatenate(edges))
        speed = np.zeros(grid.size - 1)
        for m, c in zip(self.moving, self._moving_cols):
            tr = m.trajectory
            lev = levers[c]
            peaks = tr.peaks()
            cap = float(np.abs(peaks.velocity) @ lev)
            acc = float(np.abs(peaks.acceleration) @ lev)
            tau = np.clip(grid - m.offset + tr.start_time, tr.start_time, tr.end_time)
            v = np.abs(np.asarray(tr.sample(tau)[1], dtype=float).reshape(grid.size, -1)) @ lev
            h = np.diff(grid)
            inside = (grid[1:] > m.offset) & (grid[:-1] < m.offset + tr.end_time - tr.start_time)
            speed += np.where(inside, np.minimum(np.maximum(v[:-1], v[1:]) + acc * h / 2.0, cap), 0.0)
        cumulative = np.concatenate([[0.0], np.cumsum(speed * np.diff(grid))])
        return grid, cumulative

    def moving_travel(self, ta: ArrayLike, tb: ArrayLike) -> np.ndarray:
        """Bound [m] of how far any point of the moving arms travels between cell times ``ta`` and ``tb``."""
        I = np.interp(np.asarray(tb, dtype=float), self._travel_t, self._travel_i)
        return np.abs(I - np.interp(np.asarray(ta, dtype=float), self._travel_t, self._travel_i))

    def _pin_is_identity(self) -> bool:
        if self.model.nq != self.cell.nq:
            return False
        q = self.cell.random_q(3, seed=0)
        return bool(np.array_equal(self.cell.robot.q_to_pinocchio(q), q))

    def full(self, X: ArrayLike) -> np.ndarray:
        """Cell configurations ``(N, nq)`` for planned states ``X (N, n[+1])`` (time last when timed)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        Q = np.tile(self.hold, (X.shape[0], 1))
        Q[:, self.cols] = X[:, : self.n]
        if self.timed:
            t = X[:, self.n]
            for m, c in zip(self.moving, self._moving_cols):
                Q[:, c] = m.q_at(t)
        return Q

    def span_turns(self, X: Any) -> None:
        """Widen the search box of the continuous columns to hold the states ``X (k, n)`` and half a turn
        beyond: ``[min − π, max + π]`` (never narrowed; the other columns keep their joint limits)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))[:, : self.n]
        c = self.continuous
        if X.size and c.any():
            self.lower[c] = np.minimum(self.lower[c], X[:, c].min(axis=0) - np.pi)
            self.upper[c] = np.maximum(self.upper[c], X[:, c].max(axis=0) + np.pi)

    def within_limits(self, X: np.ndarray) -> np.ndarray:
        X = np.atleast_2d(X)
        return np.all((X[:, : self.n] >= self.lower - 1e-12) & (X[:, : self.n] <= self.upper + 1e-12), axis=1)

    # ------------------------------------------------------------------ states
    def state_valid(self, x: ArrayLike) -> bool:
        """One planned state: within the limits and every pair at least its margin apart."""
        x = np.asarray(x, dtype=float)
        self.counts["states"] += 1
        if not self.within_limits(x[None])[0]:
            return False
        q = self.full(x[None])[0]
        if self.pairwise:
            return not self._state_pairs(q)
        if self.cover_decides_screens and self.cover.screen(q[None], self._cover_pairs, self.pair_margin)[0]:
            return True
        self.counts["coal"] += 1
        self.counts["coal_pairs"] += len(self.pairs)
        return not pin.computeCollisions(self.model, self._data, self._manager, self.to_pinocchio(q[None])[0], True)

    def excess(self, Q: np.ndarray, mask: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Exact smallest ``d_k − margin_k`` over the pairs [m] per row of cell configurations ``Q``,
        the index (into :attr:`pairs`) of that pair and its distance ``d_k`` [m].

        ``mask (P,)`` bool: only those pairs (e.g. the arm–environment ones). coal's distances
        of the pairs in increasing order of a numpy lower bound
        (:func:`pinarms.robots.cell.collision.pair_lower_bounds`), stopping when the next bound
        exceeds the best found: exact, not sampled."""
        from pinarms.robots.cell.collision import pair_lower_bounds

        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        N = Q.shape[0]
        self.counts["exact"] += N
        known = self.pair_index >= 0
        lb = np.full((N, self.pair_index.size), -np.inf)
        lb[:, known] = pair_lower_bounds(self.cell, Q)[:, self.pair_index[known]]
        lb -= self.pair_margin
        if mask is not None:
            lb[:, ~np.asarray(mask, dtype=bool)] = np.inf
        order = np.argsort(lb, axis=1, kind="stable")
        qp = self.to_pinocchio(Q)
        gm, gd = self.geometry, self._gd_dist
        out = np.full(N, np.inf)
        arg = np.full(N, -1, dtype=int)
        dist = np.full(N, np.inf)
        for i in range(N):
            pin.updateGeometryPlacements(self.model, self._data, gm, gd, qp[i])
            best, k_best, d_best = np.inf, -1, np.inf
            for k in order[i]:
                if lb[i, k] >= best:
                    break
                d = pin.computeDistance(gm, gd, int(k)).min_distance
                e = d - self.pair_margin[k]
                if e < best:
                    best, k_best, d_best = e, int(k), d
            out[i], arg[i], dist[i] = best, k_best, d_best
        return out, arg, dist

    def memo(self, key: str, build: Callable[[], T]) -> T:
        """The value kept with this checker under ``key``, built by ``build()`` the first time (as
        :meth:`pinarms.robots.cell.Cell.memo`; the fast check of :func:`pinarms.optim.motion.fast.fast_check`)."""
        if key not in self._memo:
            self._memo[key] = build()
        return self._memo[key]

    def place_geometry(self, qp: np.ndarray) -> None:
        """Place every collision body at Pinocchio configuration ``qp`` (one row of :meth:`to_pinocchio`) for
        :meth:`pair_distance`."""
        pin.updateGeometryPlacements(self.model, self._data, self.geometry, self._gd_dist, qp)

    def pair_distance(self, k: int) -> float:
        """The exact distance [m] of collision pair ``k`` of :attr:`geometry` where :meth:`place_geometry` last put them."""
        return float(pin.computeDistance(self.geometry, self._gd_dist, int(k)).min_distance)

    def closest(self, x: ArrayLike) -> tuple[float, Any, float]:
        """``(excess [m], pair, distance [m])`` of the pair nearest its margin at state ``x``."""
        e, k, d = self.excess(self.full(np.asarray(x, dtype=float)[None]))
        return float(e[0]), (self.pairs[int(k[0])] if k[0] >= 0 else None), float(d[0])

    # ------------------------------------------------------------------ proofs
    def travel(self, xa: np.ndarray, xb: np.ndarray) -> float:
        """Bound [m] of how far any point of the planned arms moves along the straight edge ``xa → xb``."""
        return float(np.abs(xb[: self.n] - xa[: self.n]) @ self.levers)

    def edge_samples(self, xa: ArrayLike, xb: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The samples ``(n+1, n_joints)`` of the straight edge ``xa → xb`` and their travel budgets ``(n,)`` [m]."""
        X, budgets, _ = self._edge_samples(xa, xb, 0)
        return X, budgets

    def _edge_samples(self, xa: Any, xb: Any, coarse: int = COARSE_LEVELS) -> tuple[np.ndarray, np.ndarray, int]:
        """Samples of the straight edge at the coarsest level ``−k`` (``k ≤ coarse``): budgets ≤ ``step · 2^k``."""
        xa = np.asarray(xa, dtype=float)
        xb = np.asarray(xb, dtype=float)
        T = self.travel(xa, xb)
        k = int(np.clip(math.floor(math.log2(max(T / self.step, 1.0))), 0, coarse))
        n = max(1, int(math.ceil(T / (self.step * 2.0 ** k) * (1.0 + 1e-12))))
        f = np.arange(n + 1) / n
        return xa + f[:, None] * (xb - xa), np.full(n, T / n), -k

    def edge_valid(self, xa: ArrayLike, xb: ArrayLike) -> Verdict:
        """Whether the straight joint-space edge ``xa → xb`` keeps every margin everywhere (module docstring)."""
        if self.timed:
            raise InvalidInput("straight edges are checked with the other arms held; a moving arm is checked "
                               "along a timed trajectory (trajectory_valid)")
        xa = np.asarray(xa, dtype=float)
        xb = np.asarray(xb, dtype=float)
        self.counts["edges"] += 1
        X, budgets, top = self._edge_samples(xa, xb)
        n = budgets.size

        def midpoint(i: int, a: float, b: float, B: float):
            f = (i + 0.5 * (a + b)) / n
            return xa + f * (xb - xa), 0.5 * B, 0.5 * B

        self._share = self._travel_share(xa, xb) if self.pairwise else None
        try:
            v = self.prove(X, budgets, midpoint, convex=bool(self.within_limits(np.stack([xa, xb])).all()), top=top)
        finally:
            self._share = None
        if v.ok:
            return v
        return Verdict(False, v.first_bad, max(0.0, (v.first_bad - 1) / n) if v.first_bad >= 0 else 0.0, v.exact)

    def trajectory_valid(self, trajectory: Trajectory, t0: float = 0.0, until: float | None = None) -> Verdict:
        """Prove a timed motion of the planned arms (their joints, in order), played from cell time ``t0``,
        against the moving arms at the same instants (and the fixtures, the held arms).

        ``until``: the cell time up to which the proof runs (default: the end of the moving
        arms' motions, if later than the trajectory's): the planned arms hold their last
        configuration meanwhile.

        Samples uniform in time so that the planned arms' travel (exact velocity peaks times
        the levers) plus the moving arms' (:meth:`moving_travel`) is at most ``step`` between
        two; a halved interval gets each half's own budget. The joint limits are checked at the
        trajectory's exact per-joint extremes first (within :data:`TIMED_LIMIT_TOL`): a timed motion
        may pass a limit between two samples."""
        from pinarms.planning import Trajectory

        tr = trajectory
        low, high = tr.position_range()
        if np.any(low < self.lower - TIMED_LIMIT_TOL) or np.any(high > self.upper + TIMED_LIMIT_TOL):
            return Verdict(False, 0, 0.0)
        vb = float(np.abs(np.asarray(tr.peaks().velocity, dtype=float)) @ self.levers)
        if until is None and self.timed:
            until = max(m.offset + m.trajectory.end_time - m.trajectory.start_time for m in self.moving)
        end = t0 + tr.end_time - tr.start_time
        if until is not None and until > end + 1e-12:
            C = tr.coefficients
            rest = np.zeros((1, C.shape[1], C.shape[2]))
            rest[0, 0] = np.asarray(tr.sample(tr.end_time)[0], dtype=float)
            tr = Trajectory(np.append(tr.knot_times, tr.end_time + (until - end)), np.concatenate([C, rest]))
        duration = tr.end_time - tr.start_time
        total = vb * duration + (float(self.moving_travel(t0, t0 + duration)) if self.timed else 0.0)
        n = max(1, int(math.ceil(total / self.step * (1.0 + 1e-12))))
        tau = tr.start_time + duration * np.arange(n + 1) / n

        def budget(ta: np.ndarray, tb: np.ndarray) -> np.ndarray:
            out = vb * (tb - ta)
            if self.timed:
                out = out + self.moving_travel(t0 + ta - tr.start_time, t0 + tb - tr.start_time)
            return out

        def states(taus: np.ndarray) -> np.ndarray:
            q = np.asarray(tr.sample(taus)[0], dtype=float).reshape(taus.size, -1)
            return np.column_stack([q, t0 + taus - tr.start_time]) if self.timed else q

        def midpoint(i: int, a: float, b: float, B: float):
            ta = tau[i] + a * (tau[i + 1] - tau[i])
            tb = tau[i] + b * (tau[i + 1] - tau[i])
            tm = 0.5 * (ta + tb)
            halves = budget(np.array([ta, tm]), np.array([tm, tb]))
            return states(np.array([tm]))[0], halves[0], halves[1]

        budgets = budget(tau[:-1], tau[1:])
        if np.any(budgets > self.step * (1.0 + 1e-9)):  # the moving arms' share is uneven: split where needed
            extra = np.maximum(1, np.ceil(budgets / self.step)).astype(int)
            first = np.repeat(np.cumsum(extra) - extra, extra)
            k = np.arange(int(extra.sum())) - first
            tau = np.append(np.repeat(tau[:-1], extra) + k * np.repeat(np.diff(tau) / extra, extra), tau[-1])
            budgets = budget(tau[:-1], tau[1:])
        return self.prove(states(tau), budgets, midpoint)
