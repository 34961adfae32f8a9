"""The segment-timing problem: turns segment durations into peaks, constraints, totals.

A :class:`TimingProblem` holds via points (m+1, n_joints), a trajectory family and
per-joint limits. For durations ``h`` (m,) it builds the trajectory with knot times
``[0, cumsum(h)]`` through :mod:`pinarms.planning` and reads its exact peaks. It is the bridge
between trajectories and the optimisers: the GA sees only arrays.

A population of durations (P, m) is evaluated in a few numpy calls: planning's batched
constructor (``piecewise_polynomial_batch``, ``multi_quintic_batch``,
``quintic_bspline_batch``) gives the coefficients of all P trajectories from one batched
solve, and :func:`pinarms.planning.piece_peaks_batch` peaks every piece of every individual in
one pass. Single timings go through the same code with P = 1.

Scaling laws used by the exact optimiser and by the final rescaling: with durations
``s * r`` (ratios ``r``, total ``s``), peak velocity scales as 1/s, acceleration as
1/s**2 and jerk as 1/s**3 (time scaling of the same curve), so the smallest feasible
total for given ratios is::

    s*(r) = max_j max( v_j(r) / V_j, sqrt(a_j(r) / A_j), cbrt(k_j(r) / J_j) )

where ``v, a, k`` are the peaks at total 1.
"""

from __future__ import annotations

import inspect
from typing import TYPE_CHECKING, Any, Callable, Protocol

import numpy as np

from pinarms.errors import InvalidInput
from pinarms.optim.errors import InfeasibleProblem, InvalidLimits, InvalidSettings
from pinarms.planning.torque import piece_states
from pinarms.optim.types import JointLimit

if TYPE_CHECKING:
    from pinarms.planning.torque import JointTorqueConstraint

__all__ = ["TimingProblem", "KINDS", "Builder", "BatchBuilder", "check_limit"]

#: Trajectory families known to :func:`pinarms.optim.minimize_time`.
KINDS = ("3-5-3", "multi-quintic", "quintic-bspline")

#: Relative margin under the limits kept by rescaled answers (round-off safety).
SAFETY = 1e-9

#: Factor on the default upper duration bound ``s0 * min(1, 4 / m)`` (see ``TimingProblem``).
DEFAULT_UPPER_MARGIN = 1.001


class _PeaksLike(Protocol):
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray


class _TrajectoryLike(Protocol):
    """What a custom builder must return (a :class:`pinarms.planning.Trajectory` does)."""

    knot_times: np.ndarray
    coefficients: np.ndarray

    def peaks(self) -> _PeaksLike: ...


#: Maps (knot times (m+1,), positions (m+1, n)) to a trajectory with ``peaks()``,
#: ``coefficients`` and ``knot_times`` (see ``_TrajectoryLike``).
Builder = Callable[[np.ndarray, np.ndarray], "_TrajectoryLike"]

#: Maps (knot times (P, m+1), positions (m+1, n)) to coefficients (P, m, K+1, n).
BatchBuilder = Callable[[np.ndarray, np.ndarray], np.ndarray]


def path_static_check(torque: JointTorqueConstraint, times: np.ndarray, coefs: np.ndarray) -> None:
    """Refuse a path (one timing's pieces) through a pose the arm cannot hold still, naming it.

    Where ``|g(q)| > L`` no timing of that path exists (slower only tends to ``g``).
    """
    q, _, _ = piece_states(np.atleast_2d(times)[:1], np.asarray(coefs)[:1], torque.s)
    q = q[0]  # (m, k, n)
    g, over = torque.holding_excess(q)
    if np.any(over):
        robot = torque.robot
        seg, k, j = (int(i) for i in np.argwhere(over)[0])
        raise InfeasibleProblem(
            f"robot '{robot.name}' cannot hold the path still between via points {seg} and {seg + 1} "
            f"(at {torque.s[k]:.0%} of that segment, q = {np.round(q[seg, k], 4).tolist()}): joint "
            f"{robot.joint_names[j]} needs {g[seg, k, j]:.4g} N·m against gravity (payload included), "
            f"its limit is {torque.limit[j]:.4g}; no timing helps: lighten the payload or change the path"
        )


def static_check(torque: JointTorqueConstraint, positions: np.ndarray) -> None:
    """Refuse via points the arm cannot even hold still (``|g(q)| > L``), naming joint and via point."""
    g, over = torque.holding_excess(positions)
    if np.any(over):
        robot = torque.robot
        k, j = (int(i) for i in np.argwhere(over)[0])
        raise InfeasibleProblem(
            f"robot '{robot.name}' cannot hold via point {k} still: joint {robot.joint_names[j]} needs "
            f"{g[k, j]:.4g} N·m against gravity (payload included), its limit is {torque.limit[j]:.4g}; "
            "lighten the payload or move the via point closer to the base"
        )


def check_limit(value: JointLimit | None, n_joints: int, name: str, required: bool) -> np.ndarray | None:
    """A per-joint limit (scalar or (n_joints,)) as a (n_joints,) positive finite array.

    Raises :class:`InvalidLimits` for <= 0, NaN/inf, values outside :data:`LIMIT_RANGE`, or a
    wrong shape; returns None for
    an optional limit left out.
    """
    if value is None:
        if required:
            raise InvalidLimits(f"{name} is required: give a positive limit per joint (SI units)")
        return None
    try:
        if np.iscomplexobj(value):
            raise TypeError("complex numbers")
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidLimits(f"{name}={value!r} is not numeric: give a positive number per "
                            "joint") from exc
    if arr.ndim > 1 or (arr.ndim == 1 and arr.size not in (1, n_joints)):
        raise InvalidLimits(f"{name} has shape {arr.shape}: give a scalar or {n_joints} values "
                            "(one per joint)")
    arr = np.broadcast_to(arr.reshape(-1) if arr.ndim else arr, (n_joints,)).astype(float)
    if not np.all(np.isfinite(arr)):
        raise InvalidLimits(f"{name}={arr.tolist()} holds NaN or inf: give finite limits")
    if np.any(arr <= 0.0):
        raise InvalidLimits(f"{name}={arr.tolist()} must be > 0 for every joint")
    if np.any(arr < LIMIT_RANGE[0]) or np.any(arr > LIMIT_RANGE[1]):
        raise InvalidLimits(f"{name}={arr.tolist()} lies outside [{LIMIT_RANGE[0]:g}, {LIMIT_RANGE[1]:g}] (SI): no "
                            "physical joint has such a limit, and the timing would overflow float64")
    return arr


#: Range of every kinematic limit accepted (SI units: rad/s or m/s, rad/s², rad/s³, ...).
LIMIT_RANGE = (1e-9, 1e12)


def _planning_builders(kind: str, options: dict[str, Any]) -> tuple[Builder, BatchBuilder]:
    """The planning constructor of ``kind`` for one timing and for a population."""
    from pinarms import planning  # optim sits above planning in the one-way flow

    if kind == "3-5-3":
        single, batch = planning.piecewise_polynomial, planning.piecewise_polynomial_batch
        options = {"degrees": (3, 5, 3), **options}
    elif kind == "multi-quintic":
        single, batch = planning.multi_quintic, planning.multi_quintic_batch
    elif kind == "quintic-bspline":
        single, batch = planning.quintic_bspline, planning.quintic_bspline_batch
    else:
        raise InvalidInput(f"kind={kind!r} is not a known trajectory family: use one of {KINDS}")
    known = [p for p in inspect.signature(batch).parameters if p not in ("times", "positions")]
    unknown = sorted(set(options) - set(known))
    if unknown:
        raise InvalidSettings(f"trajectory_options {unknown} are not options of the {kind!r} "
                              f"constructor; it takes {known}")
    return (lambda t, q: single(t, q, **options), lambda t, q: batch(t, q, **options))


def _quintic_rule(kind: str, options: dict[str, Any]) -> bool | None:
    """Whether the multi-quintic via velocities follow the sign-of-slopes rule (True), are zero (False),
    or neither (None: given arrays, or other families)."""
    if kind != "multi-quintic" or set(options) - {"velocities", "accelerations"}:
        return None
    zero = (None, "zero")
    velocities, accelerations = options.get("velocities"), options.get("accelerations")
    if not (isinstance(accelerations, str) or accelerations is None) or accelerations not in zero:
        return None
    if isinstance(velocities, str) and velocities == "heuristic":
        return True
    return False if (isinstance(velocities, str) or velocities is None) and velocities in zero else None


class TimingProblem:
    """Minimum-time (and time-jerk) timing of a trajectory through fixed via points.

    Args:
        positions: (m+1, n_joints) or (m+1,) via points, SI (rad or m).
        kind: ``"3-5-3"`` (exactly 4 via points), ``"multi-quintic"`` or ``"quintic-bspline"``.
        vmax: Velocity limit per joint (scalar or (n_joints,)), rad/s or m/s. Required.
        amax: Acceleration limit per joint, rad/s^2 or m/s^2, or None.
        jmax: Jerk limit per joint, rad/s^3 or m/s^3, or None.
        bounds: Segment-duration bounds (s): (m, 2) rows, or one (lower, upper) pair for
            all segments, or None for defaults (see :attr:`bounds`).
        trajectory_options: Extra keyword arguments for the planning constructor (e.g.
            ``velocities=0`` for multi-quintic rest at every via point).
        builder: Replace the planning constructor (advanced; tests and custom families).
            A custom builder is called once per individual (no batched form).
        torque: Joint-torque limits of a robot (:class:`pinarms.planning.JointTorqueConstraint`),
            checked on a grid per piece beside the exact v/a/jerk peaks, with their own
            scaling law in :meth:`minimal_scale`; None: kinematic limits only.
    """

    def __init__(self, positions: np.ndarray, kind: str, vmax: JointLimit | None, amax: JointLimit | None = None,
                 jmax: JointLimit | None = None, bounds: np.ndarray | tuple[float, float] | None = None,
                 trajectory_options: dict[str, object] | None = None,
                 builder: Builder | None = None, torque: JointTorqueConstraint | None = None) -> None:
        try:
            if np.iscomplexobj(positions):
                raise TypeError("complex numbers")
            q = np.asarray(positions, dtype=float)
        except (TypeError, ValueError):
            raise InvalidInput(f"positions={positions!r} are not numeric: give (m+1,) or "
                               "(m+1, n_joints) via points (rad or m)") from None
        if q.ndim == 1:
            q = q[:, None]
        if q.ndim != 2 or q.shape[0] < 2:
            raise InvalidInput(f"positions of shape {np.shape(positions)}: give (m+1,) or "
                               "(m+1, n_joints) via points, at least 2")
        if not np.all(np.isfinite(q)):
            raise InvalidInput("positions hold NaN or inf: give finite via points (rad or m)")
        if kind not in KINDS:
            raise InvalidInput(f"kind={kind!r} is not a known trajectory family: use one of "
                               f"{KINDS}")
        if kind == "3-5-3" and q.shape[0] != 4:
            raise InvalidInput(f"kind='3-5-3' has 3 segments and needs 4 via points, got "
                               f"{q.shape[0]}; for another count use 'multi-quintic' or "
                               "'quintic-bspline'")
        self.positions = q
        self.kind = kind
        self.n_segments = q.shape[0] - 1
        self.n_joints = q.shape[1]
        self.vmax = check_limit(vmax, self.n_joints, "vmax", required=True)
        self.amax = check_limit(amax, self.n_joints, "amax", required=False)
        self.jmax = check_limit(jmax, self.n_joints, "jmax", required=False)
        if np.all(np.ptp(q, axis=0) == 0.0):
            raise InvalidInput("positions do not move (all via points equal): nothing to time")
        self.trajectory_options = dict(trajectory_options or {})
        #: multi-quintic through the planning constructor with via velocities zero (False) or by the
        #: sign-of-slopes rule (True) and zero via accelerations: peaks by a compiled loop; else None
        self._quintic_rule = _quintic_rule(kind, self.trajectory_options) if builder is None else None
        if builder is None:
            self._build, self._build_batch = _planning_builders(kind, self.trajectory_options)
        else:
            self._build, self._build_batch = builder, None
        self.evaluations = 0
        self.torque = torque
        if torque is not None:
            if torque.n_joints != self.n_joints:
                raise InvalidSettings(f"the torque limits are for {torque.n_joints} joints but the via points have "
                                      f"{self.n_joints}: give every joint of the arm")
            static_check(torque, q)
            equal = np.full((1, self.n_segments), 1.0 / self.n_segments)
            path_static_check(torque, *self.coefficients_batch(equal))
            self.evaluations = 0
        self.bounds = self._check_bounds(bounds)

    # -- trajectories and peaks -------------------------------------------------------
    def knot_times(self, durations: np.ndarray) -> np.ndarray:
        """Knot times (m+1,) (s) from segment durations (m,)."""
        return np.concatenate([[0.0], np.cumsum(np.asarray(durations, dtype=float))])

    def trajectory(self, durations: np.ndarray) -> Any:
        """The planning trajectory for segment durations (m,) (s)."""
        return self._build(self.knot_times(durations), self.positions)

    def peaks(self, durations: np.ndarray) -> np.ndarray:
        """Exact peaks as (3, n_joints): |velocity|, |acceleration|, |jerk| maxima."""
        return self.peaks_batch(np.asarray(durations, dtype=float)[None])[0]

    def minimal_scale(self, ratios: np.ndarray) -> float:
        """s*(r): the smallest total (s) meeting every limit with durations ``s * r``."""
        return float(self.minimal_scale_batch(np.asarray(ratios, dtype=float)[None])[0])

    def minimal_scale_batch(self, ratios: np.ndarray) -> np.ndarray:
        """s*(r) for a population of ratios (pop, m) -> (pop,) (s); rows need not sum to 1."""
        from pinarms import planning

        r = np.atleast_2d(np.asarray(ratios, dtype=float))
        r = r / r.sum(axis=1, keepdims=True)
        from pinarms.planning import extrema

        if self._quintic_rule is not None and self.torque is None and extrema.COMPILED:  # compiled: the same peaks
            self.evaluations += r.shape[0]
            times = np.concatenate([np.zeros((r.shape[0], 1)), np.cumsum(r, axis=1)], axis=1)
            pk = planning.multi_quintic_peaks_batch(times, self.positions, self._quintic_rule)
        else:
            times, coefs = self.coefficients_batch(r)
            pk = planning.piece_peaks_batch(times, coefs).max(axis=2)  # (pop, 3, n) at total 1
        s = np.max(pk[:, 0] / self.vmax, axis=1)
        if self.torque is not None:
            s = np.maximum(s, self.torque.minimal_scale(times, coefs))
        if self.amax is not None:
            s = np.maximum(s, np.max(np.sqrt(pk[:, 1] / self.amax), axis=1))
        if self.jmax is not None:
            s = np.maximum(s, np.max(np.cbrt(pk[:, 2] / self.jmax), axis=1))
        return s

    # -- arrays for the GA --------------------------------------------------------------
    def limit_ratios(self, durations: np.ndarray) -> np.ndarray:
        """Peak / limit per active limit and joint, flattened (n_con,) (torque last, when set)."""
        return self.limit_ratios_batch(np.asarray(durations, dtype=float)[None])[0]

    def coefficients_batch(self, population: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Knot times (pop, m'+1) (s) and piece coefficients (pop, m', K+1, n) for durations (pop, m).

        With a planning family, one call of its batched constructor (m' = m); with a
        custom ``builder``, one call per individual (its pieces, m' of them, may differ
        from the segments). Counts ``pop`` evaluations.
        """
        h = np.atleast_2d(np.asarray(population, dtype=float))
        self.evaluations += h.shape[0]
        times = np.concatenate([np.zeros((h.shape[0], 1)), np.cumsum(h, axis=1)], axis=1)
        if self._build_batch is not None:
            return times, self._build_batch(times, self.positions)
        trajs = [self._build(row, self.positions) for row in times]
        coefs = np.stack([np.asarray(t.coefficients, dtype=float) for t in trajs])
        return np.stack([np.asarray(t.knot_times, dtype=float) for t in trajs]), coefs

    def piece_peaks_batch(self, population: np.ndarray) -> np.ndarray:
        """Exact peaks per polynomial piece, (pop, 3, pieces, n_joints), for durations (pop, m).

        The coefficients of all individuals come from :meth:`coefficients_batch`; the exact
        peak search (:func:`pinarms.planning.piece_peaks_batch`) then runs once for the whole
        population.
        """
        from pinarms import planning

        times, coefs = self.coefficients_batch(population)
        return planning.piece_peaks_batch(times, coefs)

    def _piece_ratios_and_torque(self, population: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """Peaks per piece (pop, 3, pieces, n) and torque ratios per piece (pop, pieces, n) or None."""
        from pinarms import planning

        times, coefs = self.coefficients_batch(population)
        pk = planning.piece_peaks_batch(times, coefs)
        tq = None if self.torque is None else self.torque.piece_ratios(times, coefs)
        return pk, tq

    def peaks_batch(self, population: np.ndarray) -> np.ndarray:
        """Exact peaks for a population of durations (pop, m) -> (pop, 3, n_joints)."""
        return self.piece_peaks_batch(population).max(axis=2)

    def _limits_stack(self) -> tuple[np.ndarray, np.ndarray]:
        """(kinds,) indices of the active limits and their values (kinds, n_joints)."""
        kinds = [0] + ([1] if self.amax is not None else []) + ([2] if self.jmax is not None else [])
        values = [self.vmax, self.amax, self.jmax]
        return np.array(kinds), np.stack([values[k] for k in kinds])

    def piece_limit_ratios_batch(self, population: np.ndarray) -> np.ndarray:
        """Peak / limit per active limit, piece and joint: (pop, n_con * pieces)."""
        pk, tq = self._piece_ratios_and_torque(population)
        kinds, lim = self._limits_stack()
        ratios = pk[:, kinds] / lim[None, :, None, :]
        ratios = ratios.reshape(ratios.shape[0], -1)
        if tq is not None:
            ratios = np.concatenate([ratios, tq.reshape(tq.shape[0], -1)], axis=1)
        return ratios

    def limit_ratios_batch(self, population: np.ndarray) -> np.ndarray:
        """Peak / limit for a population (pop, m) -> (pop, n_con) (torque last, when set)."""
        pk, tq = self._piece_ratios_and_torque(population)
        pk = pk.max(axis=2)
        parts = [pk[:, 0] / self.vmax]
        if self.amax is not None:
            parts.append(pk[:, 1] / self.amax)
        if self.jmax is not None:
            parts.append(pk[:, 2] / self.jmax)
        if tq is not None:
            parts.append(tq.max(axis=1))
        return np.concatenate(parts, axis=1)

    def constraints(self, population: np.ndarray) -> np.ndarray:
        """``peak / limit * (1 + SAFETY) - 1`` for durations (pop, m) -> (pop, n_con).

        Feasible (<= 0) keeps a relative margin of ``SAFETY`` under every limit, so that
        answers stay feasible through round-off. Rows repeated in the population
        (elites, uncrossed copies) are computed once.
        """
        h = np.atleast_2d(np.asarray(population, dtype=float))
        unique, inverse = np.unique(h, axis=0, return_inverse=True)
        return self.limit_ratios_batch(unique)[inverse.reshape(-1)] * (1.0 + SAFETY) - 1.0

    def is_feasible(self, durations: np.ndarray, rtol: float = 0.0) -> bool:
        """Whether every peak is within its limit (times 1 + rtol) and h within bounds."""
        h = np.asarray(durations, dtype=float)
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        if np.any(h < lo * (1 - 1e-12)) or np.any(h > hi * (1 + 1e-12)):
            return False
        return bool(np.all(self.limit_ratios(h) <= 1.0 + rtol))

    # -- bounds --------------------------------------------------------------------------
    def reference_total(self) -> float:
        """s* for equal segment durations: a feasible total every default bound contains."""
        return self.minimal_scale(np.full(self.n_segments, 1.0 / self.n_segments))

    def _check_bounds(self, bounds: Any) -> np.ndarray:
        m = self.n_segments
        if bounds is None:
            # The upper bound keeps a 0.1 % margin over s0 * min(1, 4/m): with one segment
            # the only feasible durations are s0 (1 + SAFETY) and above.
            s0 = self.reference_total()
            return np.tile([s0 / (20.0 * m), s0 * min(1.0, 4.0 / m) * DEFAULT_UPPER_MARGIN],
                           (m, 1))
        try:
            if np.iscomplexobj(bounds):
                raise TypeError("complex numbers")
            b = np.asarray(bounds, dtype=float)
        except (TypeError, ValueError):
            raise InvalidSettings(f"bounds={bounds!r} are not numeric: give (lower, upper) in s, "
                                  f"or ({m}, 2) rows") from None
        if b.shape == (2,):
            b = np.tile(b, (m, 1))
        if b.shape != (m, 2):
            raise InvalidSettings(f"bounds of shape {b.shape}: give (lower, upper) in s, or "
                                  f"({m}, 2) rows, one per segment")
        if not np.all(np.isfinite(b)) or np.any(b[:, 0] <= 0.0) or np.any(b[:, 0] > b[:, 1]):
            raise InvalidSettings(f"bounds {b.tolist()}: need 0 < lower <= upper (s), finite")
        return b.copy()
