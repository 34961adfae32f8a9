"""Physical references for a timing: the time-optimal limits the GA is measured against.

- :func:`path_velocity_limit`: along the trajectory's own geometric path with only
  velocity limits, the fastest traversal moves at ``max_j |dq_j/ds| / V_j = 1`` all the
  time, so ``T = integral max_j |qd_j(t)| / V_j dt`` (exact up to the quadrature).
- :func:`toppra_limit`: the same path with velocity, acceleration and joint-torque limits,
  by TOPP-RA (Pham and Pham 2018; the ``toppra`` package, optional: ``pip install
  pinarms[reference]``). The path is a cubic spline through samples of the trajectory spaced
  evenly in joint-space arc length, cut where the trajectory rests.
- :func:`toppra_path_duration`: TOPP-RA (toppra) on a :class:`pinarms.planning.JointPath` itself,
  read through an adapter (the same q(s), q'(s), q''(s) that :func:`pinarms.optim.time_optimal`
  uses), on a grid of the caller's choice: the independent check of the time scaling
  written here.
- :func:`ruckig_limit` / :func:`double_s_limit`: jerk-limited, rest-to-rest point to
  point from the first to the last via point (ruckig, optional; or planning's double-S),
  a lower bound for any rest-to-rest motion through the via points.

These are references, not competitors: the via-point families (3-5-3, quintics,
B-splines) are smooth polynomials and cannot reach a bang-bang profile.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from pinarms.optim.types import JointLimit, JointVector

if TYPE_CHECKING:
    from pinarms.planning.joint_path import JointPath
    from pinarms.planning.trajectory import Trajectory
    from pinarms.robots.payload import Payload
    from pinarms.robots.robot import Robot

from pinarms.optim.errors import OptimError
from pinarms.optim.ga.problem import check_limit

__all__ = ["path_velocity_limit", "toppra_limit", "toppra_path", "toppra_path_duration", "ruckig_limit", "double_s_limit",
           "MissingReference"]


class MissingReference(OptimError, ImportError):
    """An optional reference library (toppra, ruckig) is not installed."""


def _dense(trajectory: Any, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.linspace(0.0, float(trajectory.duration), n)
    q, qd, _, _ = trajectory.sample(t)
    return t, q, qd


def path_velocity_limit(trajectory: Trajectory, vmax: JointLimit, n: int = 20001) -> float:
    """Minimal duration (s) along the trajectory's path under velocity limits only."""
    t, _, qd = _dense(trajectory, n)
    v = check_limit(vmax, qd.shape[1], "vmax", required=True)
    rate = np.max(np.abs(qd) / v, axis=1)
    return float(np.sum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t)))


def _rest_instants(trajectory: Any) -> np.ndarray:
    """Knot times (s) where every joint is at rest (|qd| <= 1e-9 of the peak): the path may turn there."""
    knots = np.asarray(trajectory.knot_times, dtype=float)
    qd = trajectory.sample(knots)[1]
    scale = max(float(np.max(np.abs(trajectory.peaks().velocity))), 1e-300)
    rest = np.all(np.abs(qd) <= 1e-9 * scale, axis=1)
    rest[0] = rest[-1] = True
    return knots[rest]


def _arc_length_section(trajectory: Any, t0: float, t1: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` points of the section's joint path spaced evenly in joint-space arc length.

    Returns the arc-length parameters (n,) [rad or m, the joints' Euclidean norm] and the
    positions (n, dof). Parameterised by arc length, a path that starts and ends at rest has a
    regular tangent everywhere (parameterised by time it would not: q'(t) -> 0 at a rest).
    """
    tf = np.linspace(t0, t1, 50 * n)
    qf = trajectory.sample(tf)[0]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(qf, axis=0), axis=1))])
    s = np.linspace(0.0, arc[-1], n)
    t = np.interp(s, arc, tf)
    return s, trajectory.sample(t)[0]


def toppra_limit(trajectory: Trajectory, vmax: JointLimit, amax: JointLimit | None = None, n: int = 400, *,
                 robot: Robot | None = None, torque_limits: bool | JointLimit | None = None,
                 payload: float | Payload | dict | None = None) -> float:
    """Minimal duration (s) along the trajectory's geometric path under velocity, acceleration
    and joint-torque limits (TOPP-RA on about ``n`` grid points).

    The path is the trajectory's joint-space curve (its timing is dropped), cut where the
    trajectory comes to rest (a rest-to-rest via point may be a corner, where any motion must
    stop too), each section re-parameterised by joint-space arc length (a regular tangent
    everywhere) and interpolated by a cubic spline through ``n`` points spread over the sections
    in proportion to their length (at least 50 each); TOPP-RA times each section from rest to
    rest and the durations add up.

    Args:
        trajectory: the path (its geometric shape is kept, its timing is not).
        vmax: velocity limits per joint (required); amax: acceleration limits or None.
        robot, torque_limits, payload: as in :func:`pinarms.optim.minimize_time`: with torque limits
            (``True``: the URDF's efforts) TOPP-RA's ``JointTorqueConstraint`` gets the
            robot's inverse dynamics (Pinocchio's RNEA, payload included), no dry friction.

    Raises:
        MissingReference: toppra is not installed.
        OptimError: TOPP-RA finds no parameterisation (e.g. the arm cannot hold the path still).
    """
    try:
        import toppra
        import toppra.algorithm
        import toppra.constraint
    except ImportError as exc:  # pragma: no cover - toppra is in the test extra
        raise MissingReference("toppra is not installed: pip install 'pinarms[reference]'") from exc
    dof = int(trajectory.n_joints)
    v = check_limit(vmax, dof, "vmax", required=True)
    a = check_limit(amax, dof, "amax", required=False)
    from pinarms.optim.torque import torque_constraint

    torque = torque_constraint(robot, torque_limits if torque_limits is not None else False, payload)
    constraints = [toppra.constraint.JointVelocityConstraint(np.column_stack([-v, v]))]
    if a is not None:
        constraints.append(toppra.constraint.JointAccelerationConstraint(np.column_stack([-a, a])))
    if torque is not None:
        arm, L = torque.robot, torque.limit
        constraints.append(toppra.constraint.JointTorqueConstraint(
            lambda q_, qd_, qdd_: arm.inverse_dynamics(q_, qd_, qdd_), np.column_stack([-L, L]), np.zeros(dof)))
    rests = _rest_instants(trajectory)
    lengths = []
    for t0, t1 in zip(rests[:-1], rests[1:]):
        q = trajectory.sample(np.linspace(t0, t1, 201))[0]
        lengths.append(float(np.sum(np.linalg.norm(np.diff(q, axis=0), axis=1))))
    total_length = sum(lengths)
    duration = 0.0
    for (t0, t1), length in zip(zip(rests[:-1], rests[1:]), lengths):
        if length <= 1e-12 * max(total_length, 1e-300):
            duration += 0.0  # a section without motion (a dwell) takes no time on the path
            continue
        k = max(50, int(round(n * length / total_length)))
        s, q = _arc_length_section(trajectory, float(t0), float(t1), k)
        path = toppra.SplineInterpolator(s, q)
        algo = toppra.algorithm.TOPPRA(constraints, path, gridpoints=s, parametrizer="ParametrizeConstAccel")
        out = algo.compute_parameterization(0.0, 0.0)
        sd = out[1] if isinstance(out, tuple) else None
        if sd is None or np.any(~np.isfinite(sd)):
            raise OptimError(f"TOPP-RA found no parameterisation of the path section t = [{t0:.6g}, {t1:.6g}] s "
                             "under these limits")
        duration += float(algo.compute_trajectory(0.0, 0.0).duration)
    return duration


def toppra_path(path: JointPath) -> Any:
    """``path`` (a :class:`pinarms.planning.JointPath`) as toppra's geometric path: toppra reads q, q', q''
    through ``path.sample(s)`` directly (no spline fitted in between)."""
    try:
        from toppra.interpolator import AbstractGeometricPath
    except ImportError as exc:  # pragma: no cover - toppra is in the test extra
        raise MissingReference("toppra is not installed: pip install 'pinarms[reference]'") from exc

    class _Adapter(AbstractGeometricPath):
        def __call__(self, s, order=0):
            out = path.sample(np.atleast_1d(np.asarray(s, dtype=float)))[order]
            return out[0] if np.ndim(s) == 0 else out

        @property
        def dof(self):
            return path.n_joints

        @property
        def path_interval(self):
            return np.array([0.0, path.length])

    return _Adapter()


def toppra_path_duration(path: JointPath, vmax: JointLimit, amax: JointLimit, gridpoints: np.ndarray, *, tool_speed: float | None = None,
                         discretization: str = "interpolation") -> float:
    """Duration (s) of toppra's time-optimal parameterisation of ``path`` (a :class:`pinarms.planning.JointPath`).

    Args:
        path: the joint path; toppra evaluates ``path.sample(s)`` (q, q', q'') directly.
        vmax, amax: joint limits (scalar or per joint).
        gridpoints: toppra's grid in s (increasing, from 0 to ``path.length``).
        tool_speed: optional tcp speed limit [m/s], as toppra's second-order constraint
            ``|J_v q'|² ṡ² <= v²`` (needs ``path.robot``).
        discretization: toppra's scheme for the acceleration (and tool) rows,
            ``"interpolation"`` (its default) or ``"collocation"``.
    """
    try:
        import toppra
        import toppra.algorithm
        import toppra.constraint
    except ImportError as exc:  # pragma: no cover - toppra is in the test extra
        raise MissingReference("toppra is not installed: pip install 'pinarms[reference]'") from exc

    dof = path.n_joints
    v = check_limit(vmax, dof, "vmax", required=True)
    a = check_limit(amax, dof, "amax", required=True)
    scheme = {"interpolation": toppra.constraint.DiscretizationType.Interpolation,
              "collocation": toppra.constraint.DiscretizationType.Collocation}[discretization]
    constraints = [toppra.constraint.JointVelocityConstraint(np.column_stack([-v, v])),
                   toppra.constraint.JointAccelerationConstraint(np.column_stack([-a, a]), discretization_scheme=scheme)]
    if tool_speed is not None:
        robot, frame = path.robot, path.frame

        def speed_squared(q, qd, qdd):  # |J_v(q) qd|^2: a = f(q, 0, q') = 0, b = f(q, q', q'') = |J_v q'|^2
            J = np.asarray(robot.jacobian(np.asarray(q, dtype=float), frame=frame))[:3]
            return np.array([float(np.sum((J @ np.asarray(qd, dtype=float)) ** 2))])

        F, g = np.array([[1.0]]), np.array([float(tool_speed) ** 2])
        constraints.append(toppra.constraint.SecondOrderConstraint(
            speed_squared, lambda q: F, lambda q: g, dof, discretization_scheme=scheme))
    grid = np.asarray(gridpoints, dtype=float)
    algo = toppra.algorithm.TOPPRA(constraints, toppra_path(path), gridpoints=grid, parametrizer="ParametrizeConstAccel")
    out = algo.compute_parameterization(0.0, 0.0)
    sd = out[1] if isinstance(out, tuple) else None
    if sd is None or np.any(~np.isfinite(sd)):
        raise OptimError("TOPP-RA found no parameterisation of the path under these limits")
    sd = np.asarray(sd, dtype=float)
    return float(np.sum(2.0 * np.diff(grid) / (sd[:-1] + sd[1:])))


def ruckig_limit(q0: JointVector, q1: JointVector, vmax: JointLimit, amax: JointLimit, jmax: JointLimit) -> float:
    """Time-optimal rest-to-rest duration (s) from q0 to q1, synchronised, by ruckig."""
    try:
        import ruckig
    except ImportError as exc:  # pragma: no cover - ruckig is in the test extra
        raise MissingReference("ruckig is not installed: pip install 'pinarms[reference]'") from exc
    a0 = np.atleast_1d(np.asarray(q0, dtype=float))
    a1 = np.atleast_1d(np.asarray(q1, dtype=float))
    dof = a0.shape[0]
    inp = ruckig.InputParameter(dof)
    inp.current_position = a0.tolist()
    inp.target_position = a1.tolist()
    inp.current_velocity = inp.current_acceleration = [0.0] * dof
    inp.target_velocity = inp.target_acceleration = [0.0] * dof
    inp.max_velocity = check_limit(vmax, dof, "vmax", True).tolist()
    inp.max_acceleration = check_limit(amax, dof, "amax", True).tolist()
    inp.max_jerk = check_limit(jmax, dof, "jmax", True).tolist()
    traj = ruckig.Trajectory(dof)
    result = ruckig.Ruckig(dof).calculate(inp, traj)
    if result not in (ruckig.Result.Working, ruckig.Result.Finished):
        raise OptimError(f"ruckig could not plan {a0.tolist()} -> {a1.tolist()}: {result}")
    return float(traj.duration)


def double_s_limit(q0: JointVector, q1: JointVector, vmax: JointLimit, amax: JointLimit,
                   jmax: JointLimit) -> float:
    """Rest-to-rest double-S duration (s) from q0 to q1 (planning's profile, synchronised)."""
    from pinarms import planning

    return float(planning.double_s(q0, q1, vmax, amax, jmax).duration)
