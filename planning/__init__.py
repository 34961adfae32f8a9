"""Joint-space trajectories through via points (seed papers 000, 001, 002), and Cartesian paths.

Every constructor returns a :class:`Trajectory` (a piecewise polynomial in time, per
joint) with exact peaks, limit checks against a :class:`JointLimits` spec, time scaling,
concatenation and a JSON-able ``definition`` that :func:`from_definition` rebuilds.
The ``*_batch`` constructors return the coefficients of P timings of the same via points
at once, and :func:`peaks_batch` peaks them in one pass (for optimisers).
Cartesian motion: :func:`tool_path` (straight tcp lines, SLERP orientation, circular
blends, arc length) and :func:`cartesian_path` / :func:`joint_image` (its joint-space image
on one IK branch within a tolerance) give a :class:`JointPath` q(s); the limits along a
path are objects (:mod:`planning.path_constraints`) that :func:`optim.time_optimal` reads.
Units: s, and rad or m per joint.
"""

from pinarms.planning.bspline import quintic_bspline, quintic_bspline_batch
from pinarms.planning.cartesian import joint_path_from_waypoints, joint_waypoints, tcp_path, tcp_speed
from pinarms.planning.cartesian_path import CartesianPath, cartesian_path, joint_image
from pinarms.planning.definition import from_definition
from pinarms.planning.errors import (BlendTooLarge, ConditionCountError, JointLimitOnPath, OutOfTimeRange, PathError,
                                     SingularityOnPath, TrajectoryError, UnreachableOnPath)
from pinarms.planning.joint_path import JointPath, joint_spline
from pinarms.planning.path_constraints import (JointAccelerationConstraint, JointVelocityConstraint, PathConstraint,
                                               PathRows, PathSamples, ToolAccelerationConstraint, ToolSpeedConstraint)
from pinarms.planning.tool_path import ToolPath, tool_path
from pinarms.planning.extrema import peaks_batch, piece_peaks_batch
from pinarms.planning.limits import JointLimits
from pinarms.planning.multi_quintic import heuristic_velocities, multi_quintic, multi_quintic_batch
from pinarms.planning.piecewise import PRESETS, piecewise_polynomial, piecewise_polynomial_batch
from pinarms.planning.point_to_point import double_s, trapezoidal
from pinarms.planning.polynomial import polynomial
from pinarms.planning.limit_report import LimitReport, Violation
from pinarms.planning.trajectory import Peaks, Trajectory
from pinarms.planning.torque import JointTorqueConstraint, TorquePeaks, torque_peaks, torques

__all__ = [
    "Trajectory",
    "Peaks",
    "LimitReport",
    "Violation",
    "JointLimits",
    "polynomial",
    "piecewise_polynomial",
    "PRESETS",
    "multi_quintic",
    "heuristic_velocities",
    "quintic_bspline",
    "piecewise_polynomial_batch",
    "multi_quintic_batch",
    "quintic_bspline_batch",
    "peaks_batch",
    "piece_peaks_batch",
    "trapezoidal",
    "double_s",
    "from_definition",
    "joint_waypoints",
    "joint_path_from_waypoints",
    "tcp_path",
    "tcp_speed",
    "ToolPath",
    "tool_path",
    "JointPath",
    "joint_spline",
    "CartesianPath",
    "cartesian_path",
    "joint_image",
    "PathConstraint",
    "PathSamples",
    "PathRows",
    "JointVelocityConstraint",
    "JointAccelerationConstraint",
    "ToolSpeedConstraint",
    "ToolAccelerationConstraint",
    "TrajectoryError",
    "ConditionCountError",
    "OutOfTimeRange",
    "TorquePeaks",
    "JointTorqueConstraint",
    "torques",
    "torque_peaks",
    "BlendTooLarge",
    "PathError",
    "SingularityOnPath",
    "JointLimitOnPath",
    "UnreachableOnPath",
]
