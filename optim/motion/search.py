"""The search itself: OMPL's planners on a :class:`MotionChecker`, seeded, with its path shortcut.

OMPL (the Open Motion Planning Library, ``ompl`` on PyPI) samples and connects states; it
knows nothing of the cell. pinarms gives it:

- the state space: a box of the planned joints' limits (plus the time for a plan around a
  moving arm), Euclidean distance (time scaled by :data:`TIME_WEIGHT` rad/s);
- the state validity checker: :meth:`MotionChecker.state_valid`;
- the motion validator: :meth:`MotionChecker.edge_valid` — every edge OMPL adds to a tree or
  a shortcut is proven continuously, as one batch (OMPL's own validator would check
  states at a fixed joint-space resolution, the rule pyroboplan uses too);
- the seed: OMPL's global generator is seeded before any OMPL object is made, and one
  search runs at a time in a process (a lock), so the same call gives the same path.

Shortcutting is OMPL's :class:`PathSimplifier` (``reduceVertices``, ``partialShortcutPath``
and ``ropeShortcutPath``,
repeated until a round shortens the path by less than 0.1 %), every new edge proven by the
same validator; it is seeded like the search (no time-based stop, so it is reproducible).
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Any, Callable, TYPE_CHECKING

import numpy as np

from pinarms.optim.errors import InvalidSettings

if TYPE_CHECKING:
    from pinarms.optim.motion.checker import MotionChecker

__all__ = ["PLANNERS", "SearchResult", "SearchSettings", "search", "shortcut"]

#: Planner names accepted by :func:`search` (OMPL classes of ``ompl.geometric``).
PLANNERS = {
    "rrtconnect": "RRTConnect",
    "rrt": "RRT",
    "rrtstar": "RRTstar",
    "informedrrtstar": "InformedRRTstar",
    "bitstar": "BITstar",
    "prm": "PRM",
    "prmstar": "PRMstar",
    "kpiece": "KPIECE1",
    "bkpiece": "BKPIECE1",
    "lbkpiece": "LBKPIECE1",
}
#: Planners that stop at their first solution (the others improve it until the time limit).
FIRST_SOLUTION = ("rrtconnect", "rrt", "kpiece", "bkpiece", "lbkpiece")

#: Weight of the time coordinate in the distance of a space-time search [rad per s].
TIME_WEIGHT = 1.0

_LOCK = threading.Lock()


@dataclass(frozen=True, eq=False)
class SearchResult:
    """One OMPL search: ``path (M, dim)`` (None when not found), states explored, seconds, planner."""

    path: np.ndarray | None
    states: int
    seconds: float
    planner: str
    goal_index: int
    status: str


def _ompl():
    try:
        from ompl import base as ob, geometric as og, util as ou
    except ImportError as exc:  # pragma: no cover - a dependency
        raise InvalidSettings("motion planning needs OMPL: pip install 'ompl>=2.0.1'") from exc
    ou.setLogLevel(ou.LOG_NONE)
    return ob, og, ou


def _validator_class(ob):
    class EdgeValidator(ob.MotionValidator):
        """OMPL motion validator backed by a :class:`MotionChecker` (continuous, batched)."""

        def __init__(self, si, checker, dim, reverse_ok=False):
            super().__init__(si)
            self.checker = checker
            self.dim = dim

        def checkMotion(self, s1, s2, *rest):  # noqa: N802 - OMPL's name
            a = np.fromiter((s1[i] for i in range(self.dim)), float, self.dim)
            b = np.fromiter((s2[i] for i in range(self.dim)), float, self.dim)
            return bool(self.checker.edge_valid(a, b).ok)

    return EdgeValidator


def _seed(seed: int) -> int:
    return int(seed) % 2_147_483_646 + 1  # OMPL refuses 0


def _state(si, x: np.ndarray):
    st = si.allocState()
    for i, v in enumerate(x):
        st[i] = float(v)
    return st


def _read(path, dim: int) -> np.ndarray:
    return np.array([[path.getState(k)[i] for i in range(dim)] for k in range(path.getStateCount())], dtype=float)


def _setup(ob, og, checker, lower, upper):
    dim = lower.size
    space = ob.RealVectorStateSpace(dim)
    bounds = ob.RealVectorBounds(dim)
    for i in range(dim):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()

    def valid(state) -> bool:
        return checker.state_valid(np.fromiter((state[i] for i in range(dim)), float, dim))

    ss.setStateValidityChecker(valid)
    validator = _validator_class(ob)(si, checker, dim)
    si.setMotionValidator(validator)
    return ss, si, validator, valid


@dataclass(frozen=True)
class SearchSettings:
    """How :func:`search` searches: the OMPL ``planner`` (a key of :data:`PLANNERS`), its ``time_limit`` [s]
    and ``seed``, the box of the state space (``lower``/``upper``, default the checker's joint limits), the
    planner's ``planner_range`` (its step; ``None``: OMPL's) and ``scale``: per-coordinate factors the search
    works in (the time coordinate of a space-time search), undone on the returned path.

    Raises:
        InvalidSettings: an unknown planner, a time limit that is not a finite positive number.
    """

    planner: str = "rrtconnect"
    time_limit: float = 1.0
    seed: int = 0
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None
    planner_range: float | None = None
    scale: np.ndarray | None = None

    def __post_init__(self) -> None:
        if str(self.planner).lower() not in PLANNERS:
            raise InvalidSettings(f"unknown planner {self.planner!r}; use one of {', '.join(PLANNERS)}")
        if not (np.isfinite(self.time_limit) and self.time_limit > 0.0):
            raise InvalidSettings(f"time_limit must be a finite positive number of seconds, got {self.time_limit!r}")


def search(checker: MotionChecker, start: np.ndarray, goals: np.ndarray, settings: SearchSettings = SearchSettings(),
           *, progress: Callable[[str], None] | None = None) -> SearchResult:
    """Search a path from ``start (dim,)`` to any of ``goals (G, dim)`` with OMPL (module docstring), as
    ``settings`` say (:class:`SearchSettings`)."""
    planner, time_limit, seed = settings.planner, settings.time_limit, settings.seed
    lower, upper, planner_range, scale = settings.lower, settings.upper, settings.planner_range, settings.scale
    key = str(planner).lower()
    ob, og, ou = _ompl()
    lo = np.asarray(checker.lower if lower is None else lower, dtype=float)
    hi = np.asarray(checker.upper if upper is None else upper, dtype=float)
    sc = np.ones(lo.size) if scale is None else np.asarray(scale, dtype=float)
    scaled = _Scaled(checker, sc)
    with _LOCK:
        ou.RNG.setSeed(_seed(seed))
        ss, si, validator, _ = _setup(ob, og, scaled, lo * sc, hi * sc)
        ss.setStartState(_state(si, np.asarray(start) * sc))
        goal = ob.GoalStates(si)
        for g in np.atleast_2d(goals):
            goal.addState(_state(si, g * sc))
        ss.setGoal(goal)
        plan = getattr(og, PLANNERS[key])(si)
        if planner_range is not None and hasattr(plan, "setRange"):
            plan.setRange(float(planner_range))
        ss.setPlanner(plan)
        if progress:
            progress(f"searching with {PLANNERS[key]} (at most {time_limit:g} s)")
        inner = getattr(checker, "checker", checker)
        if hasattr(inner, "warm"):
            inner.warm()
        t0 = time.perf_counter()
        if hasattr(inner, "deadline"):  # an edge proof cut short by the limit counts as not valid
            inner.deadline = t0 + float(time_limit)
        try:
            status = ss.solve(float(time_limit))
        finally:
            if hasattr(inner, "deadline"):
                inner.deadline = None
        seconds = time.perf_counter() - t0
        data = ob.PlannerData(si)
        ss.getPlannerData(data)
        states = int(data.numVertices())
        if not ss.haveExactSolutionPath():
            return SearchResult(None, states, seconds, PLANNERS[key], -1, str(status))
        path = _read(ss.getSolutionPath(), lo.size) / sc
        gi = int(np.argmin(np.linalg.norm(np.atleast_2d(goals) - path[-1], axis=1)))
        return SearchResult(path, states, seconds, PLANNERS[key], gi, str(status))


class _Scaled:
    """A checker seen through per-coordinate scale factors (OMPL works on ``x * scale``)."""

    def __init__(self, checker: Any, scale: np.ndarray) -> None:
        self.checker = checker
        self.scale = scale
        self.identity = bool(np.all(scale == 1.0))

    def state_valid(self, x: np.ndarray) -> bool:
        return self.checker.state_valid(x if self.identity else x / self.scale)

    def edge_valid(self, a: np.ndarray, b: np.ndarray):
        if self.identity:
            return self.checker.edge_valid(a, b)
        return self.checker.edge_valid(a / self.scale, b / self.scale)


def shortcut(checker: MotionChecker, path: np.ndarray, *, seed: int = 0, rounds: int = 10, scale: np.ndarray | None = None,
             lower: np.ndarray | None = None, upper: np.ndarray | None = None) -> np.ndarray:
    """OMPL's shortcutting of ``path (M, dim)`` under the checker's continuous edge proof (module docstring)."""
    ob, og, ou = _ompl()
    P = np.atleast_2d(np.asarray(path, dtype=float))
    if P.shape[0] <= 2:
        return P.copy()
    lo = np.asarray(checker.lower if lower is None else lower, dtype=float)
    hi = np.asarray(checker.upper if upper is None else upper, dtype=float)
    sc = np.ones(lo.size) if scale is None else np.asarray(scale, dtype=float)
    scaled = _Scaled(checker, sc)
    with _LOCK:
        ou.RNG.setSeed(_seed(seed))
        ss, si, validator, _ = _setup(ob, og, scaled, lo * sc, hi * sc)
        geo = og.PathGeometric(si)
        for x in P:
            geo.append(_state(si, x * sc))
        simp = og.PathSimplifier(si)
        length = geo.length()
        for _ in range(int(rounds)):
            simp.reduceVertices(geo)
            simp.partialShortcutPath(geo)
            simp.ropeShortcutPath(geo)
            new = geo.length()
            if new > length * (1.0 - 1e-3):
                length = new
                break
            length = new
        return _read(geo, lo.size) / sc
