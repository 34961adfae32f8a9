"""The compiled check and search: RRT-Connect and shortcutting on the sphere cover, proven.

:class:`FastCheck` is the cover's side of a :class:`MotionChecker` (its pairs, margins,
levers, held arms), all in compiled code (:mod:`._fast_kernel`):

- a **state** is proven clear when the cover's lower bound of the excess
  ``E(x) = min_k (d_k − margin_k)`` is ≥ 0 (the cover contains the geometry: its distances
  are lower bounds); inconclusive counts as not valid here — never as clear;
- an **edge** is proven by the Lipschitz rule of the exact proof taken per pair group: the
  distance of two links changes along the edge by at most the travel of the joints upstream
  of one and not the other times their levers to that link's points (``w_g``, at most the
  whole-arm ``T = Σ |Δx_j| ℓ_j``; :mod:`.link_levers`), so an interval whose ends have
  ``Ẽ_a + Ẽ_b ≥ s_b − s_a`` on the scaled excess ``Ẽ = min_k ê_k / w_g`` keeps every margin;
  bisecting where needed down to the exact proof's finest travel ``step / 2^MAX_SPLITS``;
  ``E`` is capped at the clearance above which the checker left pairs out (they are proven
  that far apart).

:func:`fast_search` runs RRT-Connect on it (the smaller tree grows next, ties in turn, half of its
samples near one of its own nodes: an end deep in a crate gets the samples it needs,
:data:`._fast_kernel.LOCAL_SHARE`; seeded SplitMix64 stream, chunks of iterations between which
the clock is read: the time limit holds to a chunk, a few ms) and
:func:`fast_shortcut` shortcuts on it. A path so found is proven; :func:`pinarms.optim.plan_motion`
still proves it again with the exact checker before reporting it.
"""

from __future__ import annotations

import time
from typing import Any, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.optim.motion import _fast_kernel as kernel
from pinarms.optim.motion.link_levers import group_levers
from pinarms.optim.motion.proof import MAX_SPLITS
from pinarms.robots.cell.cover_kernel import place_world
from pinarms.robots.cell.cover import motion_pairs, pair_arrays
from pinarms.optim.motion.search import SearchResult

if TYPE_CHECKING:
    from pinarms.optim.motion.checker import MotionChecker

__all__ = ["FastCheck", "fast_check", "fast_search", "fast_shortcut", "COMPILED_PLANNER", "TREE_NODES"]

#: The planner named in results found by :func:`fast_search`.
COMPILED_PLANNER = "RRTConnect"
#: Clearance above the margins [m] up to which the compiled check looks at pairs (the cell's
#: ``pairs_for``): the excess bound is capped there, so an edge needs at least one state per
#: ``2 · REACH`` of travel.
REACH = 0.25
#: Most states one compiled edge proof takes before it gives up (the edge then counts as not proven):
#: an edge running long within millimetres of something needs thousands (tens of ms); the search
#: and the shortcutting look for others instead.
EDGE_STATES = 400
#: Most nodes per tree of the compiled search.
TREE_NODES = 16384
#: Iterations of the compiled search's first chunk (the chunks double while one takes under 2 ms): most
#: queries of the Panda and AUBO-i3 scenes are solved in one or two calls (a call costs 5–10 µs).
FIRST_CHUNK = 4
#: Longest edge the compiled search adds at once, as a share of the diagonal of the joint-limit box
#: (OMPL's default is 0.2). Measured (25 queries, 0.75 s, load 2.5–3.5): ``aubo_crate_guard`` 15, 20, 20
#: solved at 0.2, 0.15, 0.1 (the narrow passage out of the crate), ``panda_shelf`` median 14.8, 10.2,
#: 11.5 ms, ``panda_table_box`` 0.94, 0.85, 1.10 ms.
RANGE_SHARE = 0.15
#: An end the cover does not prove (the spheres overshoot the geometry near a wall) but the exact
#: checker does is joined to a nearby state the cover proves by an edge the exact checker proves:
#: random states at these joint-space radii (shares of each joint's range) are tried,
#: :data:`ESCAPE_SAMPLES` per radius, and at most :data:`ESCAPE_EDGES` exact edge proofs.
#: A shortcut try is proven only when it would shorten the path by at least this share of its length: the
#: tries on a path already nearly straight proved long edges for nothing. Measured on the compiled searches'
#: paths of 25 queries (thread time, load 2.6): ``panda_shelf`` 5.5 -> 3.8 ms median at 0.01 (mean length
#: +1.0 %), ``panda_table_box`` 3.2 -> 1.8 ms, ``aubo_two_belt`` 1.4 -> 0.9 ms, ``aubo_crate_guard`` 2.1 ->
#: 1.8 ms (lengths within 0.3 %).
SHORTCUT_GAIN = 0.01
ESCAPE_RADII = (0.01, 0.02, 0.04, 0.08, 0.16)
ESCAPE_SAMPLES = 12
ESCAPE_EDGES = 6


class FastCheck:
    """The compiled cover check of ``checker`` (module docstring): states, edges and polylines.

    ``reach``: the cap of the excess bound [m] (default :data:`REACH`); the pairs of the cell
    not proven farther apart than the margins plus ``reach`` are checked. ``max_states``: most
    states one edge proof may take (default :data:`EDGE_STATES`).

    Raises:
        ValueError: a checker without a cover, or one with arms moving on their own
            trajectories (their checks stay with :meth:`MotionChecker.trajectory_valid`).
    """

    def __init__(self, checker: MotionChecker, reach: float | None = None, max_states: int | None = None) -> None:
        if checker.cover is None or checker.timed:
            raise ValueError("the compiled check needs a checker with the sphere cover and no moving arms")
        cover = checker.cover
        reach = REACH if reach is None else float(reach)
        planned = set(checker.arms)
        widest = max(checker.margin, checker.self_margin) + reach
        chosen = motion_pairs(checker.cell, widest, planned, checker.self_margin, checker.margin)
        margins = np.array([checker.self_margin if p.kind == "self" else checker.margin for p in chosen])
        pairs = cover.prepare(*pair_arrays(chosen))
        self.checker = checker
        self.pairs = tuple(chosen)
        self.fk = cover.fk
        self.cov = cover.kernel_arrays()
        self.grp = cover.group_arrays(pairs, margins)
        self.work = _moving_work(cover, pairs, checker.hold, checker.cols)
        self.hold = np.ascontiguousarray(checker.hold, dtype=float)
        self.cols = np.ascontiguousarray(checker.cols, dtype=np.int64)
        self.levers = np.ascontiguousarray(checker.levers, dtype=float)
        model = checker.cell.model
        #: each pair group's levers (G, n): its distance changes at most by ``Σ_j |Δx_j| lam[g, j]``
        self.lam = group_levers(cover, pairs, model.lowerPositionLimit, model.upperPositionLimit, self.cols)
        #: the pairs left out are proven farther apart than this above their margins [m]: E is capped there
        self.cap = reach
        self.min_budget = float(checker.step / 2.0 ** MAX_SPLITS)
        #: states one edge proof may take before it gives up (not proven: never clear)
        self.max_states = int(EDGE_STATES if max_states is None else max_states)
        #: the kernels' arguments after the states: levers, finest budget, states per edge, the cell
        self.args = (self.levers, self.lam, self.min_budget, self.max_states, self.hold, self.cols, self.fk, self.cov, self.grp,
                     self.cap, self.work)
        self._q = np.empty(self.hold.size)
        self._xm = np.empty(checker.n)
        self._queue = np.empty((kernel.QUEUE, 4))
        self._inv = np.empty(self.lam.shape[0])
        self._trees: tuple[np.ndarray, np.ndarray] | None = None
        self._load()

    def _load(self) -> None:
        """Call every kernel once on nothing (loading compiled code from the cache takes tens of ms at
        a first call): a search's clock then measures the search."""
        n = self.checker.n
        x = np.ascontiguousarray(self.checker.lower, dtype=float)
        kernel.edge_proven(x, x, *self.args, self._q, self._xm, self._queue, self._inv)
        self.excess(x)  # the search's ends are checked with it, on the search's clock
        kernel.path_proven(x[None].copy(), *self.args)
        kernel.rrt_connect(np.zeros((2, 1, n)), np.zeros((2, 1), dtype=np.int64), np.ones(2, dtype=np.int64),
                           np.zeros(5, dtype=np.int64), _rng(0), x, x, 1.0, 0, *self.args)
        kernel.shortcut(np.zeros((2, n)), 2, _rng(0), 0, 0.0, *self.args)

    def trees(self) -> tuple[np.ndarray, np.ndarray]:
        """The compiled search's tree arrays ``nodes (2, TREE_NODES, n)`` and ``parent (2, TREE_NODES)``,
        made once per check and reused by each search (one search at a time per checker, like the
        kernels' scratch arrays)."""
        if self._trees is None:
            n = self.checker.n
            self._trees = (np.zeros((2, TREE_NODES, n)), np.full((2, TREE_NODES), -1, dtype=np.int64))
        return self._trees

    def excess(self, x: ArrayLike) -> float:
        """The cover's lower bound of ``E`` [m] at planned state ``x`` (capped; below 0: not proven)."""
        return float(kernel.state_excess(np.ascontiguousarray(x, dtype=float), self.hold, self.cols, self.fk, self.cov,
                                         self.grp, self.cap, self.work, self._q))

    def state_proven(self, x: ArrayLike) -> bool:
        """Whether the cover proves state ``x`` clear of every margin (and ``x`` is within the joint limits)."""
        x = np.asarray(x, dtype=float)
        return bool(self.checker.within_limits(x[None])[0]) and self.excess(x) >= 0.0

    def edge_proven(self, xa: ArrayLike, xb: ArrayLike) -> bool:
        """Whether the cover proves the straight edge ``xa → xb`` clear of every margin (ends within the limits)."""
        xa = np.ascontiguousarray(xa, dtype=float)
        xb = np.ascontiguousarray(xb, dtype=float)
        if not self.checker.within_limits(np.stack([xa, xb])).all():
            return False
        return bool(kernel.edge_proven(xa, xb, *self.args, self._q, self._xm, self._queue, self._inv))

    def path_proven(self, P: ArrayLike) -> bool:
        """Whether the cover proves every edge of the polyline ``P (M, n)``."""
        P = np.ascontiguousarray(np.atleast_2d(P), dtype=float)
        if not self.checker.within_limits(P).all():
            return False
        return bool(kernel.path_proven(P, *self.args))


def fast_check(checker: MotionChecker) -> FastCheck | None:
    """The :class:`FastCheck` of ``checker`` (kept with it), or ``None`` when it has none (no cover, moving arms)."""
    def build() -> FastCheck | None:
        try:
            return FastCheck(checker)
        except ValueError:
            return None

    return checker.memo("fast_check", build)


def _moving_work(cover: Any, pairs: Any, hold: np.ndarray, cols: np.ndarray) -> tuple:
    """The kernels' scratch arrays placed at ``hold`` once, with what moves with the planned columns ``cols``
    (:func:`pinarms.robots.cell.cover_kernel.place_moving`): the joints below them, the bounding spheres, cover
    spheres and cylinder axes on those joints. The held arms and the fixtures stay where they were placed."""
    parent, index = cover.fk[0], cover.fk[1]
    planned = set(int(c) for c in cols)
    moves = np.zeros(parent.size, dtype=bool)
    for i in range(1, parent.size):  # a joint's parent comes before it
        moves[i] = int(index[i]) in planned or moves[parent[i]]
    work = cover.work(pairs)
    hold = np.ascontiguousarray(hold, dtype=float)
    place_world(hold, cover.fk, cover.kernel_arrays(), pairs.hjoint, pairs.hcenter, work)
    moving = (np.flatnonzero(moves), np.flatnonzero(moves[pairs.hjoint]), np.flatnonzero(moves[cover.joint]),
              np.flatnonzero(moves[cover.segments[0]]), np.empty((3, 3)))
    return (*work, tuple(np.ascontiguousarray(m, dtype=np.int64) for m in moving[:4]) + (moving[4],))


def _rng(seed: int) -> np.ndarray:
    return np.array([(int(seed) * 0x9E3779B97F4A7C15 + 0x2545F4914F6CDD1D) % (1 << 64)], dtype=np.uint64)


def fast_search(checker: MotionChecker, start: ArrayLike, goals: ArrayLike, *, time_limit: float = 1.0, seed: int = 0,
                planner_range: float | None = None) -> SearchResult:
    """RRT-Connect from ``start (n,)`` to any of ``goals (G, n)`` on the compiled cover check.

    An end the cover does not prove is joined to a nearby state it proves by an edge the exact
    checker proves (:data:`ESCAPE_RADII`); ends for which none is found are left out (a start:
    nothing searched, ``status`` says so). ``planner_range``: the longest edge added at once
    [rad or m, joint space] (default :data:`RANGE_SHARE` of the diagonal of the joint-limit
    box). The result's ``path`` is ``None`` when nothing was found within ``time_limit`` [s]."""
    fc = fast_check(checker)  # built, its kernels loaded and its trees made before the clock starts
    if fc is not None:
        fc.trees()
    t0 = time.perf_counter()
    x0 = np.asarray(start, dtype=float)
    G = np.atleast_2d(np.asarray(goals, dtype=float))
    gen = np.random.default_rng(int(seed))
    root = None if fc is None else _escape(fc, x0, gen)
    if root is None:
        return SearchResult(None, 0, time.perf_counter() - t0, COMPILED_PLANNER, -1, "start not proven by the cover")
    ends = [(k, _escape(fc, g, gen)) for k, g in enumerate(G)]
    keep = [(k, y) for k, y in ends if y is not None]
    if not keep:
        return SearchResult(None, 1, time.perf_counter() - t0, COMPILED_PLANNER, -1, "no goal proven by the cover")
    n = x0.size
    lower, upper = np.asarray(checker.lower, dtype=float), np.asarray(checker.upper, dtype=float)
    step_range = float(planner_range) if planner_range is not None else \
        RANGE_SHARE * float(np.linalg.norm(upper - lower))
    nodes, parent = fc.trees()  # rows past a tree's count are never read
    nodes[0, 0] = root
    nodes[1, : len(keep)] = [y for _, y in keep]
    parent[0, 0] = -1
    parent[1, : len(keep)] = -1
    counts = np.array([1, len(keep)], dtype=np.int64)
    status = np.zeros(5, dtype=np.int64)
    rng = _rng(seed)
    chunk, found = FIRST_CHUNK, 0
    deadline = t0 + float(time_limit)
    while time.perf_counter() < deadline and counts.min() < TREE_NODES:
        tc = time.perf_counter()
        found = kernel.rrt_connect(nodes, parent, counts, status, rng, lower, upper, step_range, chunk,
                                   *fc.args)
        if found:
            break
        spent = time.perf_counter() - tc
        if spent < 0.002 and spent < 0.02 * float(time_limit):  # chunks of a few ms: the clock read often enough
            chunk *= 2
    seconds = time.perf_counter() - t0
    states = int(counts.sum())
    if not found:
        return SearchResult(None, states, seconds, COMPILED_PLANNER, -1, f"Timeout ({int(status[4])} states checked)")
    tail = _branch(nodes[1], parent[1], int(status[2]))
    gi = keep[int(np.argmin(np.linalg.norm(np.array([y for _, y in keep]) - tail[-1], axis=1)))][0]
    parts = [_branch(nodes[0], parent[0], int(status[1]))[::-1], tail[1:]]
    if not np.array_equal(root, x0):  # the exactly proven edges off the ends
        parts.insert(0, x0[None])
    if not np.array_equal(tail[-1], G[gi]):
        parts.append(G[gi][None])
    path = np.concatenate(parts)
    return SearchResult(path, states, seconds, COMPILED_PLANNER, gi, f"Exact solution ({int(status[4])} states checked)")


def _escape(fc: FastCheck, x: np.ndarray, gen: np.random.Generator) -> np.ndarray | None:
    """``x`` when the cover proves it; else a nearby state the cover proves joined to ``x`` by an edge
    the exact checker proves (module constants), or ``None``."""
    if fc.state_proven(x):
        return x
    checker = fc.checker
    if not checker.state_valid(x):
        return None
    lower, upper = np.asarray(checker.lower, dtype=float), np.asarray(checker.upper, dtype=float)
    edges = 0
    for radius in ESCAPE_RADII:
        for _ in range(ESCAPE_SAMPLES):
            y = x + radius * (upper - lower) * gen.uniform(-1.0, 1.0, x.size)
            if not fc.state_proven(y):  # also outside the limits: not proven
                continue
            if checker.edge_valid(x, y).ok:
                return y
            edges += 1
            if edges >= ESCAPE_EDGES:
                return None
    return None


def _branch(nodes: np.ndarray, parent: np.ndarray, leaf: int) -> np.ndarray:
    rows = []
    k = leaf
    while k >= 0:
        rows.append(nodes[k])
        k = int(parent[k])
    return np.array(rows)


def fast_shortcut(checker: MotionChecker, path: ArrayLike, *, seed: int = 0, tries: int | None = None) -> np.ndarray:
    """Random shortcutting of the cover-proven polyline ``path (M, n)`` on the compiled check (seeded;
    ``tries`` default: 16 and 2 per vertex; a try gaining less than :data:`SHORTCUT_GAIN` of the length is
    skipped), then every vertex dropped whose neighbours join."""
    fc = fast_check(checker)
    P = np.atleast_2d(np.asarray(path, dtype=float))
    if fc is None or P.shape[0] <= 2:
        return P.copy()
    k = int(tries) if tries is not None else 16 + 2 * P.shape[0]
    buf = np.zeros((P.shape[0] + k + 2, P.shape[1]))
    buf[: P.shape[0]] = P
    m = kernel.shortcut(buf, P.shape[0], _rng(seed + 1), k, SHORTCUT_GAIN, *fc.args)
    return buf[:m].copy()
