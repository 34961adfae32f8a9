"""Joint-space trajectories through via points (seed papers 000, 001, 002), and Cartesian paths.

Every constructor returns a :class:`Trajectory` (a piecewise polynomial in time, per
joint) with exact peaks, limit checks against a :class:`JointLimits` spec, time scaling,
concatenation and a JSON-able ``definition`` that :func:`from_definition` rebuilds.
The ``*_batch`` constructors return the coefficients of P timings of the same via points
at once, and :func:`peaks_batch` peaks them in one pass (for optimisers).
Cartesian motion: :func:`tool_path` (straight tcp lines, SLERP orientation, circular
blends, arc length) and :func:`cartesian_path` / :func:`joint_image` (its joint-space image
on one IK branch within a tolerance) give a :class:`JointPath` q(s); the limits along a
path are objects (:mod:`pinarms.planning.path_constraints`) that :func:`pinarms.optim.time_optimal` reads.
Units: s, and rad or m per joint.
"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "quintic_bspline": ".bspline",
    "quintic_bspline_batch": ".bspline",
    "joint_path_from_waypoints": ".cartesian",
    "joint_waypoints": ".cartesian",
    "tcp_path": ".cartesian",
    "tcp_speed": ".cartesian",
    "CartesianPath": ".cartesian_path",
    "cartesian_path": ".cartesian_path",
    "joint_image": ".cartesian_path",
    "from_definition": ".definition",
    "BlendTooLarge": ".errors",
    "ConditionCountError": ".errors",
    "JointLimitOnPath": ".errors",
    "OutOfTimeRange": ".errors",
    "PathError": ".errors",
    "SingularityOnPath": ".errors",
    "TrajectoryError": ".errors",
    "UnreachableOnPath": ".errors",
    "JointPath": ".joint_path",
    "joint_spline": ".joint_path",
    "JointAccelerationConstraint": ".path_constraints",
    "JointVelocityConstraint": ".path_constraints",
    "PathConstraint": ".path_constraints",
    "PathRows": ".path_constraints",
    "PathSamples": ".path_constraints",
    "ToolAccelerationConstraint": ".path_constraints",
    "ToolSpeedConstraint": ".path_constraints",
    "ToolPath": ".tool_path",
    "tool_path": ".tool_path",
    "peaks_batch": ".extrema",
    "piece_peaks_batch": ".extrema",
    "JointLimits": ".limits",
    "heuristic_velocities": ".multi_quintic",
    "multi_quintic": ".multi_quintic",
    "multi_quintic_batch": ".multi_quintic",
    "PRESETS": ".piecewise",
    "piecewise_polynomial": ".piecewise",
    "piecewise_polynomial_batch": ".piecewise",
    "double_s": ".point_to_point",
    "trapezoidal": ".point_to_point",
    "polynomial": ".polynomial",
    "LimitReport": ".limit_report",
    "Violation": ".limit_report",
    "Peaks": ".trajectory",
    "Trajectory": ".trajectory",
    "JointTorqueConstraint": ".torque",
    "TorquePeaks": ".torque",
    "torque_peaks": ".torque",
    "torques": ".torque",
}

__all__ = [
    "Trajectory", "Peaks", "LimitReport", "Violation", "JointLimits", "polynomial", "piecewise_polynomial", "PRESETS",
    "multi_quintic", "heuristic_velocities", "quintic_bspline", "piecewise_polynomial_batch", "multi_quintic_batch",
    "quintic_bspline_batch", "peaks_batch", "piece_peaks_batch", "trapezoidal", "double_s", "from_definition",
    "joint_waypoints", "joint_path_from_waypoints", "tcp_path", "tcp_speed", "ToolPath", "tool_path", "JointPath",
    "joint_spline", "CartesianPath", "cartesian_path", "joint_image", "PathConstraint", "PathSamples", "PathRows",
    "JointVelocityConstraint", "JointAccelerationConstraint", "ToolSpeedConstraint", "ToolAccelerationConstraint",
    "TrajectoryError", "ConditionCountError", "OutOfTimeRange", "TorquePeaks", "JointTorqueConstraint", "torques",
    "torque_peaks", "BlendTooLarge", "PathError", "SingularityOnPath", "JointLimitOnPath", "UnreachableOnPath",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
