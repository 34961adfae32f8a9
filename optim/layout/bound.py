"""Branch and bound over the candidates of a layout search (``LayoutRequest(..., bound=True)``).

A candidate's cycle cannot be shorter than its **lower bound**: each (pick, place) pair's
cycle holds the dwell at the pick and at the place and moves the arm from its pick
configuration to its place configuration and back, and no joint moves faster than its
velocity limit, so

    T ≥ 2 · dwell + 2 · min over the IK solutions (a at the pick, b at the place) of max_j t_j(|b_j − a_j|)

whatever the trajectory family, the lift, the via points or the planned transfer (a joint
whose range spans a full turn is measured the short way round the circle). ``t_j(d)`` is the
shortest time joint j can travel ``d`` from rest to rest: ``d / v_j`` with a velocity limit
only; with an acceleration limit ``a_j`` too (``LayoutRequest(amax=)``: every move of the
cycle keeps it, each starting and ending at rest at the pick and the place) the bang-bang
time ``d / v_j + v_j / a_j`` when ``d ≥ v_j² / a_j`` (it reaches its top speed), else
``2 √(d / a_j)``. The bound of a
candidate is the mean over its pairs (its cycle time is their mean). It costs one batched
closed-form IK of the picks and places, already solved by the reach screen.

The candidates still in the running are planned in increasing order of their bound (ties by
index), in waves (one task at a time serially; a wave per round of a Dask client's
workers; one wave for the other schedulers, which start their workers per call). Before each
wave, a candidate whose bound exceeds the ``keep``-th shortest cycle planned so far by more
than :data:`SLACK` (relative) cannot reach the first ``keep`` places of the ranking: it and
every later one (their bounds are larger) are not planned and fail as ``"outranked"``. With
``keep`` = max(1, refine), the best candidate and the refinement starts are those of the
exhaustive search, and every candidate planned has the outcome it has there (its
evaluation does not depend on the others).

Only analytic-IK arms have a bound (0 otherwise: nothing is skipped).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pinarms.optim.types import JointLimit, Scheduler

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot

from pinarms.optim.layout.candidates import PPM_RTOL

__all__: list[str] = []  # search_layout's (bound=True)

#: A candidate is skipped only when its bound exceeds the ``keep``-th best cycle by more than this
#: (relative): ties of the ranking (1e-9 relative in picks/min) are always planned.
SLACK = 8.0 * PPM_RTOL


def _travel(a: np.ndarray, b: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """``|b − a|`` per joint ``(..., n)``, the short way round for a joint whose range spans a turn."""
    d = np.abs(b - a)
    turn = (upper - lower) >= 2.0 * np.pi - 1e-12
    wrapped = np.mod(d, 2.0 * np.pi)
    return np.where(turn, np.minimum(wrapped, 2.0 * np.pi - wrapped), d)


def rest_to_rest_time(distance: np.ndarray, vmax: np.ndarray, amax: np.ndarray | None) -> np.ndarray:
    """Shortest time [s] to travel ``distance (..., n)`` from rest to rest under ``|v| ≤ vmax`` and, when given,
    ``|a| ≤ amax`` (the bang-bang profile, module docstring), per joint."""
    d = np.asarray(distance, dtype=float)
    if amax is None:
        return d / vmax
    return np.where(d >= vmax * vmax / amax, d / vmax + vmax / amax, 2.0 * np.sqrt(d / amax))


def cycle_lower_bounds(robot: Robot, targets: np.ndarray, n_picks: int, dwell: float,
                       vmax: JointLimit | None, amax: JointLimit | None = None) -> np.ndarray:
    """The lower bound [s] (module docstring) of each candidate's mean cycle time, ``(M,)``.

    ``targets (M, P + Q, 4, 4)``: the tcp poses of the picks, then the places, in each
    candidate's base frame. 0 for every candidate of an arm without a closed form, and for a
    candidate with a pose without solution (it has failed the reach screen).
    """
    M, K = targets.shape[:2]
    out = np.zeros(M)
    if not getattr(robot, "has_analytic_ik", False) or n_picks >= K:
        return out
    v = np.broadcast_to(np.asarray(robot.velocity_limit if vmax is None else vmax, dtype=float), (int(robot.nq),))
    if not np.all(np.isfinite(v) & (v > 0.0)):
        return out
    a_lim = None if amax is None else np.broadcast_to(np.asarray(amax, dtype=float), (int(robot.nq),))
    if a_lim is not None and not np.all(np.isfinite(a_lim) & (a_lim > 0.0)):
        a_lim = None
    lower, upper = np.asarray(robot.lower, dtype=float), np.asarray(robot.upper, dtype=float)
    sols = robot.ik_all(targets.reshape(M * K, 4, 4))
    for m in range(M):
        row = sols[m * K : (m + 1) * K]
        if any(np.shape(s)[0] == 0 for s in row):
            continue
        pairs = [float(np.min(np.max(rest_to_rest_time(_travel(a[:, None, :], b[None, :, :], lower, upper), v, a_lim),
                                     axis=-1)))
                 for a in row[:n_picks] for b in row[n_picks:]]
        out[m] = 2.0 * float(dwell) + 2.0 * float(np.mean(pairs))
    return out


def wave_size(scheduler: Scheduler, chunk_size: int) -> int | None:
    """Candidates per wave: one task serially, a task per worker thread of a Dask client, else None (one wave)."""
    if scheduler is None or scheduler == "serial":
        return int(chunk_size)
    nthreads = getattr(scheduler, "nthreads", None)
    if callable(nthreads):
        try:
            return int(chunk_size) * max(1, int(sum(nthreads().values())))
        except Exception:  # a client that cannot say: one wave
            return None
    return None


def threshold(times: list[float], keep: int) -> float:
    """The cycle time a candidate must be able to beat: the ``keep``-th shortest planned (inf before)."""
    if len(times) < keep:
        return float("inf")
    return float(np.partition(np.asarray(times), keep - 1)[keep - 1])


def outranked(lower_bound: float, limit: float, keep: int) -> str:
    """The reason of a candidate not planned."""
    which = "best cycle" if keep == 1 else f"{keep}th best cycle"
    return (f"its cycle takes at least {lower_bound:.3f} s (dwells, and the joint travel from pick to place and "
            f"back within the velocity and acceleration limits), longer than the {which} planned ({limit:.3f} s): not planned "
            "(LayoutRequest(bound=False) plans every candidate)")
