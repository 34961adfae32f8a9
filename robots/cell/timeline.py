"""The arms' motions on the cell's clock: who moves when, and where every arm is at a time.

Each arm follows its own joint trajectory (:class:`ArmMotion`) with its own time offset
and, for a cyclic schedule, its own period; arms without a motion hold still.
:func:`arm_motions` checks a schedule against a cell, :func:`motion_window` gives its
default time window, :func:`configurations` the cell configurations at given cell times and
:func:`sample_motions` samples them at a fixed rate. The continuous check of such a
schedule is :func:`~pinarms.robots.cell.motion.check_motion`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from pinarms.errors import InvalidInput

from pinarms.robots.cell.cell_model import CellModel

__all__ = ["ArmMotion", "arm_motions", "as_time", "configurations", "motion_window", "sample_motions", "MAX_SAMPLES",
           "MAX_TIME"]

#: Largest number of samples of one check.
MAX_SAMPLES = 2_000_000
#: Largest magnitude of a time (offset, period, window end, trajectory time) [s]: about 11.6
#: days; beyond it a double cannot resolve the bisection's 1e-6 s.
MAX_TIME = 1e6


def as_time(value: float, what: str) -> float:
    """``value`` as a time [s]; :class:`InvalidInput` naming ``what`` unless a finite number within ±:data:`MAX_TIME`."""
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    t = float(value) if ok else float("nan")
    if not (math.isfinite(t) and abs(t) <= MAX_TIME):
        raise InvalidInput(f"{what} must be a finite time within ±{MAX_TIME:.0e} s, got {value!r}")
    return t


@dataclass(frozen=True)
class ArmMotion:
    """One arm's motion in a cell.

    Attributes:
        arm: the arm's name in the cell.
        trajectory: its joint trajectory (a :class:`pinarms.planning.Trajectory`, or any
            object with ``start_time``, ``end_time`` [s], ``sample(t) -> (q, qd, ...)`` and
            ``peaks().velocity``), in the arm's own joint order.
        offset: cell time [s] at which the trajectory's ``start_time`` is played.
        period: if given [s] (≥ the trajectory's duration), the motion repeats every
            ``period`` s (a cycle); between the trajectory's end and the next start the
            arm holds its last position.
    """

    arm: str
    trajectory: Any
    offset: float = 0.0
    period: float | None = None

    def local_time(self, t: np.ndarray) -> np.ndarray:
        """The trajectory's own time for cell times ``t`` (held at its ends)."""
        traj = self.trajectory
        tau = np.asarray(t, dtype=float) - self.offset
        if self.period is not None:
            tau = np.mod(tau, self.period)
        return np.clip(tau + traj.start_time, traj.start_time, traj.end_time)


def arm_motions(cell: "CellModel", motions: Any) -> list[ArmMotion]:
    """The motions as a checked list of :class:`ArmMotion`.

    Takes :class:`ArmMotion` objects (or one), or ``{arm: trajectory}`` /
    ``{arm: (trajectory, offset[, period])}``.

    Raises:
        InvalidInput: no motion, an unknown arm or one named twice, a trajectory of the
            wrong width or without ``start_time``/``end_time``/``sample``, bad times or periods.
    """
    if isinstance(motions, ArmMotion):
        motions = [motions]
    if isinstance(motions, Mapping):
        out = []
        for arm, value in motions.items():
            if isinstance(value, tuple):
                out.append(ArmMotion(arm, *value))
            else:
                out.append(ArmMotion(arm, value))
        motions = out
    motions = list(motions)
    if not motions:
        raise InvalidInput("check_motion needs at least one ArmMotion")
    seen = set()
    for m in motions:
        if not isinstance(m, ArmMotion):
            raise InvalidInput(f"motions must be ArmMotion objects or {{arm: trajectory}}, got {type(m).__name__}")
        arm = cell.arm(m.arm)
        if m.arm in seen:
            raise InvalidInput(f"arm {m.arm!r} has two motions; give each arm one trajectory")
        seen.add(m.arm)
        _check_trajectory(m, arm.nq)
    return motions


def _check_trajectory(m: ArmMotion, nq: int) -> None:
    """The trajectory of ``m`` has the arm's ``nq`` joints, valid start and end times, offset and period."""
    traj = m.trajectory
    for attr in ("start_time", "end_time", "sample"):
        if not hasattr(traj, attr):
            raise InvalidInput(f"the trajectory of arm {m.arm!r} has no {attr!r}: pass a pinarms.planning.Trajectory")
    n = np.asarray(traj.sample(traj.start_time)[0]).shape
    if n != (nq,):
        raise InvalidInput(f"the trajectory of arm {m.arm!r} has {n[0] if n else 0} joints, the arm {nq}")
    as_time(m.offset, f"offset of arm {m.arm!r}")
    start = as_time(traj.start_time, f"start_time of the trajectory of arm {m.arm!r}")
    end = as_time(traj.end_time, f"end_time of the trajectory of arm {m.arm!r}")
    if end < start:
        raise InvalidInput(f"the trajectory of arm {m.arm!r} ends ({end!r} s) before it starts ({start!r} s)")
    if m.period is not None:
        as_time(m.period, f"period of arm {m.arm!r}")
        duration = traj.end_time - traj.start_time
        if not (math.isfinite(float(m.period)) and float(m.period) >= duration - 1e-12 and m.period > 0):
            raise InvalidInput(
                f"period of arm {m.arm!r} must be at least the trajectory's duration {duration:.6g} s, got {m.period!r}"
            )


def configurations(cell: "CellModel", motions: list[ArmMotion], times: np.ndarray, hold: np.ndarray) -> np.ndarray:
    """Cell configurations ``(M, nq)`` at cell ``times`` (arms without a motion at ``hold``)."""
    Q = np.tile(hold, (times.size, 1))
    for m in motions:
        arm = cell.arm(m.arm)
        Q[:, arm.q_slice] = np.asarray(m.trajectory.sample(m.local_time(times))[0], dtype=float).reshape(times.size, -1)
        if not np.isfinite(Q[:, arm.q_slice]).all():
            bad = times[np.flatnonzero(~np.isfinite(Q[:, arm.q_slice]).all(axis=1))[0]]
            raise InvalidInput(f"the trajectory of arm {m.arm!r} gives non-finite joint values at t = {bad!r} s")
    return Q


def motion_window(motions: list[ArmMotion]) -> tuple[float, float]:
    """Default time window [s]: earliest start to latest end, or ``(0, longest period)`` if a motion repeats."""
    if any(m.period is not None for m in motions):
        return (0.0, max(float(m.period or (m.trajectory.end_time - m.trajectory.start_time)) for m in motions))
    return (
        min(float(m.offset) for m in motions),
        max(float(m.offset) + m.trajectory.end_time - m.trajectory.start_time for m in motions),
    )


def sample_motions(cell: "CellModel", motions: Any, *, hz: float = 100.0, window: tuple[float, float] | None = None,
                   hold: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """The arms' motions sampled together: times ``(M,)`` [s] and cell configurations ``(M, nq)``.

    ``hz`` samples per second over ``window`` (default :func:`motion_window`), its end included.
    """
    motions = arm_motions(cell, motions)
    if not (isinstance(hz, (int, float)) and math.isfinite(hz) and hz > 0):
        raise InvalidInput(f"hz must be a positive sampling rate in 1/s, got {hz!r}")
    w0, w1 = motion_window(motions) if window is None else (window[0], window[1])
    t0, t1 = as_time(w0, "window start"), as_time(w1, "window end")
    if t1 < t0:
        raise InvalidInput(f"window must be (t_start, t_end) with t_end >= t_start, got {window!r}")
    n = max(2, int(math.ceil((t1 - t0) * hz)) + 1)
    if n > MAX_SAMPLES:
        raise InvalidInput(f"{n} samples at {hz!r} Hz over {t1 - t0:.3g} s: at most {MAX_SAMPLES}; lower hz or the window")
    times = np.linspace(t0, t1, n)
    hold_q = cell.hold if hold is None else cell.robot.check_q(hold)[0][0]
    return times, configurations(cell, motions, times, hold_q)
