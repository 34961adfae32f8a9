"""Joint-torque limits in segment timing: a constraint object with its own scaling law.

A :class:`TorqueConstraint` holds a robot (with its payload) and torque limits ``L`` per
joint (N·m or N). For a population of timings it gives ``max |tau| / L`` per polynomial
piece and joint on a grid of ``samples_per_piece`` instants per piece (one RNEA batch for
the whole population, :func:`planning.torque.piece_torques`).

Scaling law. With every duration multiplied by ``s`` the same path is traversed with
``qd = qd_1 / s`` and ``qdd = qdd_1 / s²`` at the same normalised instants, and inverse
dynamics is quadratic in the speed: ``tau(s) = (tau_1 - g) / s² + g``, with ``tau_1`` the
torque at ``s = 1`` and ``g = g(q)`` the gravity torque (the Coriolis term ``C(q, qd) qd``
is quadratic in ``qd``, ``M(q) qdd`` linear in ``qdd``). With ``u = 1 / s²`` every sample
gives the linear condition ``-L <= b u + g <= L`` (``b = tau_1 - g``), so

    u_max = min over samples and joints of  (L - g) / b   (b > 0)   or   (L + g) / |b|   (b < 0)

and the smallest feasible total for given ratios is ``1 / sqrt(u_max)`` (exact on the grid);
any slower timing is feasible too as long as the arm can hold every sample still
(``|g| <= L``). Where it cannot, no timing exists: :class:`InfeasibleProblem` names the joint
and the instant.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms.optim.errors import InfeasibleProblem, InvalidLimits, InvalidSettings
from pinarms.optim.problem import check_limit

__all__ = ["TorqueConstraint", "torque_constraint"]


class TorqueConstraint:
    """Torque limits of ``robot`` (payload included) on the trajectories of a timing problem.

    Args:
        robot: a :class:`robots.Robot` (``robot.with_payload(...)`` for a load).
        limit: (nq,) or scalar torque limits [N·m or N], > 0.
        samples_per_piece: grid instants per polynomial piece (ends included).
    """

    def __init__(self, robot: Any, limit: Any, samples_per_piece: int | None = None) -> None:
        from pinarms.planning import torque as ptorque

        if not hasattr(robot, "inverse_dynamics"):
            raise InvalidSettings(f"robot must be a robots.Robot, got {type(robot).__name__}")
        self.robot = robot
        self.limit = check_limit(limit, int(robot.nq), "torque limit [N·m or N]", required=True)
        self.samples_per_piece = ptorque.SAMPLES_PER_PIECE if samples_per_piece is None else samples_per_piece
        self.s = ptorque.grid(self.samples_per_piece)

    @property
    def n_joints(self) -> int:
        return int(self.robot.nq)

    def _torques(self, times: np.ndarray, coefs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Torques and positions (P, m, k, n) on the grid."""
        from pinarms.planning.torque import piece_states

        q, qd, qdd = piece_states(times, coefs, self.s)
        flat = q.reshape(-1, q.shape[-1])
        tau = self.robot.inverse_dynamics(flat, qd.reshape(flat.shape), qdd.reshape(flat.shape)).reshape(q.shape)
        return tau, q

    def piece_ratios(self, times: np.ndarray, coefs: np.ndarray) -> np.ndarray:
        """``max |tau| / L`` per piece and joint on the grid: (P, m, n)."""
        tau, _ = self._torques(times, coefs)
        return np.abs(tau).max(axis=2) / self.limit

    def path_static_check(self, times: np.ndarray, coefs: np.ndarray) -> None:
        """Refuse a path (one timing's pieces) through a pose the arm cannot hold still, naming it.

        Where ``|g(q)| > L`` no timing of that path exists (slower only tends to ``g``).
        """
        from pinarms.planning.torque import piece_states

        q, _, _ = piece_states(np.atleast_2d(times)[:1], np.asarray(coefs)[:1], self.s)
        q = q[0]  # (m, k, n)
        g = np.abs(self.robot.gravity(q.reshape(-1, q.shape[-1]))).reshape(q.shape)
        over = g > self.limit
        if np.any(over):
            seg, k, j = (int(i) for i in np.argwhere(over)[0])
            raise InfeasibleProblem(
                f"robot '{self.robot.name}' cannot hold the path still between via points {seg} and {seg + 1} "
                f"(at {self.s[k]:.0%} of that segment, q = {np.round(q[seg, k], 4).tolist()}): joint "
                f"{self.robot.joint_names[j]} needs {g[seg, k, j]:.4g} N·m against gravity (payload included), "
                f"its limit is {self.limit[j]:.4g}; no timing helps: lighten the payload or change the path"
            )

    def minimal_scale(self, times: np.ndarray, coefs: np.ndarray) -> np.ndarray:
        """Smallest time scale s (P,) meeting the torque limits on the grid (module docstring).

        ``times``/``coefs`` describe timings at any total; the answer multiplies those
        durations. ``inf`` where a sample cannot be held still (``|g| > L``).
        """
        tau, q = self._torques(times, coefs)
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

    def static_check(self, positions: np.ndarray) -> None:
        """Refuse via points the arm cannot even hold still (``|g(q)| > L``), naming joint and via point."""
        g = np.abs(self.robot.gravity(np.asarray(positions, dtype=float)))
        over = g > self.limit
        if np.any(over):
            k, j = (int(i) for i in np.argwhere(over)[0])
            raise InfeasibleProblem(
                f"robot '{self.robot.name}' cannot hold via point {k} still: joint {self.robot.joint_names[j]} needs "
                f"{g[k, j]:.4g} N·m against gravity (payload included), its limit is {self.limit[j]:.4g}; "
                "lighten the payload or move the via point closer to the base"
            )

    def refined_scale(self, trajectory: Any) -> float:
        """Factor (>= 1) on every duration that brings the *refined* torque peaks under the limits.

        The grid misses the exact peak by a hair; the refined peaks and the scaling law at
        those instants give the factor (:func:`planning.torque.torque_dilation`).
        """
        from pinarms.planning.torque import torque_dilation

        return torque_dilation(trajectory, self.robot, self.limit, self.samples_per_piece)


def torque_constraint(robot: Any, torque_limits: Any, payload: Any = None,
                      samples_per_piece: int | None = None) -> TorqueConstraint | None:
    """The :class:`TorqueConstraint` asked for by ``minimize_time``/``plan_cycle`` keywords, or None.

    Args:
        robot: the arm (required when torque limits are asked for).
        torque_limits: ``False``/``None`` (no torque limits), ``True`` (the URDF's joint
            ``effort`` limits, ``robot.effort_limit``) or limits per joint [N·m or N].
        payload: ``None``, a mass [kg], a :class:`robots.Payload` or its dict form; the
            robot carries it (``robot.with_payload``).

    Raises:
        InvalidSettings: torque limits without a robot, or a payload without torque limits
            (a payload changes only torques).
        InvalidLimits: ``True`` but the URDF has no effort limit for some joint.
    """
    if torque_limits is None or torque_limits is False:
        if payload is not None:
            raise InvalidSettings("a payload changes only the torques: pass torque_limits=True (or limits) with it")
        return None
    if robot is None:
        raise InvalidSettings("torque limits need the robot whose inverse dynamics give the torques: pass robot=arm")
    if payload is not None:
        robot = robot.with_payload(payload)
    if torque_limits is True:
        effort = np.asarray(robot.effort_limit, dtype=float)
        missing = [n for n, e in zip(robot.joint_names, effort) if not e > 0.0]
        if missing:
            raise InvalidLimits(f"robot '{robot.name}' has no effort limit for joint(s) {missing} in its URDF: "
                                "pass torque_limits=[...] (N·m or N per joint)")
        torque_limits = effort
    return TorqueConstraint(robot, torque_limits, samples_per_piece)
