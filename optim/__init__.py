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
:func:`plan_motion` plans a collision-free move of an arm in a cell with OMPL, proves it
continuously and times it with :func:`time_optimal` (:mod:`pinarms.optim.motion`).
"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "CellCycleReport": ".cycle.cell_report",
    "CellSettings": ".cycle.request",
    "CycleApproach": ".cycle.request",
    "CycleLoad": ".cycle.request",
    "CycleRequest": ".cycle.request",
    "CycleResult": ".cycle.spec",
    "CycleTiming": ".cycle.request",
    "PickPlace": ".cycle.spec",
    "plan_cycle": ".cycle.plan",
    "LineSchedule": ".line.schedule",
    "schedule_line": ".line.schedule",
    "GAHistory": ".ga.engine",
    "GAProgress": ".ga.engine",
    "GAResult": ".ga.engine",
    "run_ga": ".ga.engine",
    "EndpointInCollision": ".errors",
    "GoalInCollision": ".errors",
    "InfeasibleProblem": ".errors",
    "InvalidLimits": ".errors",
    "InvalidSettings": ".errors",
    "NoPathFound": ".errors",
    "OptimError": ".errors",
    "PlanningError": ".errors",
    "SettingOutOfRange": ".errors",
    "StartInCollision": ".errors",
    "MotionPlan": ".motion.report",
    "plan_motion": ".motion.plan",
    "ExactSolution": ".timing.exact",
    "solve_exact": ".timing.exact",
    "LayoutSearch": ".layout.result",
    "Refinement": ".layout.result",
    "grid_candidates": ".layout.candidates",
    "random_candidates": ".layout.candidates",
    "search_layout": ".layout.search",
    "PathTiming": ".topp.path_timing",
    "time_optimal": ".topp.path_timing",
    "time_scaled": ".topp.path_timing",
    "TorqueConstraint": ".torque",
    "KINDS": ".ga.problem",
    "TimingProblem": ".ga.problem",
    "GASettings": ".ga.settings",
    "MissingReference": ".timing.reference",
    "double_s_limit": ".timing.reference",
    "path_velocity_limit": ".timing.reference",
    "ruckig_limit": ".timing.reference",
    "toppra_limit": ".timing.reference",
    "toppra_path_duration": ".timing.reference",
    "TimeJerkResult": ".timing.time_jerk",
    "jerk_integral": ".timing.time_jerk",
    "minimize_time_jerk": ".timing.time_jerk",
    "TimingResult": ".timing.segments",
    "minimize_time": ".timing.segments",
}

__all__ = [
    "run_ga", "GASettings", "GAResult", "GAHistory", "GAProgress", "TimingProblem", "KINDS", "TimingResult",
    "minimize_time", "minimize_time_jerk", "PickPlace", "CycleResult", "CycleRequest", "CycleTiming", "CycleLoad",
    "CycleApproach", "CellSettings", "plan_cycle", "search_layout", "LayoutSearch", "Refinement", "grid_candidates",
    "random_candidates", "time_optimal", "time_scaled", "TorqueConstraint", "PathTiming", "CellCycleReport",
    "LineSchedule", "schedule_line", "TimeJerkResult", "jerk_integral", "path_velocity_limit", "toppra_limit",
    "toppra_path_duration", "ruckig_limit", "double_s_limit", "MissingReference", "ExactSolution", "solve_exact",
    "OptimError", "InfeasibleProblem", "InvalidLimits", "InvalidSettings", "SettingOutOfRange", "plan_motion",
    "MotionPlan", "PlanningError", "EndpointInCollision", "StartInCollision", "GoalInCollision", "NoPathFound",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
