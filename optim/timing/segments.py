"""Minimum-time segment timing of a trajectory through via points: GA or exact.

``minimize_time`` is the user-facing entry: it takes a :class:`~pinarms.optim.timing.request.TimingRequest`
(checked when built, with its :class:`~pinarms.optim.ga.problem.TimingProblem`), solves it with the GA
of this package (``method="ga"``) or with the deterministic scaling-law optimiser
(``method="exact"``), verifies the answer with planning's exact peaks, and returns a
:class:`TimingResult` whose ``status`` (:class:`TimingStatus`) says how the optimiser ended. It
never returns an infeasible timing: with none within the bounds it raises
:class:`InfeasibleProblem` (there is no trajectory to return; :mod:`pinarms.optim.status`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from pinarms.optim.errors import InfeasibleProblem
from pinarms.optim.ga.engine import GAHistory, GAProgress, run_ga
from pinarms.optim.ga.request import GARequest
from pinarms.optim.ga.problem import SAFETY, TimingProblem
from pinarms.optim.ga.settings import GASettings
from pinarms.optim.timing.exact import polish_durations, scaled_to_limits, solve_exact, start_ratios
from pinarms.optim.timing.request import METHODS, TimingRequest, TimingStatus

__all__ = ["TimingRequest", "TimingStatus", "TimingResult", "minimize_time", "finish_timing", "rescale_to_limits",
           "METHODS"]

_WHY = {TimingStatus.TIME_LIMIT: "the GA stopped at its time_limit: the timing is feasible but may not be the "
                                 "shortest; raise time_limit or use method='exact'",
        TimingStatus.CALLBACK: "the callback stopped the GA: the timing is its best so far (feasible, maybe not the "
                               "shortest)"}


@dataclass(frozen=True)
class TimingResult:
    """A verified timing.

    Attributes:
        durations: (m,) segment durations (s), shared by all joints.
        total: Their sum (s).
        trajectory: The planning trajectory with these durations.
        peaks: Its exact peaks (planning ``Peaks``: velocity, acceleration, jerk per joint).
        history: GA history per generation (None for ``method="exact"``).
        method: ``"ga"``, ``"ga+polish"`` (GA answer refined by the local polish),
            ``"exact"`` (or a two-stage label for time-jerk results).
        evaluations: Trajectories built and peaked by the optimiser.
        wall_time: Seconds spent.
        raw_total: GA: total of the GA's best individual before rescaling to the limits;
            exact: equal to ``total``.
        kind: Trajectory family.
        stop_reason: GA stop reason ("" for exact).
        unpolished_total: ``"ga+polish"``: total (s) of the GA's answer (rescaled onto the
            limits) before the local polish; None otherwise.
        torque_peaks: with torque limits, the refined per-joint torque peaks of
            ``trajectory`` (:class:`pinarms.planning.TorquePeaks`, N·m or N); None otherwise.
        torque_limit: the torque limits (n,) used [N·m or N], or None.
        status: how the optimiser ended (:class:`TimingStatus`: ``SOLVED`` for the exact
            solver, else the GA's stop reason); the timing is verified in every case.
        status_reason: for a GA stopped by its time limit or a callback, that its best may
            not be the shortest; ``""`` otherwise.
    """

    durations: np.ndarray
    total: float
    trajectory: Any
    peaks: Any
    history: GAHistory | None
    method: str
    evaluations: int
    wall_time: float
    raw_total: float
    kind: str
    stop_reason: str = ""
    unpolished_total: float | None = None
    torque_peaks: Any = None
    torque_limit: np.ndarray | None = None
    status: TimingStatus = TimingStatus.SOLVED
    status_reason: str = ""

    @property
    def torque_ratios(self) -> np.ndarray | None:
        """Refined torque peak / limit per joint (n,), or None without torque limits."""
        if self.torque_peaks is None:
            return None
        return self.torque_peaks.torque / self.torque_limit

    @property
    def knot_times(self) -> np.ndarray:
        """Knot times (m+1,) (s)."""
        return np.concatenate([[0.0], np.cumsum(self.durations)])


def rescale_to_limits(problem: TimingProblem, durations: np.ndarray) -> np.ndarray:
    """Scale feasible durations down (same ratios) until the first limit is reached.

    Keeps the lower bounds; never scales up past the given durations.
    """
    h = np.asarray(durations, dtype=float)
    s = h.sum()
    r = h / s
    s_new = problem.minimal_scale(r) * (1.0 + SAFETY)
    s_new = max(s_new, float(np.max(problem.bounds[:, 0] / r)))
    return r * min(s, s_new)


def finish_timing(problem: TimingProblem, durations: np.ndarray, *, method: str,
                  history: GAHistory | None, evaluations: int, t0: float,
                  raw_total: float, stop_reason: str = "",
                  unpolished_total: float | None = None) -> TimingResult:
    """Build the final trajectory, verify it with its exact peaks, wrap the result."""
    status = TimingStatus(stop_reason) if stop_reason else TimingStatus.SOLVED
    h = np.asarray(durations, dtype=float)
    torque = getattr(problem, "torque", None)
    if torque is not None:
        # the grid's torque peaks miss the true ones by a hair: stretch onto the refined peaks
        factor = torque.refined_scale(problem.trajectory(h))
        if not np.isfinite(factor):
            raise InfeasibleProblem(f"the {method} timing cannot meet the torque limits at any speed")
        h = h * factor
    if not problem.is_feasible(h):
        ratios = problem.limit_ratios(h)
        raise InfeasibleProblem(
            f"the {method} timing {np.round(h, 6).tolist()} s exceeds a limit (peak/limit up "
            f"to {ratios.max():.6g}): no feasible timing was found; widen the bounds")
    traj = problem.trajectory(h)
    tq_peaks = None if torque is None else traj.torque_peaks(torque.robot, torque.samples_per_piece)
    return TimingResult(durations=h, total=float(h.sum()), trajectory=traj, peaks=traj.peaks(),
                        history=history, method=method, evaluations=evaluations,
                        wall_time=time.perf_counter() - t0, raw_total=raw_total,
                        kind=problem.kind, stop_reason=stop_reason,
                        unpolished_total=unpolished_total, torque_peaks=tq_peaks,
                        torque_limit=None if torque is None else torque.limit.copy(), status=status,
                        status_reason=_WHY.get(status, ""))


def _infeasible(problem: TimingProblem, method: str) -> InfeasibleProblem:
    b = problem.bounds
    return InfeasibleProblem(
        f"no timing within the duration bounds meets the limits ({method}): segment bounds "
        f"{np.round(b, 6).tolist()} s allow at most {b[:, 1].sum():.6g} s in all; raise the "
        "upper bounds or relax vmax/amax/jmax")


def minimize_time(request: TimingRequest, *,
                  callback: Callable[[GAProgress], bool | None] | None = None) -> TimingResult:
    """Shortest segment durations through the request's via points under its limits.

    Args:
        request: what to time and how (:class:`TimingRequest`, checked when built).
        callback: GA progress callback (see :func:`pinarms.optim.run_ga`); returning True stops the GA
            (status :attr:`TimingStatus.CALLBACK`).

    Returns:
        :class:`TimingResult`, verified against the limits, with its ``status``.

    Raises:
        InfeasibleProblem: No timing within the bounds meets the limits.
    """
    t0 = time.perf_counter()
    rq = request
    problem = rq.problem
    before = problem.evaluations
    if rq.method == "exact":
        return _exact_timing(problem, rq.seed, before, t0)
    return _ga_timing(problem, rq.seed, rq.settings, before, t0, max_generations=rq.max_generations,
                      stall_generations=rq.stall_generations, time_limit=rq.time_limit, callback=callback,
                      initial=rq.initial, rescale=rq.rescale, polish=rq.polish)


def _exact_timing(problem: TimingProblem, seed: int, before: int, t0: float) -> TimingResult:
    """``method="exact"``: the exact solver's durations, verified (evaluations counted from ``before``)."""
    sol = solve_exact(problem, seed=seed)
    if not sol.feasible:
        raise _infeasible(problem, "exact")
    return finish_timing(problem, sol.durations, method="exact", history=None,
                         evaluations=problem.evaluations - before, t0=t0,
                         raw_total=sol.total)


def _ga_timing(problem: TimingProblem, seed: int, settings: GASettings | None, before: int, t0: float, *,
               max_generations: int | None, stall_generations: int | None, time_limit: float | None,
               callback: Callable[[GAProgress], bool | None] | None, initial: Any, rescale: bool,
               polish: bool) -> TimingResult:
    """``method="ga"``: the GA's best, rescaled onto the limits and polished if asked, verified."""
    settings = GASettings.seed002() if settings is None else settings
    request = GARequest(lambda h: h.sum(axis=1), problem.bounds, settings, constraints=problem.constraints,
                        seed=seed, max_generations=max_generations, stall_generations=stall_generations,
                        time_limit=time_limit,
                        initial=_scaling_law_starts(problem, seed) if initial is None else initial)
    result = run_ga(request, callback=callback)
    if not result.feasible:
        raise _infeasible(problem, "ga")
    h = rescale_to_limits(problem, result.x) if rescale else result.x
    label, unpolished = "ga", None
    if polish:
        refined, ok = polish_durations(problem, h)
        label, unpolished = "ga+polish", float(h.sum())
        if ok and refined.sum() < h.sum():
            h = refined
    return finish_timing(problem, h, method=label, history=result.history,
                         evaluations=problem.evaluations - before, t0=t0,
                         raw_total=float(result.f), stop_reason=result.stop_reason,
                         unpolished_total=unpolished)


def _scaling_law_starts(problem: TimingProblem, seed: int) -> np.ndarray | None:
    """Feasible, informed GA individuals (seed 002 starts from feasible timings): the scaling-law
    starts (equal ratios, ratios from the segment lengths) at s*(r); None when none is feasible."""
    starts = [scaled_to_limits(problem, r) for r in start_ratios(problem, 0, seed)[:3]]
    rows = [h for h, ok in starts if ok and np.all(h >= problem.bounds[:, 0])]
    return np.array(rows) if rows else None
