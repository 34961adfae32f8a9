"""What a minimum-time timing is asked: :class:`TimingRequest`, one frozen object checked when
built, and :class:`TimingStatus`, how :func:`pinarms.optim.minimize_time` ended.

Statuses and exceptions (:mod:`pinarms.optim.status`): a malformed request (limits, via points,
bounds, method, seed, generations, torque settings) raises when the request is built, before
any work. Every returned :class:`TimingResult` holds a timing verified against the limits;
its ``status`` says how the optimiser ended (the exact solver's optimum, or why the GA
stopped: a time limit or a callback leaves a feasible answer that may not be the best, and
``status_reason`` says so). When no timing within the bounds meets the limits there is no
trajectory to return: :func:`pinarms.optim.minimize_time` raises :class:`InfeasibleProblem`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from pinarms.optim.caps import MAX_GENERATIONS
from pinarms.optim.errors import InvalidSettings, SettingOutOfRange
from pinarms.optim.ga.request import checked_initial, random_generator
from pinarms.optim.ga.problem import TimingProblem
from pinarms.optim.ga.settings import GASettings
from pinarms.optim.status import Status

if TYPE_CHECKING:
    from pinarms.robots.payload import Payload
    from pinarms.robots.robot import Robot

__all__ = ["TimingRequest", "TimingStatus", "METHODS"]

METHODS = ("ga", "exact")


class TimingStatus(Status):
    """How a minimum-time timing ended (the value is the word printed); the timing is feasible in every case."""

    #: the exact (scaling-law) optimiser's answer, ``method="exact"``
    SOLVED = "solved"
    #: the GA ran its ``max_generations``
    MAX_GENERATIONS = "max_generations"
    #: the GA's best did not improve for ``stall_generations``
    STALL = "stall"
    #: the GA reached ``time_limit`` (its best so far: feasible, maybe not the best)
    TIME_LIMIT = "time_limit"
    #: the callback asked the GA to stop (its best so far)
    CALLBACK = "callback"


@dataclass(frozen=True, eq=False)
class TimingRequest:
    """Shortest segment durations through via points under per-joint limits: what to time and how.

    Minimises ``T = h_1 + ... + h_m`` subject to max|velocity| <= vmax, and optionally
    max|acceleration| <= amax and max|jerk| <= jmax, for every joint over the whole
    trajectory (exact peaks), with the same durations for all joints.

    Attributes:
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
        trajectory_options: Extra keyword arguments of the planning constructor.
        problem: A prebuilt :class:`TimingProblem` (then positions/kind/limits/bounds
            are not given); else the problem built from them when the request is built.
        robot: The arm whose joints the via points are; needed for torque limits.
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

    Raises (when built):
        InvalidLimits: A limit is <= 0, NaN/inf or has the wrong shape.
        InvalidSettings: unknown method, bad seed; torque limits without a robot, a payload
            without torque limits, torque limits both here and in ``problem``.
        SettingOutOfRange: ``max_generations`` outside its range.
        InfeasibleProblem: the arm cannot hold a via point still with its payload.
    """

    positions: np.ndarray | None = None
    kind: str | None = None
    vmax: float | np.ndarray | None = None
    amax: float | np.ndarray | None = None
    jmax: float | np.ndarray | None = None
    method: str = "ga"
    seed: int = 0
    settings: GASettings | None = None
    bounds: np.ndarray | None = None
    max_generations: int | None = None
    stall_generations: int | None = None
    time_limit: float | None = None
    rescale: bool = True
    polish: bool = False
    initial: np.ndarray | None = None
    trajectory_options: dict[str, object] | None = None
    problem: TimingProblem | None = None
    robot: Robot | None = None
    payload: float | Payload | dict | None = None
    torque_limits: bool | np.ndarray = False
    torque_samples: int | None = None

    def __post_init__(self) -> None:
        for name in ("positions", "bounds", "initial", "vmax", "amax", "jmax"):
            value = getattr(self, name)
            if isinstance(value, np.ndarray):  # the request owns its arrays: a copy the caller cannot change
                value = value.copy()
                value.setflags(write=False)
                object.__setattr__(self, name, value)
        g = self.max_generations
        if g is not None and not (isinstance(g, (int, np.integer)) and not isinstance(g, bool)
                                  and 1 <= g <= MAX_GENERATIONS):
            raise SettingOutOfRange(f"max_generations = {g!r} is outside 1 to {MAX_GENERATIONS:,} "
                                    "(the generations of the timing GA)")
        if self.method not in METHODS:
            raise InvalidSettings(f"method={self.method!r}: use one of {METHODS}")
        random_generator(self.seed)  # refuse a bad seed before any work, for both methods
        from pinarms.optim.torque import torque_constraint

        torque = torque_constraint(self.robot, self.torque_limits, self.payload, self.torque_samples)
        if self.problem is None:
            problem = TimingProblem(self.positions, self.kind, self.vmax, self.amax, self.jmax, bounds=self.bounds,
                                    trajectory_options=self.trajectory_options, torque=torque)
            object.__setattr__(self, "problem", problem)
        elif torque is not None:
            raise InvalidSettings("give torque limits either in the prebuilt problem (TimingProblem(torque=...)) "
                                  "or in the request (torque_limits=), not both")
        if self.initial is not None:  # the GA's initial individuals, checked against the durations' bounds
            checked_initial(self.initial, self.problem.bounds)
