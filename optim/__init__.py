"""Optimisation: a genetic algorithm written here, and segment timing of trajectories.

The GA engine (:func:`run_ga`, :class:`GASettings`, operators in ``selection``,
``crossover``, ``mutation``, ``adaptive``, ``constraints``) minimises vectorised
objectives over a box and knows nothing about trajectories. The timing layer
(:class:`TimingProblem`, :func:`minimize_time`, :func:`minimize_time_jerk`) turns segment
durations of a planning trajectory into objective and constraint arrays, and checks every
GA answer against a deterministic optimiser (``method="exact"``) and the time-optimal
limit along the same path (:mod:`pinarms.optim.timing.reference`). :func:`plan_cycle` times a whole
pick-and-place cycle (:class:`PickPlace`: pick, lift, transfer, lower, place, and back);
:func:`search_layout` ranks base placements of an arm by the picks per minute of that cycle
(many cycles, run through :mod:`pinarms.execution`: serial or on Dask).
:func:`time_optimal` times a geometric path (:class:`pinarms.planning.JointPath`, e.g. a straight
Cartesian line's joint image) under constraint objects by reachability analysis (TOPP-RA,
:mod:`pinarms.optim.topp`), returning a :class:`PathTiming` with a ``Trajectory``.
:func:`plan_motion` plans a collision-free move of an arm in a cell (one :class:`MotionRequest` in,
a :class:`MotionPlan` with a :class:`MotionStatus` out), proves it continuously and times it with
:func:`time_optimal` (:mod:`pinarms.optim.motion`).
"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "CellCycleReport": "pinarms.optim.cycle.in_cell",
    "CellSettings": "pinarms.optim.cycle",
    "CycleApproach": "pinarms.optim.cycle",
    "CycleLoad": "pinarms.optim.cycle",
    "CycleRequest": "pinarms.optim.cycle",
    "CycleResult": "pinarms.optim.cycle",
    "CycleStatus": "pinarms.optim.cycle",
    "CycleTiming": "pinarms.optim.cycle",
    "PickPlace": "pinarms.optim.cycle",
    "plan_cycle": "pinarms.optim.cycle",
    "LineSchedule": "pinarms.optim.line",
    "schedule_line": "pinarms.optim.line",
    "GAHistory": "pinarms.optim.ga.engine",
    "GAProgress": "pinarms.optim.ga.engine",
    "GAResult": "pinarms.optim.ga.engine",
    "run_ga": "pinarms.optim.ga.engine",
    "GARequest": "pinarms.optim.ga.request",
    "GAStop": "pinarms.optim.ga.request",
    "EndpointInCollision": "pinarms.optim.errors",
    "GoalInCollision": "pinarms.optim.errors",
    "InfeasibleProblem": "pinarms.optim.errors",
    "InvalidLimits": "pinarms.optim.errors",
    "InvalidSettings": "pinarms.optim.errors",
    "NoPathFound": "pinarms.optim.errors",
    "OptimError": "pinarms.optim.errors",
    "PlanningError": "pinarms.optim.errors",
    "SettingOutOfRange": "pinarms.optim.errors",
    "StartInCollision": "pinarms.optim.errors",
    "MotionLimits": "pinarms.optim.motion",
    "MotionOptions": "pinarms.optim.motion",
    "MotionPlan": "pinarms.optim.motion",
    "MotionRequest": "pinarms.optim.motion",
    "MotionStatus": "pinarms.optim.motion",
    "plan_motion": "pinarms.optim.motion",
    "ExactSolution": "pinarms.optim.timing.exact",
    "solve_exact": "pinarms.optim.timing.exact",
    "CandidateFailure": "pinarms.optim.layout.search",
    "LayoutRequest": "pinarms.optim.layout.search",
    "LayoutSearch": "pinarms.optim.layout.search",
    "LayoutStatus": "pinarms.optim.layout.search",
    "Refinement": "pinarms.optim.layout.search",
    "grid_candidates": "pinarms.optim.layout.search",
    "random_candidates": "pinarms.optim.layout.search",
    "search_layout": "pinarms.optim.layout.search",
    "PathTiming": "pinarms.optim.topp.path_timing",
    "time_optimal": "pinarms.optim.topp.path_timing",
    "time_scaled": "pinarms.optim.topp.path_timing",
    "TorqueConstraint": "pinarms.optim.torque",
    "KINDS": "pinarms.optim.ga.problem",
    "TimingProblem": "pinarms.optim.ga.problem",
    "GASettings": "pinarms.optim.ga.settings",
    "MissingReference": "pinarms.optim.timing.reference",
    "double_s_limit": "pinarms.optim.timing.reference",
    "path_velocity_limit": "pinarms.optim.timing.reference",
    "ruckig_limit": "pinarms.optim.timing.reference",
    "toppra_limit": "pinarms.optim.timing.reference",
    "toppra_path_duration": "pinarms.optim.timing.reference",
    "TimeJerkResult": "pinarms.optim.timing.time_jerk",
    "jerk_integral": "pinarms.optim.timing.time_jerk",
    "minimize_time_jerk": "pinarms.optim.timing.time_jerk",
    "TimingRequest": "pinarms.optim.timing.segments",
    "TimingResult": "pinarms.optim.timing.segments",
    "TimingStatus": "pinarms.optim.timing.segments",
    "minimize_time": "pinarms.optim.timing.segments",
}

__all__ = [
    "run_ga", "GARequest", "GAStop", "GASettings", "GAResult", "GAHistory", "GAProgress", "TimingProblem",
    "KINDS", "TimingResult", "minimize_time", "TimingRequest", "TimingStatus", "minimize_time_jerk",
    "PickPlace", "CycleResult", "CycleStatus", "CycleRequest", "CycleTiming", "CycleLoad", "CycleApproach",
    "CellSettings", "plan_cycle", "search_layout", "LayoutRequest", "LayoutStatus", "CandidateFailure",
    "LayoutSearch", "Refinement", "grid_candidates", "random_candidates", "time_optimal", "time_scaled",
    "TorqueConstraint", "PathTiming", "CellCycleReport", "LineSchedule", "schedule_line", "TimeJerkResult",
    "jerk_integral", "path_velocity_limit", "toppra_limit", "toppra_path_duration", "ruckig_limit",
    "double_s_limit", "MissingReference", "ExactSolution", "solve_exact", "OptimError", "InfeasibleProblem",
    "InvalidLimits", "InvalidSettings", "SettingOutOfRange", "plan_motion", "MotionRequest", "MotionOptions",
    "MotionLimits", "MotionPlan", "MotionStatus", "PlanningError", "EndpointInCollision", "StartInCollision",
    "GoalInCollision", "NoPathFound",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
