"""Physical references for a timing: the time-optimal limits the GA is measured against.

- :func:`path_velocity_limit`: along the trajectory's own geometric path with only
  velocity limits, the fastest traversal moves at ``max_j |dq_j/ds| / V_j = 1`` all the
  time, so ``T = integral max_j |qd_j(t)| / V_j dt`` (exact up to the quadrature).
- :func:`toppra_limit`: the same path with velocity and acceleration limits, by TOPP-RA
  (Pham and Pham 2018; the ``toppra`` package, optional: ``pip install pinarms[reference]``).
  The path is a cubic spline through dense samples of the trajectory, parameterised by
  the trajectory's time.
- :func:`ruckig_limit` / :func:`double_s_limit`: jerk-limited, rest-to-rest point to
  point from the first to the last via point (ruckig, optional; or planning's double-S),
  a lower bound for any rest-to-rest motion through the via points.

These are references, not competitors: the via-point families (3-5-3, quintics,
B-splines) are smooth polynomials and cannot reach a bang-bang profile.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms.optim.errors import OptimError
from pinarms.optim.problem import check_limit

__all__ = ["path_velocity_limit", "toppra_limit", "ruckig_limit", "double_s_limit",
           "MissingReference"]


class MissingReference(OptimError, ImportError):
    """An optional reference library (toppra, ruckig) is not installed."""


def _dense(trajectory: Any, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.linspace(0.0, float(trajectory.duration), n)
    q, qd, _, _ = trajectory.sample(t)
    return t, q, qd


def path_velocity_limit(trajectory: Any, vmax: Any, n: int = 20001) -> float:
    """Minimal duration (s) along the trajectory's path under velocity limits only."""
    t, _, qd = _dense(trajectory, n)
    v = check_limit(vmax, qd.shape[1], "vmax", required=True)
    rate = np.max(np.abs(qd) / v, axis=1)
    return float(np.sum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t)))


def toppra_limit(trajectory: Any, vmax: Any, amax: Any, n: int = 400) -> float:
    """Minimal duration (s) along the trajectory's path, velocity + acceleration limits
    (TOPP-RA on ``n`` grid points)."""
    try:
        import toppra
        import toppra.algorithm
        import toppra.constraint
    except ImportError as exc:  # pragma: no cover - toppra is in the test extra
        raise MissingReference("toppra is not installed: pip install 'pinarms[reference]'") from exc
    t, q, _ = _dense(trajectory, max(n, 50))
    dof = q.shape[1]
    v = check_limit(vmax, dof, "vmax", required=True)
    a = check_limit(amax, dof, "amax", required=True)
    path = toppra.SplineInterpolator(t, q)
    constraints = [toppra.constraint.JointVelocityConstraint(np.column_stack([-v, v])),
                   toppra.constraint.JointAccelerationConstraint(np.column_stack([-a, a]))]
    algo = toppra.algorithm.TOPPRA(constraints, path, gridpoints=np.linspace(0.0, t[-1], n),
                                   parametrizer="ParametrizeConstAccel")
    out = algo.compute_parameterization(0.0, 0.0)
    sd = out[1] if isinstance(out, tuple) else None
    if sd is None or np.any(~np.isfinite(sd)):
        raise OptimError("TOPP-RA found no parameterisation of the path under these limits")
    jnt = algo.compute_trajectory(0.0, 0.0)
    return float(jnt.duration)


def ruckig_limit(q0: Any, q1: Any, vmax: Any, amax: Any, jmax: Any) -> float:
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


def double_s_limit(q0: Any, q1: Any, vmax: Any, amax: Any, jmax: Any) -> float:
    """Rest-to-rest double-S duration (s) from q0 to q1 (planning's profile, synchronised)."""
    from pinarms import planning

    return float(planning.double_s(q0, q1, vmax, amax, jmax).duration)
