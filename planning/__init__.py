"""Joint-space trajectories through via points (seed papers 000, 001, 002).

Every constructor returns a :class:`Trajectory` (a piecewise polynomial in time, per
joint) with exact peaks, limit checks against a :class:`JointLimits` spec, time scaling,
concatenation and a JSON-able ``definition`` that :func:`from_definition` rebuilds.
The ``*_batch`` constructors return the coefficients of P timings of the same via points
at once, and :func:`peaks_batch` peaks them in one pass (for optimisers).
Units: s, and rad or m per joint.
"""

from planning.bspline import quintic_bspline, quintic_bspline_batch
from planning.cartesian import joint_path_from_waypoints, joint_waypoints, tcp_path
from planning.definition import from_definition
from planning.errors import ConditionCountError, OutOfTimeRange, TrajectoryError
from planning.extrema import peaks_batch, piece_peaks_batch
from planning.limits import JointLimits
from planning.multi_quintic import heuristic_velocities, multi_quintic, multi_quintic_batch
from planning.piecewise import PRESETS, piecewise_polynomial, piecewise_polynomial_batch
from planning.point_to_point import double_s, trapezoidal
from planning.polynomial import polynomial
from planning.trajectory import LimitReport, Peaks, Trajectory, Violation

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
    "TrajectoryError",
    "ConditionCountError",
    "OutOfTimeRange",
]
