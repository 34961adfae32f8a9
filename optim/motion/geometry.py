"""Steps 1–4 of :func:`.plan.plan_motion` for a checked start: goals, search, shortcut, smoothing.

The search runs first compiled (:mod:`.fast`: RRT-Connect whose states and edges the sphere
cover proves) for a share of the time limit (:data:`FAST_SHARE`) when the cover proves at
least half of the clear states (:func:`fast_share`), then — nothing found, or a planner other than
RRT-Connect, or arms moving on their own trajectories — OMPL with the exact checker for
the rest of the time, as before. A compiled path is shortcut on the compiled check; the
smooth spline reported is proven by :func:`.smoothing.prove_path` (the cover compiled first,
the exact checker on the ranges it leaves open), and a polyline with stops edge by edge by
the exact checker. A polyline the exact proof does not accept (the cover proves what coal
proves, so this does not happen in the tests) is dropped and OMPL searches.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from pinarms.optim.errors import NoPathFound
from pinarms.optim.motion.ends import goal_candidates
from pinarms.optim.motion.fast import fast_search, fast_shortcut
from pinarms.optim.motion.report import FAST_SIMPLIFIER, SIMPLIFIER
from pinarms.optim.motion.search import SearchSettings, search, shortcut
from pinarms.optim.motion.smoothing import smooth_path
from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.optim.motion.checker import MotionChecker
    from pinarms.optim.motion.request import MotionOptions

__all__ = ["plan_geometry", "find_path", "other_way", "fast_share", "travel_time_bound", "FAST_SHARE"]

#: Share of the time limit the compiled search may take when the cover proves at least half of the
#: clear random states (:attr:`MotionChecker.cover_share`); OMPL has the rest. Measured on
#: ``aubo_crate_guard`` (25 queries, 1 s): 13, 16 and 17 solved at shares 0.25, 0.5 and 0.75;
#: ``panda_shelf``: 24 at 0.5 and at 0.75 (every one compiled).
FAST_SHARE = 0.75


def fast_share(checker: MotionChecker, planner: str) -> float:
    """Share of the time limit given to the compiled search (0: OMPL alone; module docstring)."""
    if str(planner).lower() != "rrtconnect" or checker.cover is None or checker.timed:
        return 0.0
    return FAST_SHARE if checker.cover_share >= 0.5 else 0.0


def _exact(checker: Any, P: np.ndarray) -> bool:
    """Every edge of the polyline ``P`` proven by the exact checker."""
    return all(checker.edge_valid(P[i], P[i + 1]).ok for i in range(P.shape[0] - 1))


def travel_time_bound(P: np.ndarray, vmax: np.ndarray) -> float:
    """A lower bound [s] of the time to follow the polyline ``P (k, n)`` at joint speeds ``vmax (n,)``: each
    edge takes at least its slowest joint's travel at full speed."""
    P = np.asarray(P, dtype=float)
    if P.shape[0] < 2:
        return 0.0
    return float(np.sum(np.max(np.abs(np.diff(P, axis=0)) / vmax, axis=1)))


def _best_goal(checker: Any, x0: np.ndarray, G: np.ndarray, found: np.ndarray, vmax: np.ndarray, seed: int,
               limit: float) -> tuple[np.ndarray, int, int]:
    """The shortcut path to the goal branch whose path has the smallest :func:`travel_time_bound`: each other
    goal, in increasing order of its straight move's bound, is searched alone (compiled, ``limit`` seconds
    each, like the first search: the same seed gives the same path whatever the clock read before) while
    that bound is below the best path's (no later goal can beat it). Returns the path, the searches run and
    their states."""
    best, best_bound = found, travel_time_bound(found, vmax)
    straight = np.max(np.abs(G - x0) / vmax, axis=1)
    runs = states = 0
    for g in np.argsort(straight, kind="stable"):
        if straight[g] >= best_bound:
            break
        if np.array_equal(G[g], best[-1]):
            continue
        r = fast_search(checker, x0, G[g][None], time_limit=limit, seed=int(seed))
        runs, states = runs + 1, states + r.states
        if r.path is None:
            continue
        P = fast_shortcut(checker, r.path, seed=int(seed))
        bound = travel_time_bound(P, vmax)
        if bound < best_bound:
            best, best_bound = P, bound
    return best, runs, states


def find_path(checker: MotionChecker, x0: np.ndarray, G: np.ndarray, *, planner: str, time_limit: float, seed: int,
              compiled: bool = True, say: Callable[[str], None] = lambda _m: None,
              best_goal: np.ndarray | None = None) -> dict:
    """Search and shortcut (module docstring): a dict with ``result`` (:class:`.search.SearchResult`, its
    seconds and states those of both searches), ``simplified``, ``simplifier``, ``compiled`` (bool),
    ``seconds`` (``"search"``, ``"shortcut"``). ``NoPathFound`` when nothing is found in time.
    ``compiled=False``: OMPL alone. ``best_goal``: the planned joints' speed limits ``(n,)``: with several
    goal configurations, a compiled path is compared with paths searched to each other goal, each with
    the compiled search's share of the time limit (:func:`_best_goal`); ``None``: the first goal reached."""
    t0 = time.perf_counter()
    share = fast_share(checker, planner) if compiled else 0.0
    spent, states = 0.0, 0
    if share > 0.0:
        fast = fast_search(checker, x0, G, time_limit=share * float(time_limit), seed=int(seed))
        spent, states = fast.seconds, fast.states
        if fast.path is not None:
            say(f"path found compiled in {fast.seconds:.4f} s ({fast.states} states); shortcutting")
            t = time.perf_counter()
            simplified = fast_shortcut(checker, fast.path, seed=int(seed))
            if best_goal is not None and len(G) > 1:
                simplified, runs, more = _best_goal(checker, x0, G, simplified, np.asarray(best_goal, dtype=float),
                                                    int(seed), share * float(time_limit))
                say(f"{runs} other goal(s) searched ({more} states); the path with the shortest time bound kept")
            return {"result": fast, "simplified": simplified, "simplifier": FAST_SIMPLIFIER, "compiled": True,
                    "seconds": {"search": fast.seconds, "shortcut": time.perf_counter() - t}}
    rest = max(float(time_limit) - (time.perf_counter() - t0), 1e-3)
    result = search(checker, x0, G, SearchSettings(planner=planner, time_limit=rest, seed=int(seed)))
    seconds = {"search": spent + result.seconds}
    if result.path is None:
        raise NoPathFound(
            f"{result.planner} found no collision-free path in {float(time_limit):g} s ({result.states + states} "
            f"states explored, {len(G)} goal configuration(s), margin {checker.margin * 1e3:.1f} mm): raise "
            "time_limit, try another planner or seed, or lower the margin", planner=result.planner,
            time_limit=float(time_limit), seconds=spent + result.seconds, states=result.states + states, goals=len(G))
    say(f"path found by {result.planner} in {result.seconds:.3f} s ({result.states} states); shortcutting")
    t = time.perf_counter()
    simplified = shortcut(checker, result.path, seed=int(seed))
    seconds["shortcut"] = time.perf_counter() - t
    return {"result": result, "simplified": simplified, "simplifier": SIMPLIFIER, "compiled": False,
            "seconds": seconds}


def other_way(checker: MotionChecker, x0: np.ndarray, G: np.ndarray) -> np.ndarray | None:
    """The goals ``G (k, n)``, each with one continuous joint turned the other way round (its angle 2π farther
    from the start's, the same pose), one row per goal and joint that moves; ``None`` when none moves."""
    rows = []
    for g in np.atleast_2d(G):
        for j in np.flatnonzero(checker.continuous):
            d = g[j] - x0[j]
            if abs(d) > 1e-9:
                y = g.copy()
                y[j] -= 2.0 * np.pi * np.sign(d)
                rows.append(y)
    return np.array(rows) if rows else None


def plan_geometry(checker: MotionChecker, arms: tuple[str, ...], x0: np.ndarray, goal: np.ndarray,
                  options: MotionOptions, *, frame: str | None = None, say: Callable[[str], None] = lambda _m: None,
                  best_goal: np.ndarray | None = None, nearest: bool = True) -> dict:
    """Steps 1-4 of :func:`.plan.plan_motion` for a checked start: goals, search, shortcut, smoothing.

    ``options``: the planner, time limit, seed and ``compiled`` (``False``: OMPL alone) of
    :class:`.request.MotionOptions`. ``nearest``: continuous joints of the goal at the 2π equivalent
    nearest the start (:func:`.ends.goal_candidates`; ``False``: as given). Returns a dict: ``goals``,
    ``raw``, ``simplified``, ``path``, ``smoothing``, ``planner``, ``states``, ``seconds``, ``simplifier``,
    ``compiled``.
    """
    planner, time_limit, seed, compiled = options.planner, options.time_limit, options.seed, options.compiled
    t_start = time.perf_counter()
    cell = checker.cell
    goals = goal_candidates(checker, arms, goal, x0, int(seed), frame, nearest=nearest)
    G = np.array([g.q for g in goals if g.valid])
    same = np.flatnonzero(np.abs(G - x0).max(axis=1) <= 1e-9)
    if same.size:
        raise InvalidInput(f"the start already is the goal (joints {np.round(x0, 6).tolist()}): there is nothing to "
                           "plan; give a goal different from the start")
    say(f"{len(G)} clear goal configuration(s) of {len(goals)}; searching")
    robot = cell.arm(arms[0]).robot if len(arms) == 1 else None
    try:
        found = find_path(checker, x0, G, planner=planner, time_limit=time_limit, seed=seed, compiled=compiled,
                          say=say, best_goal=best_goal)
    except NoPathFound as short:
        G = other_way(checker, x0, G) if nearest else None
        if G is None:
            raise
        say(f"no path the short way; searching the other way round ({len(G)} goal configuration(s))")
        checker.span_turns(G)
        found = find_path(checker, x0, G, planner=planner, time_limit=time_limit, seed=seed, compiled=compiled,
                          say=say, best_goal=best_goal)
        found["seconds"]["search"] += float(short.seconds)  # both searches' time
    t = time.perf_counter()
    path, method, _ = smooth_path(checker, found["simplified"], robot)
    if found["compiled"] and method != "cubic spline" and not _exact(checker, found["simplified"]):
        # the polyline is reported: the exact checker must prove it too (else OMPL, as before)
        rest = max(float(time_limit) - (time.perf_counter() - t_start), 1e-3)
        found = find_path(checker, x0, G, planner=planner, time_limit=rest, seed=seed, compiled=False, say=say)
        path, method, _ = smooth_path(checker, found["simplified"], robot)
    seconds = dict(found["seconds"], smooth=time.perf_counter() - t)
    result = found["result"]
    return {"goals": goals, "raw": result.path, "simplified": found["simplified"], "path": path, "smoothing": method,
            "planner": result.planner, "states": result.states, "seconds": seconds,
            "simplifier": found["simplifier"], "compiled": found["compiled"]}
