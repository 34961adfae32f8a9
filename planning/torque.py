"""Joint torques along a trajectory: samples, per-joint peaks, and the arrays optimisers use.

A trajectory is kinematic (positions, velocities, accelerations per joint); the torques
that make a given arm follow it come from the arm's inverse dynamics,
``tau(t) = M(q) qdd + C(q, qd) qd + g(q)`` (:meth:`pinarms.robots.Robot.inverse_dynamics`,
Pinocchio's RNEA; N·m for revolute, N for prismatic joints). Torques are not polynomials
in time, so their peaks are not exact like the velocity peaks: each polynomial piece is
sampled on a grid of ``samples_per_piece`` instants (both ends included, evaluated with that
piece's own coefficients, so a step in acceleration at a knot is seen from both sides), and
the largest ``|tau_j|`` of every piece and joint is then refined by a bracketing search
(the bracket around the best sample shrinks 4× per step, 12 steps: the peak's instant to
about 1e-7 of the grid spacing). A peak narrower than the grid spacing can be missed; raise
``samples_per_piece`` for very fast, long pieces.

Along a geometric path (:func:`pinarms.optim.time_optimal`) the torque is linear in (s̈, ṡ²):
:class:`JointTorqueConstraint` gives those rows to the time-optimal path scaling like the
other :mod:`pinarms.planning.path_constraints`.

The batched helpers (:func:`piece_states`, :func:`piece_torques`) work on the coefficient
arrays of a whole population of timings (``(P, m, K+1, n)``, as the ``*_batch``
constructors return them), so that an optimiser gets every individual's torques from one
RNEA batch.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning._inputs import finite_array
from pinarms.planning.errors import TrajectoryError
from pinarms.planning.extrema import derivative_coefficients
from pinarms.planning.path_constraints import PathConstraint, PathRows

if TYPE_CHECKING:
    from pinarms.planning.timed_curve import TimedCurve
    from pinarms.robots.robot import Robot

__all__ = [
    "SAMPLES_PER_PIECE",
    "JointTorqueConstraint",
    "torque_dilation",
    "clearly_within",
    "TorquePeaks",
    "torques",
    "torque_peaks",
    "piece_torque_peaks",
    "piece_states",
    "piece_torques",
    "grid",
]

#: Default number of instants per polynomial piece (ends included) of the torque grid.
SAMPLES_PER_PIECE = 48

#: Bracketing steps of the peak refinement (each shrinks the bracket 4×).
REFINE_STEPS = 12

_BRACKET_POINTS = 9


def grid(samples_per_piece: int) -> np.ndarray:
    """Normalised instants ``s = tau / h`` in [0, 1] of one piece, ends included, (k,)."""
    if isinstance(samples_per_piece, bool) or not isinstance(samples_per_piece, (int, np.integer)) or samples_per_piece < 2:
        raise TrajectoryError(f"samples_per_piece must be an integer >= 2, got {samples_per_piece!r}")
    return np.linspace(0.0, 1.0, int(samples_per_piece))


def _robot_joints(robot: Any, n_joints: int) -> None:
    nq = getattr(robot, "nq", None)
    if nq is None or not hasattr(robot, "inverse_dynamics"):
        raise TrajectoryError(f"robot must be a robots.Robot (with inverse_dynamics), got {type(robot).__name__}")
    if int(nq) != n_joints:
        raise TrajectoryError(
            f"the trajectory has {n_joints} joint(s) but robot '{robot.name}' has {nq} "
            f"({', '.join(robot.joint_names)}): torques need every joint of the arm"
        )


def _evaluate(coefs: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """States of pieces ``coefs`` (..., K+1, n) at piece times ``tau`` (..., k) [s] → 3 × (..., k, n)."""
    width = coefs.shape[-2]
    powers = tau[..., None] ** np.arange(width)  # (..., k, K+1)
    out = []
    for r in range(3):
        c = derivative_coefficients(coefs, r, axis=-2)
        out.append(powers @ c)
    return out[0], out[1], out[2]


def piece_states(times: ArrayLike, coefs: ArrayLike, s: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity, acceleration of every piece at normalised instants ``s``.

    Args:
        times: knot times (P, m+1) [s] (or (m+1,) for one trajectory).
        coefs: piece coefficients (P, m, K+1, n) (or (m, K+1, n)), ascending powers of the
            time since the piece start.
        s: normalised instants (k,) in [0, 1] (``tau = s h`` on a piece of duration h).

    Returns:
        ``q, qd, qdd``, each (P, m, k, n) (or (m, k, n)) in the joints' units per s^r.
    """
    t = np.asarray(times, dtype=float)
    c = np.asarray(coefs, dtype=float)
    single = t.ndim == 1
    if single:
        t, c = t[None], c[None]
    h = np.diff(t, axis=1)  # (P, m)
    tau = h[..., None] * np.asarray(s, dtype=float)  # (P, m, k)
    q, qd, qdd = _evaluate(c, tau)
    return (q[0], qd[0], qdd[0]) if single else (q, qd, qdd)


def piece_torques(robot: Robot, times: ArrayLike, coefs: ArrayLike, s: ArrayLike) -> np.ndarray:
    """Joint torques (P, m, k, n) [N·m or N] of every piece at normalised instants ``s`` (one RNEA batch)."""
    q, qd, qdd = piece_states(times, coefs, s)
    shape = q.shape
    tau = robot.inverse_dynamics(q.reshape(-1, shape[-1]), qd.reshape(-1, shape[-1]), qdd.reshape(-1, shape[-1]))
    return tau.reshape(shape)


@dataclass(frozen=True, eq=False)
class TorquePeaks:
    """Per-joint peaks of ``|tau|`` along a trajectory.

    Attributes:
        torque: (n,) peak magnitudes [N·m or N].
        time: (n,) instants [s] of the peaks.
        signed: (n,) the torque at those instants, with its sign.
    """

    torque: np.ndarray
    time: np.ndarray
    signed: np.ndarray

    def ratios(self, limit: ArrayLike) -> np.ndarray:
        """Peak / limit per joint for limits (n,) or a scalar [N·m or N]."""
        return self.torque / np.asarray(limit, dtype=float)

    def as_dict(self) -> dict[str, list[float]]:
        """JSON-able form ``{"torque": [...], "time": [...], "signed": [...]}`` (SI)."""
        return {"torque": self.torque.tolist(), "time": self.time.tolist(), "signed": self.signed.tolist()}


def torques(trajectory: TimedCurve, robot: Robot, t: ArrayLike) -> np.ndarray:
    """Joint torques [N·m or N] of ``robot`` following ``trajectory`` at instants ``t`` [s].

    Returns (len(t), nq), or (nq,) for a scalar ``t``. At an interior knot the piece that
    starts there is used (as :meth:`pinarms.planning.Trajectory.sample` does).
    """
    _robot_joints(robot, trajectory.n_joints)
    q, qd, qdd, _ = trajectory.sample(t)
    return robot.inverse_dynamics(q, qd, qdd)


def piece_torque_peaks(
    trajectory: TimedCurve, robot: Robot, samples_per_piece: int = SAMPLES_PER_PIECE
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Refined peak of ``|tau_j|`` on every piece and joint (see the module docstring).

    Returns ``(peak, time, signed)``, each (m, n): the peak magnitude [N·m or N], its
    instant [s] and the signed torque there.
    """
    _robot_joints(robot, trajectory.n_joints)
    s = grid(samples_per_piece)
    times = trajectory.knot_times
    coefs = trajectory.coefficients  # (m, K+1, n)
    m, n = coefs.shape[0], coefs.shape[2]
    h = np.diff(times)
    tau = piece_torques(robot, times, coefs, s)  # (m, k, n)
    best = np.argmax(np.abs(tau), axis=1)  # (m, n)
    # candidates: every (piece, joint), bracket of ±1 grid step around the best sample
    piece = np.repeat(np.arange(m), n)
    joint = np.tile(np.arange(n), m)
    idx = best.reshape(-1)
    step = s[1] - s[0]
    centre = s[idx]
    value = np.abs(tau[piece, idx, joint])
    where = centre.copy()
    signed = tau[piece, idx, joint]
    lo = np.clip(centre - step, 0.0, 1.0)
    hi = np.clip(centre + step, 0.0, 1.0)
    c_coefs = coefs[piece]  # (C, K+1, n)
    frac = np.linspace(0.0, 1.0, _BRACKET_POINTS)
    for _ in range(REFINE_STEPS):
        ss = lo[:, None] + (hi - lo)[:, None] * frac  # (C, B)
        q, qd, qdd = _evaluate(c_coefs, ss * h[piece][:, None])
        tt = robot.inverse_dynamics(q.reshape(-1, n), qd.reshape(-1, n), qdd.reshape(-1, n)).reshape(q.shape)
        mine = tt[np.arange(piece.size), :, joint]  # (C, B)
        k = np.argmax(np.abs(mine), axis=1)
        cand = np.abs(mine[np.arange(piece.size), k])
        better = cand > value
        value = np.where(better, cand, value)
        where = np.where(better, ss[np.arange(piece.size), k], where)
        signed = np.where(better, mine[np.arange(piece.size), k], signed)
        width = (hi - lo) / (_BRACKET_POINTS - 1)
        lo = np.clip(where - width, 0.0, 1.0)
        hi = np.clip(where + width, 0.0, 1.0)
    t_abs = times[:-1][piece] + where * h[piece]
    return value.reshape(m, n), t_abs.reshape(m, n), signed.reshape(m, n)


def torque_peaks(trajectory: TimedCurve, robot: Robot, samples_per_piece: int = SAMPLES_PER_PIECE) -> TorquePeaks:
    """Per-joint peaks of ``|tau|`` over the whole trajectory (module docstring: grid + refinement).

    Ties between pieces (equal peaks to the last bit) go to the earliest piece.
    """
    value, when, signed = piece_torque_peaks(trajectory, robot, samples_per_piece)
    k = np.argmax(value, axis=0)  # first maximum: the earliest piece
    cols = np.arange(value.shape[1])
    return TorquePeaks(torque=value[k, cols], time=when[k, cols], signed=signed[k, cols])


def check_torque_limit(limit: ArrayLike, n_joints: int) -> np.ndarray:
    """Torque limits (n_joints,) [N·m or N], positive and finite."""
    arr = finite_array(limit, "torque limit")
    if arr.ndim > 1 or (arr.ndim == 1 and arr.size not in (1, n_joints)):
        raise TrajectoryError(f"torque limit must be a scalar or {n_joints} values (one per joint), got shape {arr.shape}")
    arr = np.broadcast_to(arr.reshape(-1) if arr.ndim else arr, (n_joints,)).astype(float)
    if np.any(arr <= 0.0):
        raise TrajectoryError(f"torque limit must be positive for every joint, got {arr.tolist()}")
    return arr


def clearly_within(trajectory: TimedCurve, robot: Robot, limit: np.ndarray, samples_per_piece: int = SAMPLES_PER_PIECE
                   ) -> bool:
    """Whether every piece's sampled peak of ``|tau_j|`` plus twice the largest change of ``tau_j`` between
    two neighbouring samples of that piece is within ``limit`` (n,): then no refined peak reaches the limit.

    The refinement (:func:`piece_torque_peaks`) looks within one sample step of the best sample, where the
    torque differs from that sample by at most one step times its slope; the slope is taken as at most
    twice the steepest change seen between samples (the grid resolution the refinement itself assumes,
    module docstring). One RNEA batch of the grid instead of the grid and 12 bracketing batches: on a
    Kinova Jaco2 pick, whose torques stay below a fifth of its limits, the timing of a move 10x faster.
    """
    tau = piece_torques(robot, trajectory.knot_times, trajectory.coefficients, grid(samples_per_piece))  # (m, k, n)
    if tau.shape[1] < 2:
        return False
    reach = np.abs(tau).max(axis=1) + 2.0 * np.abs(np.diff(tau, axis=1)).max(axis=1)  # (m, n)
    return bool(np.all(reach <= limit))


def torque_dilation(trajectory: TimedCurve, robot: Robot, limit: ArrayLike, samples_per_piece: int = SAMPLES_PER_PIECE) -> float:
    """Smallest uniform time dilation f >= 1 after which the refined torque peaks are within ``limit``.

    Scaling every duration by f leaves the path and the normalised instants unchanged and
    gives ``tau(f) = (tau - g) / f² + g`` (``g`` the gravity torque there): at the refined peak
    instants the f each needs follows in closed form; repeated (at most 8 times) until the
    refined peaks are within the limits to 1e-12. ``inf`` when a peak is (nearly) all gravity
    beyond the limit: no speed helps.
    """
    L = check_torque_limit(limit, trajectory.n_joints)
    if clearly_within(trajectory, robot, L, samples_per_piece):
        return 1.0
    factor = 1.0
    traj = trajectory
    for _ in range(8):
        peak, when, _ = piece_torque_peaks(traj, robot, samples_per_piece)
        if np.all(peak <= L * (1.0 + 1e-12)):
            return factor
        q, qd, qdd, _ = traj.sample(np.clip(when.reshape(-1), traj.start_time, traj.end_time))
        g = robot.gravity(q)
        b = robot.inverse_dynamics(q, qd, qdd) - g
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = np.where(b > 0.0, (L - g) / b, np.where(b < 0.0, (L + g) / -b, np.inf))
        u = float(np.min(bound))
        if not u > 0.0:
            return float("inf")
        step = max(1.0 / np.sqrt(u), 1.0) * (1.0 + 1e-12)
        factor *= step
        traj = traj.scaled(step)
    return factor


class JointTorqueConstraint(PathConstraint):
    """Joint torque limits ``|tau_j| <= limit_j`` [N·m or N] of one arm: the one torque-limit object.

    Path timing (:func:`pinarms.optim.time_optimal`) reads :meth:`rows`: with ``u = s̈`` and
    ``x = ṡ²`` the inverse dynamics along ``q(s)`` is
    ``tau = M(q) q' u + (M(q) q'' + C(q, q') q') x + g(q)``, so the rows are ``a = M q'``,
    ``b = M q'' + C(q, q') q'`` and ``-limit - g <= a u + b x <= limit - g`` (three batched
    RNEA calls per grid; the split toppra makes for its own ``JointTorqueConstraint``).
    Gravity beyond a limit at some s leaves no feasible speed there (the timing says where).

    Segment timing (:func:`pinarms.optim.minimize_time`, :class:`pinarms.optim.TimingProblem`) reads
    :meth:`piece_ratios` and :meth:`minimal_scale` on a grid of ``samples_per_piece``
    instants per polynomial piece, and :meth:`refined_scale` for the refined peaks. The
    scaling law: with every duration multiplied by ``s`` the torque is
    ``tau(s) = (tau_1 - g) / s² + g``, so with ``u = 1 / s²`` every sample gives the linear
    condition ``-L <= b u + g <= L`` (``b = tau_1 - g``) and the smallest feasible total is
    ``1 / sqrt(min (L - g) / b  (b > 0)  or  (L + g) / |b|  (b < 0))`` (exact on the grid).

    Args:
        robot: the arm, with its payload (``robot.with_payload``); ``None``: the path's robot
            (path timing only).
        limit: torque limits, scalar or per joint [N·m or N]; ``None``: the robot's URDF efforts.
        columns: which of the path's joints are the robot's, in its order (a path in the joint
            space of several arms takes one constraint per arm); ``None``: all of them. With
            explicit columns the timing checks the rows densely instead of the refined peaks.
        samples_per_piece: grid instants per polynomial piece in segment timing (ends included).

    Raises:
        TrajectoryError: not a robot, a wrong-sized or non-positive limit, no URDF effort.
    """

    name = "joint torque"

    def __init__(self, robot: Robot | None = None, limit: ArrayLike | None = None, columns: ArrayLike | None = None,
                 samples_per_piece: int | None = None) -> None:
        if robot is not None and not hasattr(robot, "inverse_dynamics"):
            raise TrajectoryError(f"robot must be a robots.Robot (with inverse_dynamics), got {type(robot).__name__}")
        self.robot = robot
        self.limit = limit
        if robot is not None:
            self.limit = self._resolve(robot, int(robot.nq))[1]
        self.columns = None if columns is None else np.asarray(columns, dtype=int).reshape(-1)
        if robot is not None and self.columns is not None and self.columns.size != int(robot.nq):
            raise TrajectoryError(f"columns must name the robot's {int(robot.nq)} joints in the path, "
                                  f"got {self.columns.tolist()}")
        self.samples_per_piece = SAMPLES_PER_PIECE if samples_per_piece is None else samples_per_piece
        self.s = grid(self.samples_per_piece)

    def _resolve(self, robot: Any, n: int) -> tuple[Any, np.ndarray]:
        arm = self.robot if self.robot is not None else robot
        if arm is None:
            raise TrajectoryError("JointTorqueConstraint needs a robot: JointTorqueConstraint(robot=arm) or a path with one")
        _robot_joints(arm, n)
        given = self.limit
        limit = arm.effort_limit if given is None else given
        if given is None and not np.all(np.asarray(limit, dtype=float) > 0.0):
            raise TrajectoryError(f"robot '{arm.name}' has no effort limit for some joint in its URDF: give limit=[...]")
        return arm, check_torque_limit(limit, n)

    @property
    def n_joints(self) -> int:
        """Joints of the arm."""
        return int(self.robot.nq)

    # -- path timing --------------------------------------------------------------------
    def rows(self, samples: ArrayLike) -> PathRows:
        """Linear bounds on (s̈, ṡ²) at the samples (see the class docstring)."""
        c = slice(None) if self.columns is None else self.columns
        q, dq, ddq = samples.q[:, c], samples.dq[:, c], samples.ddq[:, c]
        n = q.shape[1]
        arm, L = self._resolve(getattr(samples.path, "robot", None), n)
        zero = np.zeros_like(q)
        g = arm.gravity(q).reshape(q.shape)
        a = arm.inverse_dynamics(q, zero, dq).reshape(q.shape) - g
        b = arm.inverse_dynamics(q, dq, ddq).reshape(q.shape) - g
        return PathRows(a, b, -L - g, L - g, tuple(f"torque of joint {j + 1}" for j in range(n)))

    def exact_dilation(self, trajectory: TimedCurve) -> float:
        """Uniform dilation making the timed trajectory's refined torque peaks meet the limits (:func:`torque_dilation`).

        1 with explicit ``columns`` (the rows are then checked densely by the timing).
        """
        if self.columns is not None:
            return 1.0
        traj = getattr(trajectory, "trajectory", trajectory)
        arm, L = self._resolve(None, traj.n_joints)
        return torque_dilation(traj, arm, L)

    # -- segment timing -----------------------------------------------------------------
    def _grid_torques(self, times: np.ndarray, coefs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Torques and positions (P, m, k, n) on the grid."""
        q, qd, qdd = piece_states(times, coefs, self.s)
        flat = q.reshape(-1, q.shape[-1])
        tau = self.robot.inverse_dynamics(flat, qd.reshape(flat.shape), qdd.reshape(flat.shape)).reshape(q.shape)
        return tau, q

    def piece_ratios(self, times: np.ndarray, coefs: np.ndarray) -> np.ndarray:
        """``max |tau| / L`` per piece and joint on the grid: (P, m, n)."""
        tau, _ = self._grid_torques(times, coefs)
        return np.abs(tau).max(axis=2) / self.limit

    def minimal_scale(self, times: np.ndarray, coefs: np.ndarray) -> np.ndarray:
        """Smallest time scale s (P,) meeting the torque limits on the grid (class docstring).

        ``times``/``coefs`` describe timings at any total; the answer multiplies those
        durations. ``inf`` where a sample cannot be held still (``|g| > L``).
        """
        tau, q = self._grid_torques(times, coefs)
        shape = q.shape
        g = self.robot.gravity(q.reshape(-1, shape[-1])).reshape(shape)
        P = shape[0]
        b = (tau - g).reshape(P, -1, shape[-1])
        g = g.reshape(P, -1, shape[-1])
        L = self.limit
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = np.where(b > 0.0, (L - g) / b, np.where(b < 0.0, (L + g) / -b, np.inf))
        u = np.min(bound.reshape(P, -1), axis=1)
        static = np.any((np.abs(g) > L).reshape(P, -1), axis=1)
        u = np.where(static, 0.0, np.maximum(u, 0.0))
        with np.errstate(divide="ignore"):
            return np.where(u > 0.0, 1.0 / np.sqrt(u), np.inf)

    def refined_scale(self, trajectory: TimedCurve) -> float:
        """Factor (>= 1) on every duration that brings the *refined* torque peaks under the limits.

        The grid misses the exact peak by a hair; the refined peaks and the scaling law at
        those instants give the factor (:func:`torque_dilation`).
        """
        return torque_dilation(trajectory, self.robot, self.limit, self.samples_per_piece)

    def holding_excess(self, positions: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``|g(q)|`` (..., n) at ``positions`` (..., n) and where it exceeds the limit (no speed helps there)."""
        q = np.asarray(positions, dtype=float)
        g = np.abs(self.robot.gravity(q.reshape(-1, q.shape[-1]))).reshape(q.shape)
        return g, g > self.limit
