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
    "quintic_bspline": "pinarms.planning.bspline",
    "quintic_bspline_batch": "pinarms.planning.bspline",
    "joint_path_from_waypoints": "pinarms.planning.cartesian",
    "joint_waypoints": "pinarms.planning.cartesian",
    "tcp_path": "pinarms.planning.cartesian",
    "tcp_speed": "pinarms.planning.cartesian",
    "CartesianPath": "pinarms.planning.cartesian_path",
    "cartesian_path": "pinarms.planning.cartesian_path",
    "joint_image": "pinarms.planning.cartesian_path",
    "from_definition": "pinarms.planning.definition",
    "BlendTooLarge": "pinarms.planning.errors",
    "ConditionCountError": "pinarms.planning.errors",
    "JointLimitOnPath": "pinarms.planning.errors",
    "OutOfTimeRange": "pinarms.planning.errors",
    "PathError": "pinarms.planning.errors",
    "SingularityOnPath": "pinarms.planning.errors",
    "TrajectoryError": "pinarms.planning.errors",
    "UnreachableOnPath": "pinarms.planning.errors",
    "JointPath": "pinarms.planning.joint_path",
    "joint_spline": "pinarms.planning.joint_path",
    "JointAccelerationConstraint": "pinarms.planning.path_constraints",
    "JointVelocityConstraint": "pinarms.planning.path_constraints",
    "PathConstraint": "pinarms.planning.path_constraints",
    "PathRows": "pinarms.planning.path_constraints",
    "PathSamples": "pinarms.planning.path_constraints",
    "ToolAccelerationConstraint": "pinarms.planning.path_constraints",
    "ToolSpeedConstraint": "pinarms.planning.path_constraints",
    "ToolPath": "pinarms.planning.tool_path",
    "tool_path": "pinarms.planning.tool_path",
    "peaks_batch": "pinarms.planning.extrema",
    "piece_peaks_batch": "pinarms.planning.extrema",
    "JointLimits": "pinarms.planning.limits",
    "heuristic_velocities": "pinarms.planning.multi_quintic",
    "multi_quintic": "pinarms.planning.multi_quintic",
    "multi_quintic_batch": "pinarms.planning.multi_quintic",
    "multi_quintic_peaks_batch": "pinarms.planning.multi_quintic",
    "PRESETS": "pinarms.planning.piecewise",
    "piecewise_polynomial": "pinarms.planning.piecewise",
    "piecewise_polynomial_batch": "pinarms.planning.piecewise",
    "double_s": "pinarms.planning.point_to_point",
    "trapezoidal": "pinarms.planning.point_to_point",
    "polynomial": "pinarms.planning.polynomial",
    "LimitReport": "pinarms.planning.limit_report",
    "Violation": "pinarms.planning.limit_report",
    "Peaks": "pinarms.planning.trajectory",
    "Trajectory": "pinarms.planning.trajectory",
    "JointTorqueConstraint": "pinarms.planning.torque",
    "TorquePeaks": "pinarms.planning.torque",
    "torque_peaks": "pinarms.planning.torque",
    "torques": "pinarms.planning.torque",
}

__all__ = [
    "Trajectory", "Peaks", "LimitReport", "Violation", "JointLimits", "polynomial", "piecewise_polynomial", "PRESETS",
    "multi_quintic", "heuristic_velocities", "quintic_bspline", "piecewise_polynomial_batch", "multi_quintic_batch",
    "multi_quintic_peaks_batch",
    "quintic_bspline_batch", "peaks_batch", "piece_peaks_batch", "trapezoidal", "double_s", "from_definition",
    "joint_waypoints", "joint_path_from_waypoints", "tcp_path", "tcp_speed", "ToolPath", "tool_path", "JointPath",
    "joint_spline", "CartesianPath", "cartesian_path", "joint_image", "PathConstraint", "PathSamples", "PathRows",
    "JointVelocityConstraint", "JointAccelerationConstraint", "ToolSpeedConstraint", "ToolAccelerationConstraint",
    "TrajectoryError", "ConditionCountError", "OutOfTimeRange", "TorquePeaks", "JointTorqueConstraint", "torques",
    "torque_peaks", "BlendTooLarge", "PathError", "SingularityOnPath", "JointLimitOnPath", "UnreachableOnPath",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
