"""Time-jerk optimal timing: the weighted objective and seed 002's two stages.

Jerk cost of a timing ``h``: ``J(h) = sum_j integral_0^T qddd_j(t)^2 dt`` (rad^2/s^5 or
m^2/s^5), exact from the polynomial coefficients (Gauss-Legendre with enough nodes to be
exact for the squared jerk polynomial of every piece).

Two formulations:

- ``mode="weighted"`` (Gasparetto and Zanotto 2008): minimise ``k_T T + k_J J(h)``
  under the kinematic limits.
- ``mode="two-stage"`` (seed 002): first the minimum time T* (:func:`minimize_time`),
  then minimum J(h) under the limits with ``T <= time_factor * T*``.

``method="exact"`` runs SLSQP on the durations h (smooth objective, the peak of every
piece as its own constraint, the time cap as a linear constraint, forward-difference
gradients of all perturbed timings in one batched evaluation), started from the exact
time-optimal answer (weighted: the time-optimal timing; two-stage: T* scaled up to the
cap). For ratios r and total s, J = J1(r) s^-5 (J1 the cost at total 1), so the
two-stage optimum uses the whole allowed time (unless the upper bounds stop it). ``method="ga"`` runs the GA on h.

:func:`minimize_time_jerk` takes the same :class:`~pinarms.optim.timing.request.TimingRequest` as
:func:`minimize_time` (via points, limits, method, seed, GA settings) and the trade's own
options; bad input raises when the request is built or before any work, and no feasible
timing raises :class:`InfeasibleProblem` (:mod:`pinarms.optim.status`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from pinarms.planning.trajectory import Trajectory
from scipy.optimize import minimize

from pinarms.optim.ga.engine import GAHistory, run_ga
from pinarms.optim.ga.request import GARequest, random_generator
from pinarms.optim.errors import InfeasibleProblem, InvalidSettings
from pinarms.optim.timing.exact import solve_exact
from pinarms.optim.ga.problem import SAFETY, TimingProblem
from pinarms.optim.ga.settings import GASettings
from pinarms.optim.timing.request import TimingRequest
from pinarms.optim.timing.segments import minimize_time

__all__ = ["TimeJerkResult", "minimize_time_jerk", "jerk_integral", "jerk_integral_batch"]

MODES = ("weighted", "two-stage")


@dataclass(frozen=True)
class TimeJerkResult:
    """A verified time-jerk timing.

    Attributes:
        durations: (m,) segment durations (s).
        total: Their sum T (s).
        jerk_integral: Sum over joints of the integral of jerk^2 (unit^2/s^5).
        objective: ``k_T T + k_J J`` (weighted) or J (two-stage).
        trajectory, peaks: The planning trajectory and its exact peaks.
        mode, method: Formulation and optimiser.
        time_optimal_total: T* of stage one (two-stage), else None.
        time_factor: Allowed T / T* (two-stage), else None.
        k_time, k_jerk: Weights (weighted), else None.
        history: GA history (None for exact).
        evaluations: Trajectories evaluated; wall_time: seconds.
    """

    durations: np.ndarray
    total: float
    jerk_integral: float
    objective: float
    trajectory: Any
    peaks: Any
    mode: str
    method: str
    time_optimal_total: float | None
    time_factor: float | None
    k_time: float | None
    k_jerk: float | None
    history: GAHistory | None
    evaluations: int
    wall_time: float


def _gauss_legendre(width: int) -> tuple[np.ndarray, np.ndarray]:
    nodes, weights = np.polynomial.legendre.leggauss(max(width, 1))
    return 0.5 * (nodes + 1.0), 0.5 * weights  # on [0, 1]


def jerk_integral(trajectory: Trajectory) -> float:
    """Sum over joints of the exact integral of jerk^2 over the trajectory."""
    return float(_jerk_integrals(np.asarray(trajectory.coefficients, dtype=float)[None],
                                 np.diff(np.asarray(trajectory.knot_times, dtype=float))[None])[0])


def _jerk_integrals(coefs: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """coefs (P, m, K+1, n) in local time tau, seg (P, m) -> (P,) sum_j int jerk^2."""
    width = coefs.shape[2]
    if width < 4:
        return np.zeros(coefs.shape[0])
    k = np.arange(3, width)
    falling = k * (k - 1) * (k - 2)
    jerk = coefs[:, :, 3:, :] * falling[None, None, :, None]  # coefficient of tau^(k-3)
    u, w = _gauss_legendre(width - 3)
    tau = u[None, None, :] * seg[:, :, None]  # (P, m, g)
    powers = tau[..., None] ** np.arange(width - 3)  # (P, m, g, D+1)
    values = np.einsum("pmgd,pmdn->pmgn", powers, jerk)
    return np.einsum("pmgn,g,pm->p", values**2, w, seg)


def jerk_integral_batch(problem: TimingProblem, population: np.ndarray) -> np.ndarray:
    """J(h) for a population of durations (pop, m) -> (pop,)."""
    times, coefs = problem.coefficients_batch(population)
    return _jerk_integrals(coefs, np.diff(times, axis=1))


def _interval(problem: TimingProblem, r: np.ndarray) -> tuple[float, float]:
    """Feasible totals [s_min, s_max] for ratios r (limits and bounds)."""
    s_min = problem.minimal_scale(r) * (1.0 + SAFETY)
    s_min = max(s_min, float(np.max(problem.bounds[:, 0] / r)))
    s_max = float(np.min(problem.bounds[:, 1] / r))
    return s_min, s_max


def _slsqp_time_jerk(problem: TimingProblem, mode: str, cap: float | None, k_time: float,
                     k_jerk: float, start: np.ndarray) -> np.ndarray:
    """SLSQP on the durations: smooth objective (J or k_T T + k_J J), per-piece limit
    constraints and the time cap; forward-difference gradients in one batched call."""
    lo, hi = problem.bounds[:, 0], problem.bounds[:, 1]
    m = problem.n_segments
    cache: dict[bytes, tuple] = {}
    scale = [1.0]

    def evaluate(h: np.ndarray) -> tuple:
        key = np.asarray(h, dtype=float).tobytes()
        if key not in cache:
            step = 1e-7 * np.maximum(np.abs(h), 1e-3)
            trial = np.vstack([h, h + np.diag(step)])
            ratios = problem.piece_limit_ratios_batch(trial)
            j = jerk_integral_batch(problem, trial)
            f = j if mode == "two-stage" else k_time * trial.sum(axis=1) + k_jerk * j
            c = 1.0 - ratios * (1.0 + 1e-7)  # margin: SLSQP ends on the limits
            cache.clear()
            cache[key] = (f[0] / scale[0], (f[1:] - f[0]) / step / scale[0], c[0],
                          ((c[1:] - c[0]) / step[:, None]).T)
        return cache[key]

    cons = [{"type": "ineq", "fun": lambda h: evaluate(h)[2], "jac": lambda h: evaluate(h)[3]}]
    if mode == "two-stage":
        cons.append({"type": "ineq", "fun": lambda h: np.array([1.0 - 1e-9 - h.sum() / cap]),
                     "jac": lambda h: -np.ones((1, m)) / cap})
        h0 = start * (cap / start.sum()) / (1.0 + 1e-9)
    else:
        h0 = start
    # The objective is divided by its value at h0 so that SLSQP's tolerances are relative.
    scale[0] = max(abs(evaluate(h0)[0]), 1e-300)
    cache.clear()
    res = minimize(lambda h: evaluate(h)[0], h0, jac=lambda h: evaluate(h)[1], method="SLSQP",
                   bounds=list(zip(lo, hi)), constraints=cons,
                   options={"maxiter": 200, "ftol": 1e-12})
    h = np.clip(np.asarray(res.x, dtype=float), lo, hi)
    if not problem.is_feasible(h) or (cap is not None and h.sum() > cap):
        # Round-off at the active limits: shrink the violation by scaling up within the cap.
        r = h / h.sum()
        s_min, s_max = _interval(problem, r)
        s = max(s_min, min(h.sum(), s_max)) if cap is None else min(max(s_min, h.sum()), cap)
        h = r * s
    return h


def minimize_time_jerk(request: TimingRequest, *, mode: str = "two-stage", k_time: float = 1.0,
                       k_jerk: float = 1.0, time_factor: float = 1.05) -> TimeJerkResult:
    """Timing that trades total time against the jerk integral.

    Args:
        request: the via points, limits, bounds (or prebuilt problem), ``method`` (``"ga"``, or
            ``"exact"``: SLSQP from the exact time-optimal timing), ``seed``, ``settings``
            (default :meth:`GASettings.seed002`), ``max_generations`` and ``time_limit`` of
            :class:`TimingRequest`; stage one of the two-stage mode uses the same method and seed.
            Its other GA options (``stall_generations``, ``rescale``, ``polish``, ``initial``)
            are not used here.
        mode: ``"two-stage"`` (seed 002: time-optimal first, then minimum jerk with
            ``T <= time_factor * T*``) or ``"weighted"`` (min ``k_time T + k_jerk J``).
        k_time: Weight of the total time (1/s units of the objective).
        k_jerk: Weight of the jerk integral (objective units per unit^2/s^5).
        time_factor: Two-stage: allowed total over the time-optimal total (>= 1).

    Raises:
        InvalidSettings: a bad mode, weights or time factor.
        InfeasibleProblem: no timing meets the limits (and the time cap).
    """
    method, seed = request.method, request.seed
    max_generations, time_limit = request.max_generations, request.time_limit
    t0 = time.perf_counter()
    _check_options(mode, method, seed, time_factor, k_time, k_jerk)
    problem = request.problem
    before = problem.evaluations
    settings = GASettings.seed002() if request.settings is None else request.settings
    t_star = None
    history = None
    if mode == "two-stage":
        first = minimize_time(TimingRequest(method=method, seed=seed, settings=settings,
                                            max_generations=max_generations, time_limit=time_limit, problem=problem))
        t_star = first.total
        cap = time_factor * t_star
        start = first.durations
    else:
        cap = None
        start = solve_exact(problem).durations if method == "exact" else None

    if method == "exact":
        h = _slsqp_time_jerk(problem, mode, cap, k_time, k_jerk, start)
    else:
        h, history = _ga_time_jerk(problem, mode, cap, start, k_time, k_jerk, settings, seed,
                                   max_generations, time_limit)

    if not problem.is_feasible(h) or (cap is not None and h.sum() > cap * (1 + 1e-12)):
        raise InfeasibleProblem(f"no feasible time-jerk timing found ({mode}, {method}): "
                                f"{np.round(h, 6).tolist()} s breaks a limit or the time cap")
    traj = problem.trajectory(h)
    J = jerk_integral(traj)
    T = float(h.sum())
    objective_value = J if mode == "two-stage" else k_time * T + k_jerk * J
    return TimeJerkResult(durations=h, total=T, jerk_integral=J, objective=objective_value,
                          trajectory=traj, peaks=traj.peaks(), mode=mode, method=method,
                          time_optimal_total=t_star,
                          time_factor=time_factor if mode == "two-stage" else None,
                          k_time=k_time if mode == "weighted" else None,
                          k_jerk=k_jerk if mode == "weighted" else None, history=history,
                          evaluations=problem.evaluations - before,
                          wall_time=time.perf_counter() - t0)


def _check_options(mode: str, method: str, seed: int, time_factor: float, k_time: float, k_jerk: float) -> None:
    """Refuse bad options of :func:`minimize_time_jerk` (InvalidSettings naming them) before any work."""
    if mode not in MODES:
        raise InvalidSettings(f"mode={mode!r}: use one of {MODES}")
    if method not in ("ga", "exact"):
        raise InvalidSettings(f"method={method!r}: use 'ga' or 'exact'")
    random_generator(seed)  # refuse a bad seed before any work
    def number(value: Any) -> bool:
        return isinstance(value, (int, float, np.number)) and not isinstance(value, bool) \
            and bool(np.isfinite(value))

    if mode == "two-stage" and not (number(time_factor) and time_factor >= 1.0):
        raise InvalidSettings(f"time_factor={time_factor!r}: use a finite value >= 1")
    if mode == "weighted" and not (number(k_time) and number(k_jerk) and k_time >= 0.0
                                   and k_jerk >= 0.0 and k_time + k_jerk > 0.0):
        raise InvalidSettings(f"k_time={k_time!r}, k_jerk={k_jerk!r}: use weights >= 0, "
                              "not both zero")


def _ga_time_jerk(problem: TimingProblem, mode: str, cap: float | None, start: np.ndarray | None, k_time: float,
                  k_jerk: float, settings: GASettings, seed: int, max_generations: int | None,
                  time_limit: float | None) -> tuple[np.ndarray, Any]:
    """The GA on the durations: the jerk integral under the time cap (two-stage, started from the
    time-optimal ``start``) or ``k_T T + k_J J`` (weighted); its best durations and history."""
    lo, hi = problem.bounds[:, 0], problem.bounds[:, 1]
    if mode == "two-stage":
        objective = lambda H: jerk_integral_batch(problem, H)

        def constraints(H: np.ndarray) -> np.ndarray:
            return np.column_stack([problem.constraints(H), H.sum(axis=1) / cap - 1.0])

        initial = start[None]
    else:
        objective = lambda H: k_time * H.sum(axis=1) + k_jerk * jerk_integral_batch(problem, H)
        constraints = problem.constraints
        initial = None
    res = run_ga(GARequest(objective, np.column_stack([lo, hi]), settings, constraints=constraints,
                           seed=seed, max_generations=max_generations, time_limit=time_limit, initial=initial))
    if not res.feasible:
        raise InfeasibleProblem("the GA found no timing within the bounds that meets the "
                                f"limits{' and the time cap' if cap else ''}; widen the "
                                "bounds or relax the limits")
    return res.x, res.history
