"""Optimisation: a genetic algorithm written here, and segment timing of trajectories.

The GA engine (:func:`run_ga`, :class:`GASettings`, operators in ``selection``,
``crossover``, ``mutation``, ``adaptive``, ``constraints``) minimises vectorised
objectives over a box and knows nothing about trajectories. The timing layer
(:class:`TimingProblem`, :func:`minimize_time`, :func:`minimize_time_jerk`) turns segment
durations of a planning trajectory into objective and constraint arrays, and checks every
GA answer against a deterministic optimiser (``method="exact"``) and the time-optimal
limit along the same path (:mod:`optim.timing.reference`). :func:`plan_cycle` times a whole
pick-and-place cycle (:class:`PickPlace`: pick, lift, transfer, lower, place, and back);
:func:`search_layout` ranks base placements of an arm by the picks per minute of that cycle
(many cycles, run through :mod:`pinarms.execution`: serial or on Dask).
:func:`time_optimal` times a geometric path (:class:`planning.JointPath`, e.g. a straight
Cartesian line's joint image) under constraint objects by reachability analysis (TOPP-RA,
:mod:`optim.topp`), returning a :class:`PathTiming` with a ``Trajectory``.
:func:`plan_motion` plans a collision-free move of an arm in a cell (one :class:`MotionRequest` in,
a :class:`MotionPlan` with a :class:`MotionStatus` out), proves it continuously and times it with
:func:`time_optimal` (:mod:`optim.motion`).
"""

from pinarms.optim.cycle.in_cell import CellCycleReport
from pinarms.optim.cycle import (CellSettings, CycleApproach, CycleLoad, CycleRequest, CycleResult, CycleStatus,
                                  CycleTiming, PickPlace, plan_cycle)
from pinarms.optim.line import LineSchedule, schedule_line
from pinarms.optim.ga.engine import GAHistory, GAProgress, GAResult, run_ga
from pinarms.optim.ga.request import GARequest, GAStop
from pinarms.optim.errors import (EndpointInCollision, GoalInCollision, InfeasibleProblem, InvalidLimits,
                                  InvalidSettings, NoPathFound, OptimError, PlanningError, SettingOutOfRange,
                                  StartInCollision)
from pinarms.optim.motion import MotionLimits, MotionOptions, MotionPlan, MotionRequest, MotionStatus, plan_motion
from pinarms.optim.timing.exact import ExactSolution, solve_exact
from pinarms.optim.layout.search import (CandidateFailure, LayoutRequest, LayoutSearch, LayoutStatus, Refinement,
                                         grid_candidates, random_candidates, search_layout)
from pinarms.optim.topp.path_timing import PathTiming, time_optimal, time_scaled
from pinarms.optim.torque import TorqueConstraint
from pinarms.optim.ga.problem import KINDS, TimingProblem
from pinarms.optim.ga.settings import GASettings
from pinarms.optim.timing.reference import (MissingReference, double_s_limit, path_velocity_limit,
                                     ruckig_limit, toppra_limit, toppra_path_duration)
from pinarms.optim.timing.time_jerk import TimeJerkResult, jerk_integral, minimize_time_jerk
from pinarms.optim.timing.segments import TimingRequest, TimingResult, TimingStatus, minimize_time

__all__ = [
    "run_ga",
    "GARequest",
    "GAStop",
    "GASettings",
    "GAResult",
    "GAHistory",
    "GAProgress",
    "TimingProblem",
    "KINDS",
    "TimingResult",
    "minimize_time",
    "TimingRequest",
    "TimingStatus",
    "minimize_time_jerk",
    "PickPlace",
    "CycleResult",
    "CycleStatus",
    "CycleRequest",
    "CycleTiming",
    "CycleLoad",
    "CycleApproach",
    "CellSettings",
    "plan_cycle",
    "search_layout",
    "LayoutRequest",
    "LayoutStatus",
    "CandidateFailure",
    "LayoutSearch",
    "Refinement",
    "grid_candidates",
    "random_candidates",
    "time_optimal",
    "time_scaled",
    "TorqueConstraint",
    "PathTiming",
    "CellCycleReport",
    "LineSchedule",
    "schedule_line",
    "TimeJerkResult",
    "jerk_integral",
    "path_velocity_limit",
    "toppra_limit",
    "toppra_path_duration",
    "ruckig_limit",
    "double_s_limit",
    "MissingReference",
    "ExactSolution",
    "solve_exact",
    "OptimError",
    "InfeasibleProblem",
    "InvalidLimits",
    "InvalidSettings",
    "SettingOutOfRange",
    "plan_motion",
    "MotionRequest",
    "MotionOptions",
    "MotionLimits",
    "MotionPlan",
    "MotionStatus",
    "PlanningError",
    "EndpointInCollision",
    "StartInCollision",
    "GoalInCollision",
    "NoPathFound",
]
