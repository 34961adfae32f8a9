"""The joint-space trajectory: a piecewise polynomial in time, one column per joint.

Every trajectory family of :mod:`pinarms.planning` (single polynomials, 3-5-3, multi-segment
quintics, quintic B-splines, trapezoidal and double-S profiles) is converted to one common
representation, so that sampling, exact peak search, limit checks, time scaling and
concatenation are written once and vectorised over instants and joints:

* ``breaks`` — knot times ``t_0 < t_1 < ... < t_m`` (s), shape ``(m+1,)``;
* ``coefficients`` — shape ``(m, K+1, n_joints)``: on piece ``i`` and for
  ``tau = t - t_i`` in ``[0, t_{i+1} - t_i]`` (s), joint ``j`` is at
  ``q_j(t) = sum_k coefficients[i, k, j] * tau**k`` (ascending powers, the joint's unit:
  rad for revolute, m for prismatic joints).

A trajectory knows nothing about limits or optimisers (the split follows toppra: path,
constraints and algorithm are separate objects). :meth:`Trajectory.check` takes a
:class:`pinarms.planning.JointLimits` spec and returns a :class:`pinarms.planning.LimitReport`
(:mod:`pinarms.planning.limit_report`). The arithmetic on the coefficient arrays (derivatives,
re-expansion, blocked products) is :mod:`pinarms.planning.poly_pieces`.

Peaks are *exact*: on each piece the extrema of ``|d^r q / dt^r|`` are at the piece ends
or at real roots of the next derivative, which are found for all pieces, joints and
derivative orders at once (closed form up to degree 3, batched companion-matrix
eigenvalues above; :mod:`pinarms.planning.extrema`, which also peaks whole populations).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning._inputs import finite_array, scalar
from pinarms.planning.errors import OutOfTimeRange, TrajectoryError
from pinarms.planning.extrema import normalised_pieces, piece_extrema
from pinarms.planning.limit_report import (LimitReport, Violation, derivative_violations, limit_report, limited_orders,
                                           position_violations, torque_violations)
from pinarms.planning.poly_pieces import derivative_stack, evaluate_by_piece, pad_degree

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot

__all__ = ["Trajectory", "Peaks"]

#: Most instants :meth:`Trajectory.at_rate` produces (10 million: 1.3 GB for 4 arrays of 4 joints).
MAX_SAMPLES = 10_000_000

#: Longest trajectory accepted (s): 10⁹ s is about 32 years; anything longer comes from limits or
#: times beyond any physical motion, and its powers of time would overflow float64 when sampled.
MAX_DURATION = 1e9


@dataclass(frozen=True, eq=False)
class Peaks:
    """Per-joint maxima of ``|qd|``, ``|qdd|`` and ``|qddd|`` over a whole trajectory.

    Each field has shape ``(n_joints,)`` in the joint's unit per s, s², s³
    (rad/s, rad/s², rad/s³ for revolute joints). Computed exactly, not by sampling.
    """

    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray

    def as_dict(self) -> dict[str, list[float]]:
        """JSON-able form ``{"velocity": [...], "acceleration": [...], "jerk": [...]}``."""
        return {k: getattr(self, k).tolist() for k in ("velocity", "acceleration", "jerk")}


class Trajectory:
    """A joint trajectory: piecewise polynomial in time, per joint (see the module docstring).

    Build one with the constructors of :mod:`pinarms.planning` (``polynomial``,
    ``piecewise_polynomial``, ``multi_quintic``, ``quintic_bspline``, ``trapezoidal``,
    ``double_s``) or directly from ``breaks`` (s, strictly increasing, (m+1,)) and
    ``coefficients`` ((m, K+1, n_joints), ascending powers of the time since each piece's
    start). ``definition`` is the JSON-able recipe :func:`pinarms.planning.from_definition` rebuilds
    it from; when omitted the raw breaks and coefficients are used.
    """

    def __init__(self, breaks: ArrayLike, coefficients: ArrayLike, definition: dict | None = None) -> None:
        b = finite_array(breaks, "breaks")
        c = finite_array(coefficients, "coefficients")
        if b.ndim != 1 or b.size < 2:
            raise TrajectoryError(f"breaks must be a 1-D array of at least 2 instants (s), got shape {b.shape}")
        if np.any(np.diff(b) <= 0.0):
            i = int(np.argmax(np.diff(b) <= 0.0))
            raise TrajectoryError(f"breaks must be strictly increasing; breaks[{i + 1}] = {float(b[i + 1])!r} <= {float(b[i])!r}")
        if b[-1] - b[0] > MAX_DURATION:
            raise TrajectoryError(
                f"the trajectory would last {float(b[-1] - b[0]):.3g} s, more than {MAX_DURATION:.0e} s (about 32 years): "
                f"its limits or times are beyond any physical motion"
            )
        if c.ndim == 2:
            c = c[:, :, None]
        if c.ndim != 3 or c.shape[0] != b.size - 1 or c.shape[1] < 1 or c.shape[2] < 1:
            raise TrajectoryError(
                f"coefficients must have shape ({b.size - 1}, degree+1, n_joints) for {b.size} breaks, got {c.shape}"
            )
        self._breaks = b.copy()
        self._coefs = c.copy()
        self._breaks.flags.writeable = False
        self._coefs.flags.writeable = False
        self._definition = definition
        self._stack: np.ndarray | None = None
        self._norm: np.ndarray | None = None
        self._peaks: np.ndarray | None = None

    # ------------------------------------------------------------------ basic data
    @property
    def n_joints(self) -> int:
        """Number of joints (columns)."""
        return self._coefs.shape[2]

    @property
    def n_segments(self) -> int:
        """Number of polynomial pieces."""
        return self._coefs.shape[0]

    @property
    def degree(self) -> int:
        """Highest polynomial degree stored (K); lower-degree pieces are zero padded."""
        return self._coefs.shape[1] - 1

    @property
    def start_time(self) -> float:
        """First knot time (s)."""
        return float(self._breaks[0])

    @property
    def end_time(self) -> float:
        """Last knot time (s)."""
        return float(self._breaks[-1])

    @property
    def duration(self) -> float:
        """Total duration (s)."""
        return float(self._breaks[-1] - self._breaks[0])

    @property
    def knot_times(self) -> np.ndarray:
        """Piece boundaries (s), shape (m+1,) (a copy)."""
        return self._breaks.copy()

    @property
    def segment_durations(self) -> np.ndarray:
        """Piece durations (s), shape (m,)."""
        return np.diff(self._breaks)

    @property
    def coefficients(self) -> np.ndarray:
        """Coefficients (m, K+1, n_joints), ascending powers of the time since the piece start (a copy)."""
        return self._coefs.copy()

    @property
    def definition(self) -> dict:
        """JSON-able recipe (kind, knot times, via points, options) for :func:`pinarms.planning.from_definition`."""
        if self._definition is not None:
            return _json_copy(self._definition)
        return {
            "kind": "ppoly",
            "breaks": self._breaks.tolist(),
            "coefficients": self._coefs.tolist(),
        }

    def __repr__(self) -> str:
        kind = (self._definition or {}).get("kind", "ppoly")
        return (
            f"Trajectory(kind={kind!r}, n_joints={self.n_joints}, n_segments={self.n_segments}, "
            f"degree={self.degree}, t=[{self.start_time:g}, {self.end_time:g}] s)"
        )

    # -------------------------------------------------------------------- sampling
    def _derivative_stack(self) -> np.ndarray:
        """(m, K+1, 4*n): coefficients of q, qd, qdd, qddd side by side (cached)."""
        if self._stack is None:
            self._stack = derivative_stack(self._coefs)
        return self._stack

    def _check_times(self, t: Any) -> tuple[np.ndarray, bool]:
        if t.__class__ is np.ndarray and t.dtype == np.float64 and t.ndim == 1 and t.size:
            # fast path: min and max are NaN/±inf when any entry is, so two reductions check it all
            lo, hi = float(t.min()), float(t.max())
            if self._breaks[0] <= lo and hi <= self._breaks[-1]:  # False for NaN
                return t, False
        arr = finite_array(t, "t")
        scalar = arr.ndim == 0
        arr = np.atleast_1d(arr)
        if arr.ndim != 1:
            raise TrajectoryError(f"t must be a scalar or a 1-D array of instants (s), got shape {arr.shape}")
        t0, t1 = self._breaks[0], self._breaks[-1]
        tol = 1e-12 * max(1.0, abs(t0), abs(t1))
        if arr.size and (arr.min() < t0 - tol or arr.max() > t1 + tol):
            bad = arr[(arr < t0 - tol) | (arr > t1 + tol)][0]
            raise OutOfTimeRange(
                f"t = {float(bad)!r} s is outside the trajectory's time range [{float(t0)!r}, {float(t1)!r}] s; "
                "sample within it (a trajectory does not extrapolate)"
            )
        return np.clip(arr, t0, t1), scalar

    def sample(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity, acceleration and jerk at the instants ``t`` (s).

        Returns ``(q, qd, qdd, qddd)``, each ``(len(t), n_joints)`` (or ``(n_joints,)`` for a
        scalar ``t``). At an interior knot the piece that starts there is used. Raises
        :class:`pinarms.planning.errors.OutOfTimeRange` for instants outside
        ``[start_time, end_time]`` (beyond a 1e-12 relative tolerance, which is clipped).
        """
        tt, scalar = self._check_times(t)
        n = self.n_joints
        D = self._derivative_stack()
        m = self.n_segments
        if m == 1:
            seg = None
            tau = tt - self._breaks[0]
        else:
            seg = np.clip(np.searchsorted(self._breaks, tt, side="right") - 1, 0, m - 1)
            tau = tt - self._breaks[seg]
        # τ^k by running products (a float power per entry costs 10x), each power a contiguous row;
        # the product below reads the transposed view without copying
        rows = np.empty((self.degree + 1, tt.size))
        rows[0] = 1.0
        with np.errstate(over="ignore", invalid="ignore"):
            for k in range(1, self.degree + 1):
                np.multiply(rows[k - 1], tau, out=rows[k])
        powers = rows.T
        out = np.empty((tt.size, 4 * n))
        with np.errstate(over="ignore", invalid="ignore"):
            evaluate_by_piece(powers, D, seg, out)
            total = np.add.reduce(out, axis=None)  # NaN/inf if any entry is (or if the sum overflows: full check)
        if not math.isfinite(total) and not np.all(np.isfinite(out)):
            i = int(np.argmax(~np.all(np.isfinite(out), axis=1)))
            raise TrajectoryError(
                f"the trajectory's values overflow float64 at t = {float(tt[i])!r} s (its times or coefficients are "
                f"beyond any physical motion: check the limits and times it was built from)"
            )
        q, qd, qdd, qddd = (out[:, r * n : (r + 1) * n] for r in range(4))
        if scalar:
            return q[0].copy(), qd[0].copy(), qdd[0].copy(), qddd[0].copy()
        return q, qd, qdd, qddd

    def __call__(self, t: ArrayLike) -> np.ndarray:
        """Positions only: ``sample(t)[0]``."""
        return self.sample(t)[0]

    def at_rate(self, hz: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Sample at ``hz`` (1/s): instants ``start + k/hz`` plus the end instant.

        Returns ``(t, q, qd, qdd, qddd)``; ``t`` is (N,), the others (N, n_joints).
        """
        rate = scalar(hz, "hz")
        if rate <= 0.0:
            raise TrajectoryError(f"hz must be positive, got {hz!r}")
        count = int(math.floor(self.duration * rate * (1.0 + 1e-12))) + 1
        if count > MAX_SAMPLES:
            raise TrajectoryError(
                f"hz = {rate:g} over {self.duration:g} s gives {count} instants, more than {MAX_SAMPLES}; "
                "lower the rate or sample a sub-interval with sample(t)"
            )
        t = self.start_time + np.arange(count) / rate
        t = t[t < self.end_time - 1e-9 / rate]
        t = np.append(t, self.end_time)
        return (t, *self.sample(t))

    # ---------------------------------------------------------------- exact extrema
    def _normalised(self) -> np.ndarray:
        """Coefficients (m, n, K+1) of each piece in normalised time s = tau / h in [0, 1] (cached)."""
        if self._norm is None:
            self._norm = normalised_pieces(self._coefs, np.diff(self._breaks))
        return self._norm

    def _extrema(self, orders: tuple[int, ...], with_times: bool = True) -> tuple[np.ndarray, Any]:
        """Values and times of the candidate extrema of derivatives ``orders`` per piece.

        Returns ``(values, times)``, each (len(orders), m, n, C): the derivative of order r
        (in the joint's unit / s^r) at the piece ends and at every root of the next
        derivative within the piece (:func:`pinarms.planning.extrema.piece_extrema`). Max/min over
        the last axis are the exact extrema.
        """
        h = np.diff(self._breaks)
        values, s = piece_extrema(self._normalised(), h, orders)
        if not with_times:
            return values, None
        o, m, n = values.shape[:3]
        times = self._breaks[:-1][None, :, None, None] + s.reshape(o, m, n, -1) * h[None, :, None, None]
        return values, times

    def peaks(self) -> Peaks:
        """Exact per-joint maxima of |velocity|, |acceleration| and |jerk| over the whole duration.

        Found once per trajectory (it is immutable: the root searches over every piece are its
        costliest query); each call returns its own arrays."""
        if self._peaks is None:
            values, _ = self._extrema((1, 2, 3), with_times=False)
            self._peaks = np.abs(values).max(axis=(1, 3))  # (3, n)
        top = self._peaks.copy()
        return Peaks(velocity=top[0], acceleration=top[1], jerk=top[2])

    def position_range(self) -> tuple[np.ndarray, np.ndarray]:
        """Exact per-joint minimum and maximum position over the whole duration, each (n_joints,)."""
        values, _ = self._extrema((0,), with_times=False)
        return values[0].min(axis=(0, 2)), values[0].max(axis=(0, 2))

    def check(self, limits: JointLimits, rtol: float = 1e-9, *, robot: Robot | None = None) -> LimitReport:
        """Check against a :class:`pinarms.planning.JointLimits`; report every violation.

        A value counts as a violation when it exceeds the limit by more than ``rtol``
        relative (so an optimised trajectory that touches a limit passes). One
        :class:`Violation` is reported per joint, kind and piece, at the time of the worst
        value on that piece; the list is sorted by time.

        Torque limits (``limits.torque``) need ``robot`` (a :class:`pinarms.robots.Robot`, with its
        payload if it carries one): its inverse dynamics give the torques, peaked per piece
        on a dense grid refined around each maximum (:mod:`pinarms.planning.torque`). With a robot
        the report names the joints.
        """
        from pinarms.planning.limits import JointLimits

        if not isinstance(limits, JointLimits):
            raise TrajectoryError(f"limits must be a planning.JointLimits, got {type(limits).__name__}")
        n = self.n_joints
        found: list[Violation] = []
        if limits.torque is not None:
            if robot is None:
                raise TrajectoryError(
                    "torque limits need the robot whose inverse dynamics give the torques: check(limits, robot=arm)"
                )
            from pinarms.planning.torque import piece_torque_peaks

            lim = limits.for_joints("torque", n)
            peak, when, _ = piece_torque_peaks(self, robot)
            found += torque_violations(peak, when, lim, rtol)
        orders = limited_orders(limits)
        if orders:
            found += derivative_violations(*self._extrema(orders), orders, limits, n, rtol)
        if limits.lower is not None or limits.upper is not None:
            values, times = self._extrema((0,))
            found += position_violations(values[0], times[0], limits, n, rtol)
        return limit_report(found, robot, n)

    # --------------------------------------------------------------------- torques
    def torques(self, robot: Robot, t: ArrayLike) -> np.ndarray:
        """Joint torques [N·m or N] of ``robot`` following this trajectory at instants ``t`` [s].

        ``(len(t), nq)`` (or ``(nq,)`` for a scalar ``t``), by the robot's inverse dynamics
        (:func:`pinarms.planning.torque.torques`); a payload is the robot's own (``robot.with_payload``).
        """
        from pinarms.planning.torque import torques

        return torques(self, robot, t)

    def torque_peaks(self, robot: Robot, samples_per_piece: int | None = None) -> Any:
        """Per-joint peaks of ``|torque|`` with their instants (:class:`pinarms.planning.torque.TorquePeaks`).

        Dense grid per piece (default :data:`pinarms.planning.torque.SAMPLES_PER_PIECE`) refined
        around each maximum; see :mod:`pinarms.planning.torque`.
        """
        from pinarms.planning.torque import SAMPLES_PER_PIECE, torque_peaks

        return torque_peaks(self, robot, SAMPLES_PER_PIECE if samples_per_piece is None else samples_per_piece)

    # ------------------------------------------------------------ transformations
    def scaled(self, factor: float) -> "Trajectory":
        """Time-scaled copy: duration multiplied by ``factor`` (> 0), same start time.

        Velocities scale by 1/factor, accelerations by 1/factor², jerks by 1/factor³.
        """
        f = scalar(factor, "factor")
        if f <= 0.0:
            raise TrajectoryError(f"factor must be positive, got {factor!r}")
        with np.errstate(over="ignore", under="ignore", divide="ignore", invalid="ignore"):
            breaks = self._breaks[0] + (self._breaks - self._breaks[0]) * f
            coefs = self._coefs / (f ** np.arange(self.degree + 1))[None, :, None]
        if not (np.all(np.isfinite(breaks)) and np.all(np.isfinite(coefs)) and np.all(np.diff(breaks) > 0.0)):
            raise TrajectoryError(f"factor {f!r} takes the scaled trajectory beyond float64 (its times or "
                                  f"coefficients overflow or collapse); use a factor nearer 1")
        return Trajectory(breaks, coefs, {"kind": "scaled", "factor": f, "base": self.definition})

    def shifted(self, start_time: float) -> "Trajectory":
        """Copy that starts at ``start_time`` (s) instead of :attr:`start_time`."""
        t0 = scalar(start_time, "start_time")
        breaks = self._breaks - self._breaks[0] + t0
        return Trajectory(breaks, self._coefs, {"kind": "shifted", "start_time": t0, "base": self.definition})

    def concatenated(self, other: "Trajectory", atol: float = 1e-9) -> "Trajectory":
        """This trajectory followed by ``other`` (shifted in time to start where this one ends).

        The end position of ``self`` must equal the start position of ``other`` within
        ``atol`` per joint; velocities and accelerations are not required to match (a
        rest-to-rest pair joins smoothly, others may have a step in velocity: check it).
        """
        if not isinstance(other, Trajectory):
            raise TrajectoryError(f"can only concatenate a Trajectory, got {type(other).__name__}")
        if other.n_joints != self.n_joints:
            raise TrajectoryError(
                f"cannot concatenate a {other.n_joints}-joint trajectory to a {self.n_joints}-joint one"
            )
        q_end = self.sample(self.end_time)[0]
        q_start = other.sample(other.start_time)[0]
        gap = np.abs(q_end - q_start)
        if np.any(gap > atol):
            j = int(np.argmax(gap))
            raise TrajectoryError(
                f"position jump at the junction: joint {j} ends at {float(q_end[j])!r} but the next trajectory "
                f"starts at {float(q_start[j])!r} (|gap| {gap[j]:.3g} > atol {atol:g}); start it where this one ends"
            )
        width = max(self.degree, other.degree) + 1
        a = pad_degree(self._coefs, width)
        b = pad_degree(other._coefs, width)
        breaks = np.concatenate([self._breaks, other._breaks[1:] - other._breaks[0] + self._breaks[-1]])
        parts = []
        for d in (self.definition, other.definition):
            parts.extend(d["parts"] if d.get("kind") == "concatenated" else [d])
        return Trajectory(breaks, np.concatenate([a, b], axis=0), {"kind": "concatenated", "parts": parts})


# ---------------------------------------------------------------------- helpers
def _json_copy(obj: Any) -> Any:
    """Deep copy of a JSON-able structure (dicts, lists, numbers, strings)."""
    if isinstance(obj, dict):
        return {k: _json_copy(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_copy(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    return obj
