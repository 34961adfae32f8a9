"""Clearance of planned picks from the cell's fixtures (and between neighbours), proven.

A pick is a timed joint trajectory (:attr:`~.tracking.PickPlan.trajectory`: approach, tracking
dwell, lift, leave or transfer, place, return). Two routes prove it keeps a clearance ``c``:

- **fast** (:func:`pinarms.optim.motion.fast_check`, compiled, on the sphere cover): the trajectory is
  sampled at its knots and on a uniform time grid of step ``h``; between two samples each joint
  leaves its chord by at most ``a_j h² / 8`` (``a_j`` its exact acceleration peak, the samples
  including every knot so that each interval is one polynomial piece), so every point of the arm
  stays within ``Σ_j ℓ_j a_j h² / 8 ≤ chord`` of the polyline's (``ℓ_j`` the joint levers of the
  checker). The polyline proven at ``c + chord`` proves the trajectory at ``c``.
- **exact** where the fast route does not prove (or the cover is not tight for the cell):
  :meth:`pinarms.optim.motion.MotionChecker.trajectory_valid` (one arm against the fixtures) or
  :meth:`pinarms.robots.cell.Cell.check_motion` (two arms), continuous in time (coal where the cover
  is inconclusive).

:class:`FixtureCheck` holds one arm against the fixtures (``cell.with_pairs("arm-fixture")``);
:class:`PairCheck` two arms' picks over the time both move against each other and the fixtures
(``"external"`` pairs), used by :class:`~.neighbours.NeighbourGuard`.
"""

from __future__ import annotations

import math
import time
from typing import Any, TYPE_CHECKING

import numpy as np

from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.optim.line.station import Station
    from pinarms.robots.cell.cell import Cell

__all__ = ["FixtureCheck", "PairCheck", "CHORD", "chord_polyline", "fixture_check", "check_in_cell"]

#: Largest distance [m] between a sampled trajectory and its polyline that the fast route allows.
CHORD = 0.003
#: Longest slice [s] of two neighbours' shared time that :class:`PairCheck` proves on its own.
SLICE = 0.25
#: Fewest polynomial pieces of a trajectory the fast route halves a run it cannot prove down to.
PIECES = 16


def _clearance(value: Any) -> float:
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    if not ok or not math.isfinite(float(value)) or float(value) <= 0.0:
        raise InvalidInput(f"clearance to the fixtures must be a finite length > 0 [m], got {value!r}")
    return float(value)


def chord_polyline(trajectories: list, levers: np.ndarray, chord: float = CHORD,
                   span: tuple[float, float] | None = None, times: bool = False, cuts: Any = ()) -> Any:
    """Samples ``(M, n)`` of the joint trajectories played together (their joints side by side, all
    on one clock from ``span`` = (t0, t1), default their common range), at every knot and on a grid
    fine enough that the motion stays within ``chord`` [m] of the polyline (module doc); with
    ``times`` also the sample instants ``(M,)``; ``cuts``: more instants to sample."""
    t0 = max(float(tr.start_time) for tr in trajectories) if span is None else float(span[0])
    t1 = min(float(tr.end_time) for tr in trajectories) if span is None else float(span[1])
    acc = np.concatenate([np.asarray(tr.peaks().acceleration, float) for tr in trajectories])
    bend = float(acc @ np.asarray(levers, float))
    h = t1 - t0 if bend <= 0.0 else math.sqrt(8.0 * chord / bend)
    n = max(1, int(math.ceil((t1 - t0) / h)))
    knots = np.concatenate([np.asarray(tr.knot_times, float) for tr in trajectories])
    t = np.unique(np.concatenate([np.linspace(t0, t1, n + 1), knots[(knots >= t0) & (knots <= t1)],
                                  np.asarray(cuts, float)]))
    P = np.hstack([np.asarray(tr.sample(t)[0], float).reshape(t.size, -1) for tr in trajectories])
    return (P, t) if times else P


class FixtureCheck:
    """Whether one arm's planned motions keep ``clearance`` [m] from the cell's fixtures (module doc).
    ``counts``: trajectories proven by the fast route alone, runs of pieces sent to the exact one,
    trajectories found not clear, and outside the joint limits (:meth:`verdict`)."""

    def __init__(self, cell: Cell, arm: str, clearance: float, chord: float = CHORD) -> None:
        from pinarms.optim.motion import MotionChecker, fast_check

        self.clearance, self.chord = _clearance(clearance), float(chord)
        view = cell.with_pairs("arm-fixture")
        self.exact = MotionChecker(view, [arm], margin=self.clearance)
        self._wide = MotionChecker(view, [arm], margin=self.clearance + self.chord, step=self.clearance)
        self.fast = fast_check(self._wide)
        self.counts = {"fast": 0, "exact": 0, "blocked": 0, "limits": 0}
        self.seconds = 0.0  #: time spent in :meth:`verdict` [s]

    def verdict(self, trajectory: Trajectory) -> str:
        """``"clear"``, ``"limits"`` (the trajectory leaves the arm's joint position limits: exact
        extrema; the checkers count such states as not valid) or ``"fixtures"`` (closer than the
        clearance to a fixture somewhere)."""
        start = time.perf_counter()
        try:
            lo, hi = trajectory.position_range()
            if np.any(lo < self.exact.lower - 1e-9) or np.any(hi > self.exact.upper + 1e-9):
                self.counts["limits"] += 1
                return "limits"
            return "clear" if self.clear(trajectory) else "fixtures"
        finally:
            self.seconds += time.perf_counter() - start

    def clear(self, trajectory: Trajectory) -> bool:
        """Whether the arm's joint ``trajectory`` keeps the clearance from every fixture over its whole time
        (and stays within the joint limits): each polynomial piece the fast route proves is clear; each run
        of pieces it does not prove goes to the exact check (a pick comes close to a fixture mostly while it
        is in its box)."""
        from pinarms.planning import Trajectory

        knots = np.asarray(trajectory.knot_times, float)
        proven = np.zeros(knots.size - 1, bool)
        if self.fast is not None:
            P, t = chord_polyline([trajectory], self._wide.levers, self.chord, times=True)
            at = np.searchsorted(t, knots)  # the samples include every knot
            todo = [(0, knots.size - 1)]
            while todo:  # runs of pieces, halved until proven or short
                i, j = todo.pop()
                if self.fast.path_proven(P[at[i]: at[j] + 1]):
                    proven[i:j] = True
                elif j - i > PIECES:
                    todo += [(i, (i + j) // 2), ((i + j) // 2, j)]
        if proven.all():
            self.counts["fast"] += 1
            return True
        C = trajectory.coefficients
        bad = np.flatnonzero(~proven)
        runs = np.split(bad, np.flatnonzero(np.diff(bad) > 1) + 1)
        for run in runs:
            i, j = int(run[0]), int(run[-1]) + 1
            self.counts["exact"] += 1
            if not self.exact.trajectory_valid(Trajectory(knots[i: j + 1], C[i:j]), 0.0).ok:
                self.counts["blocked"] += 1
                return False
        return True


_CHECKS: dict = {}


def check_in_cell(cell: Cell, station: Station) -> None:
    """InvalidInput unless ``station`` is an arm of ``cell`` (same name, same base)."""
    from pinarms.errors import PinarmsError

    try:
        arm = cell.arm(station.name)
    except PinarmsError:
        raise InvalidInput(f"station {station.name!r} is not an arm of cell {cell.name!r}: give the cell whose "
                           f"arms are the stations") from None
    if np.abs(arm.base_to_world - station.base_to_world).max() > 1e-9:
        raise InvalidInput(f"station {station.name!r} stands elsewhere than the cell's arm of that name")


def fixture_check(cell: Cell, arm: str, clearance: float) -> FixtureCheck:
    """The :class:`FixtureCheck` of ``arm`` in ``cell`` at ``clearance``, kept per process (the
    checkers' covers and coal data take tens of ms to build; a map builds one per column)."""
    key = (id(cell), arm, float(clearance))
    got = _CHECKS.get(key)
    if got is None or got[0] is not cell:
        if len(_CHECKS) > 32:
            _CHECKS.clear()
        got = _CHECKS[key] = (cell, FixtureCheck(cell, arm, clearance))
    return got[1]


class PairCheck:
    """Whether two arms' picks, each on the cell's clock, keep ``clearance`` [m] from each other and
    the fixtures over a time window (module doc); ``counts``: windows proven by the fast route alone,
    slices sent to the exact check, windows found not clear."""

    def __init__(self, cell: Cell, arms: tuple[str, str], clearance: float, chord: float = CHORD) -> None:
        from pinarms.optim.motion import MotionChecker, fast_check

        self.cell, self.arms = cell, tuple(arms)
        self.clearance, self.chord = float(clearance), float(chord)
        self.fast = None
        if self.clearance > 0.0:
            self._wide = MotionChecker(cell.with_pairs("external"), list(self.arms), margin=self.clearance + self.chord,
                                       step=self.clearance)
            self.fast = fast_check(self._wide)
        self.counts = {"fast": 0, "exact": 0, "blocked": 0}

    def clear(self, motions: list, window: tuple[float, float], margin: float) -> bool:
        """``motions``: the two arms' :class:`pinarms.robots.cell.ArmMotion` (in the order of ``arms``);
        proven over cell times ``window``; ``margin`` [m]: the exact check's time step. The window is
        cut into slices of at most :data:`SLICE` s: those the fast route proves are clear, the others go
        to the exact check one by one (the first not clear ends it)."""
        t0, t1 = float(window[0]), float(window[1])
        cuts = np.linspace(t0, t1, max(1, int(math.ceil((t1 - t0) / SLICE))) + 1)
        todo = list(zip(cuts[:-1], cuts[1:]))
        if self.fast is not None:
            shifted = [m.trajectory.shifted(m.offset) for m in motions]
            P, t = chord_polyline(shifted, self._wide.levers, self.chord, (t0, t1), times=True, cuts=cuts)
            at = np.searchsorted(t, cuts)  # the samples include every cut
            todo = [(a, b) for k, (a, b) in enumerate(todo) if not self.fast.path_proven(P[at[k]: at[k + 1] + 1])]
            if not todo:
                self.counts["fast"] += 1
                return True
        for a, b in todo:
            self.counts["exact"] += 1
            res = self.cell.check_motion(motions, margin=margin, clearance=self.clearance, window=(a, b))
            if not bool(res.clear if self.clearance > 0 else res.collision_free):
                self.counts["blocked"] += 1
                return False
        return True
