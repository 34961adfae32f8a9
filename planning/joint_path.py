"""A geometric path in joint space: ``q(s)``, a piecewise polynomial in the path parameter s.

A :class:`JointPath` is the input of the time-optimal path scaling
(:func:`pinarms.optim.time_optimal`): geometry only, no time. ``s`` runs from 0 to
:attr:`JointPath.length`; on piece k (``breaks[k] <= s <= breaks[k+1]``) joint j is

    ``q_j(s) = sum_i coefficients[k, i, j] * (s - breaks[k])**i``

(ascending powers, like :class:`pinarms.planning.Trajectory` with time replaced by s). Its
derivatives ``dq/ds`` and ``d²q/ds²`` are what the path constraints need
(:mod:`pinarms.planning.path_constraints`). Where the tangent ``dq/ds`` jumps (a corner of a
Cartesian path without a blend) the arm must stop: those ``s`` are :attr:`JointPath.stops`
and the time scaling brings ``ds/dt`` to 0 there.

Build one from joint waypoints with :func:`joint_spline` (a C² cubic spline, parameter =
cumulative joint-space chord length, e.g. for a sampling planner's path), or from tcp
poses with :func:`pinarms.planning.cartesian_path` (its :class:`pinarms.planning.CartesianPath` subclass
follows straight tool lines). ``robot`` and ``frame`` (optional) let tool-space
constraints (tcp speed) evaluate the tcp along the path.

Units: s in the path's own unit (m for Cartesian paths, rad for joint splines), q in rad
or m per joint.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning._inputs import finite_array
from pinarms.planning.errors import TrajectoryError
from pinarms.planning.extrema import derivative_coefficients

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot

__all__ = ["JointPath", "joint_spline"]


class JointPath:
    """Joint positions along a path parameter s: piecewise polynomial (see the module docstring).

    Args:
        breaks: (K+1,) strictly increasing, ``breaks[0] == 0``.
        coefficients: (K, D+1, n_joints), ascending powers of ``s - breaks[k]``.
        stops: interior values of s where the path's tangent jumps (the arm must stop there).
        robot: optional :class:`pinarms.robots.Robot` the joints belong to (for tool constraints).
        frame: the robot's frame that is the tool (default its tcp).
    """

    def __init__(self, breaks: ArrayLike, coefficients: ArrayLike, *, stops: ArrayLike = (), robot: Robot | None = None,
                 frame: str = "tcp") -> None:
        b = finite_array(breaks, "breaks")
        c = finite_array(coefficients, "coefficients")
        if b.ndim != 1 or b.size < 2 or b[0] != 0.0 or np.any(np.diff(b) <= 0.0):
            raise TrajectoryError("breaks must be a strictly increasing 1-D array starting at s = 0, "
                                  f"with at least 2 entries; got {b.tolist() if b.size < 8 else b.shape}")
        if c.ndim != 3 or c.shape[0] != b.size - 1 or c.shape[1] < 1:
            raise TrajectoryError(f"coefficients must have shape ({b.size - 1}, degree+1, n_joints), got {c.shape}")
        st = np.sort(np.atleast_1d(finite_array(stops, "stops")).reshape(-1))
        if st.size and (st.min() <= 0.0 or st.max() >= b[-1]):
            raise TrajectoryError(f"stops must lie strictly inside (0, {b[-1]!r}), got {st.tolist()}")
        self._breaks, self._coefs, self._stops = b.copy(), c.copy(), st
        for arr in (self._breaks, self._coefs, self._stops):
            arr.flags.writeable = False
        self._derivs = np.stack([derivative_coefficients(c, r, axis=1) for r in range(3)])  # (3, K, D+1, n)
        self.robot = robot
        self.frame = frame

    # ----------------------------------------------------------------- data
    @property
    def breaks(self) -> np.ndarray:
        """Piece boundaries in s, (K+1,)."""
        return self._breaks

    @property
    def coefficients(self) -> np.ndarray:
        """(K, D+1, n_joints) ascending powers of ``s - breaks[k]`` (read-only)."""
        return self._coefs

    @property
    def stops(self) -> np.ndarray:
        """Interior values of s where the arm must be at rest (tangent discontinuities)."""
        return self._stops

    @property
    def length(self) -> float:
        """End value of s."""
        return float(self._breaks[-1])

    @property
    def n_joints(self) -> int:
        return int(self._coefs.shape[2])

    @property
    def degree(self) -> int:
        return int(self._coefs.shape[1] - 1)

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(n_joints={self.n_joints}, pieces={self._coefs.shape[0]}, degree={self.degree}, "
                f"length={self.length:.6g}, stops={self._stops.size})")

    # ------------------------------------------------------------ sampling
    def _check_s(self, s: Any) -> tuple[np.ndarray, bool]:
        arr = finite_array(s, "path parameter s")
        single = arr.ndim == 0
        arr = np.atleast_1d(arr)
        if arr.ndim != 1:
            raise TrajectoryError(f"s must be a scalar or a 1-D array, got shape {arr.shape}")
        tol = 1e-12 * max(1.0, self.length)
        if arr.size and (arr.min() < -tol or arr.max() > self.length + tol):
            raise TrajectoryError(f"s must lie in [0, {self.length!r}], got {arr.min()!r} .. {arr.max()!r}")
        return np.clip(arr, 0.0, self.length), single

    def sample(self, s: ArrayLike, side: str = "right") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, dq/ds, d²q/ds²)`` at ``s``, each (N, n_joints) (or (n_joints,) for a scalar s).

        At a break ``side="right"`` takes the piece that starts there, ``"left"`` the one that
        ends there (they differ at a stop).
        """
        arr, single = self._check_s(s)
        if side not in ("left", "right"):
            raise TrajectoryError(f"side must be 'left' or 'right', got {side!r}")
        m = self._coefs.shape[0]
        k = np.clip(np.searchsorted(self._breaks, arr, side=side) - 1, 0, m - 1)
        sig = arr - self._breaks[k]
        powers = sig[:, None] ** np.arange(self.degree + 1)
        out = tuple(np.einsum("nd,ndj->nj", powers, self._derivs[r][k]) for r in range(3))
        if single:
            return out[0][0], out[1][0], out[2][0]
        return out

    def __call__(self, s: ArrayLike) -> np.ndarray:
        """Joint positions at s."""
        return self.sample(s)[0]

    def sections(self) -> list[tuple[float, float]]:
        """The (start, end) values of s between consecutive stops (and the path's ends)."""
        edges = np.concatenate([[0.0], self._stops, [self.length]])
        return [(float(a), float(b)) for a, b in zip(edges[:-1], edges[1:])]

    def tool_derivatives(self, s: ArrayLike, side: str = "right") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """tcp pose and its first two s-derivatives along the joint path (needs ``robot``).

        Returns ``(T (N, 4, 4), d1 (N, 6), d2 (N, 6))`` with ``d1 = J(q) q'`` (linear [m per unit s],
        angular [rad per unit s], base axes) and ``d2 = J q'' + (dJ/ds) q'`` (the derivative of
        J along the path by a central difference of the batched Jacobian).
        """
        if self.robot is None:
            raise TrajectoryError("this joint path has no robot: tool quantities need JointPath(robot=...)")
        q, dq, ddq = self.sample(np.atleast_1d(s), side)
        T = np.asarray(self.robot.fk(q, frame=self.frame))
        J = np.asarray(self.robot.jacobian(q, frame=self.frame))
        d1 = np.einsum("nij,nj->ni", J, dq)
        d2 = np.einsum("nij,nj->ni", J, ddq) + jacobian_rate(self.robot, q, dq, self.frame)
        return T, d1, d2


def jacobian_rate(robot: Robot, q: np.ndarray, dq: np.ndarray, frame: str = "tcp") -> np.ndarray:
    """``(dJ/ds) dq`` (N, 6): the Jacobian's change along ``dq`` applied to ``dq``, central difference.

    The step along ``dq`` is 1e-6 / max(1, |dq|∞) (rad), so the difference error (≈1e-12) and the
    rounding error (≈1e-10 of |J|) stay far below what a path check can see.
    """
    eps = 1e-6 / np.maximum(1.0, np.abs(dq).max(axis=1))
    step = eps[:, None] * dq
    n = q.shape[0]
    J = np.asarray(robot.jacobian(np.concatenate([q + step, q - step]), frame=frame))
    return np.einsum("nij,nj->ni", J[:n] - J[n:], dq) / (2.0 * eps[:, None])


def joint_spline(waypoints: ArrayLike, *, robot: Robot | None = None, frame: str = "tcp") -> JointPath:
    """C² cubic spline through joint ``waypoints`` (M, n_joints), parameter = cumulative chord length.

    ``s`` at waypoint i is ``sum_k |q_{k+1} - q_k|`` (Euclidean, in rad or m); the spline is
    scipy's not-a-knot cubic (natural for 3 waypoints or fewer; a straight line for 2).
    Consecutive equal waypoints are an error. The path is smooth (no stops): a time
    scaling passes every waypoint without stopping.
    """
    from scipy.interpolate import CubicSpline

    Q = finite_array(waypoints, "waypoints")
    if Q.ndim != 2 or Q.shape[0] < 2:
        raise TrajectoryError(f"waypoints must be (M, n_joints) with M >= 2, got shape {Q.shape}")
    step = np.linalg.norm(np.diff(Q, axis=0), axis=1)
    if np.any(step <= 1e-12):
        k = int(np.argmax(step <= 1e-12))
        raise TrajectoryError(f"waypoints {k} and {k + 1} are equal: remove one")
    s = np.concatenate([[0.0], np.cumsum(step)])
    if Q.shape[0] == 2:
        coefs = np.stack([Q[0], (Q[1] - Q[0]) / s[1]])[None]
        return JointPath(s, coefs, robot=robot, frame=frame)
    spline = CubicSpline(s, Q, axis=0, bc_type="not-a-knot" if Q.shape[0] > 3 else "natural")
    coefs = np.ascontiguousarray(spline.c[::-1].transpose(1, 0, 2))  # (K, 4, n) ascending
    return JointPath(s, coefs, robot=robot, frame=frame)
