"""Minimum-time segment timing of a trajectory through via points: GA or exact.

``minimize_time`` is the user-facing entry: it builds a :class:`~pinarms.optim.ga.problem.TimingProblem`,
solves it with the GA of this package (``method="ga"``) or with the deterministic
scaling-law optimiser (``method="exact"``), verifies the answer with planning's exact
peaks, and never returns an infeasible timing (it raises :class:`InfeasibleProblem`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from pinarms.optim.ga.engine import GAHistory, GAProgress, random_generator, run_ga
from pinarms.optim.caps import MAX_GENERATIONS
from pinarms.optim.errors import InfeasibleProblem, InvalidSettings, SettingOutOfRange
from pinarms.optim.timing.exact import polish_durations, scaled_to_limits, solve_exact, start_ratios
from pinarms.optim.ga.problem import SAFETY, TimingProblem
from pinarms.optim.ga.settings import GASettings

__all__ = ["TimingResult", "minimize_time", "finish_timing", "rescale_to_limits"]

METHODS = ("ga", "exact")


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
                        torque_limit=None if torque is None else torque.limit.copy())


def _infeasible(problem: TimingProblem, method: str) -> InfeasibleProblem:
    b = problem.bounds
    return InfeasibleProblem(
        f"no timing within the duration bounds meets the limits ({method}): segment bounds "
        f"{np.round(b, 6).tolist()} s allow at most {b[:, 1].sum():.6g} s in all; raise the "
        "upper bounds or relax vmax/amax/jmax")


def minimize_time(positions: Any, kind: str, vmax: Any, amax: Any = None, jmax: Any = None,
                  method: str = "ga", seed: int = 0, settings: GASettings | None = None,
                  bounds: Any = None, *, max_generations: int | None = None,
                  stall_generations: int | None = None, time_limit: float | None = None,
                  rescale: bool = True, polish: bool = False, initial: Any = None,
                  callback: Callable[[GAProgress], bool | None] | None = None,
                  trajectory_options: dict[str, Any] | None = None,
                  problem: TimingProblem | None = None, robot: Any = None, payload: Any = None,
                  torque_limits: Any = False, torque_samples: int | None = None) -> TimingResult:
    """Shortest segment durations through via points under per-joint limits.

    Minimises ``T = h_1 + ... + h_m`` subject to max|velocity| <= vmax, and optionally
    max|acceleration| <= amax and max|jerk| <= jmax, for every joint over the whole
    trajectory (exact peaks), with the same durations for all joints.

    Args:
        positions: (m+1, n_joints) or (m+1,) via points (rad or m).
        kind: ``"3-5-3"`` (exactly 4 via points), ``"multi-quintic"`` or ``"quintic-bspline"``.
        vmax, amax, jmax: Limits per joint (scalar or (n_joints,)), SI (rad/s, rad/s^2,
            rad/s^3 or m/...). ``vmax`` is required; None leaves a limit out.
        method: ``"ga"`` (the GA of this package) or ``"exact"`` (scaling-law optimiser).
        seed: Seed of the GA (or of the exact optimiser's random starts).
        settings: GA settings (default :meth:`GASettings.seed002`).
        bounds: Segment-duration bounds (s): one (lower, upper) pair or (m, 2) rows.
            Default: ``[s0 / (20 m), 1.001 min(s0, 4 s0 / m)]`` per segment, s0 the minimal
            total with equal durations (so equal durations s0/m are inside and feasible).
            Pass wider bounds if one segment may need more than 4x the average.
        max_generations, stall_generations, time_limit: GA stopping rules (``max_generations``
            1 to :data:`pinarms.optim.caps.MAX_GENERATIONS`, else ``SettingOutOfRange``).
        rescale: GA only: scale the GA's best (same ratios) down until the first limit is
            reached; the unscaled total is kept in ``raw_total``.
        polish: GA only: refine the GA's (rescaled) answer by a local gradient method
            (SLSQP from it, :func:`pinarms.optim.timing.exact.polish_durations`) and keep the better of
            the two; the result's method is then ``"ga+polish"`` and the GA's own total is
            kept in ``unpolished_total``. Off by default: the default answer is the GA's.
        initial: GA only: (k, m) durations put into the initial population (e.g. the
            paper's initial times).
        callback: GA progress callback (see :func:`pinarms.optim.run_ga`).
        trajectory_options: Extra keyword arguments of the planning constructor.
        problem: A prebuilt :class:`TimingProblem` (then positions/kind/limits/bounds
            are ignored).
        robot: The arm (a :class:`pinarms.robots.Robot`) whose joints the via points are; needed
            for torque limits.
        payload: What the tcp carries: a mass [kg], a :class:`pinarms.robots.Payload` or its dict
            form (``robot.with_payload``); only with ``torque_limits``.
        torque_limits: ``True``: also limit every joint's torque to the URDF's ``effort``
            (``robot.effort_limit``, N·m or N); or limits per joint; ``False``: kinematic
            limits only. The torques (inverse dynamics of the robot with its payload) are
            checked on ``torque_samples`` instants per piece (default 48) with their own
            scaling law (:mod:`pinarms.optim.torque`), and the answer is finally stretched onto the
            refined torque peaks, so it is feasible when re-checked densely. A torque-limited
            timing is never shorter than the kinematic one.
        torque_samples: Grid instants per polynomial piece for the torque constraint.

    Returns:
        :class:`TimingResult`, verified against the limits.

    Raises:
        InvalidLimits: A limit is <= 0, NaN/inf or has the wrong shape.
        InvalidSettings: torque limits without a robot, a payload without torque limits.
        InfeasibleProblem: No timing within the bounds meets the limits (also: the arm
            cannot hold a via point still with its payload).
    """
    t0 = time.perf_counter()
    if max_generations is not None and not (isinstance(max_generations, (int, np.integer))
                                            and not isinstance(max_generations, bool)
                                            and 1 <= max_generations <= MAX_GENERATIONS):
        raise SettingOutOfRange(f"max_generations = {max_generations!r} is outside 1 to {MAX_GENERATIONS:,} "
                                "(the generations of the timing GA)")
    problem = _timing_problem(method, seed, problem, robot, torque_limits, payload, torque_samples,
                              positions=positions, kind=kind, vmax=vmax, amax=amax, jmax=jmax, bounds=bounds,
                              trajectory_options=trajectory_options)
    before = problem.evaluations
    if method == "exact":
        return _exact_timing(problem, seed, before, t0)
    return _ga_timing(problem, seed, settings, before, t0, max_generations=max_generations,
                      stall_generations=stall_generations, time_limit=time_limit, callback=callback,
                      initial=initial, rescale=rescale, polish=polish)


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
    result = run_ga(lambda h: h.sum(axis=1), problem.bounds, settings,
                    constraints=problem.constraints, seed=seed,
                    max_generations=max_generations, stall_generations=stall_generations,
                    time_limit=time_limit, callback=callback,
                    initial=_scaling_law_starts(problem, seed) if initial is None else initial)
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


def _timing_problem(method: str, seed: int, problem: TimingProblem | None, robot: Any, torque_limits: Any,
                    payload: Any, torque_samples: int | None, **spec: Any) -> TimingProblem:
    """The problem :func:`minimize_time` solves: ``problem`` itself, or built from ``spec`` (positions,
    kind, limits, bounds, trajectory options) with the torque constraint; bad settings refused first."""
    if method not in METHODS:
        raise InvalidSettings(f"method={method!r}: use one of {METHODS}")
    random_generator(seed)  # refuse a bad seed before any work, for both methods
    from pinarms.optim.torque import torque_constraint

    torque = torque_constraint(robot, torque_limits, payload, torque_samples)
    if problem is None:
        return TimingProblem(spec["positions"], spec["kind"], spec["vmax"], spec["amax"], spec["jmax"],
                             bounds=spec["bounds"], trajectory_options=spec["trajectory_options"], torque=torque)
    if torque is not None:
        raise InvalidSettings("give torque limits either in the prebuilt problem (TimingProblem(torque=...)) "
                              "or as keywords, not both")
    return problem


def _scaling_law_starts(problem: TimingProblem, seed: int) -> np.ndarray | None:
    """Feasible, informed GA individuals (seed 002 starts from feasible timings): the scaling-law
    starts (equal ratios, ratios from the segment lengths) at s*(r); None when none is feasible."""
    starts = [scaled_to_limits(problem, r) for r in start_ratios(problem, 0, seed)[:3]]
    rows = [h for h, ok in starts if ok and np.all(h >= problem.bounds[:, 0])]
    return np.array(rows) if rows else None
