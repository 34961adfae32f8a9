"""The standard pick cycle of a delta robot, time-optimal under its motor limits with the payload.

Along the gate (:mod:`.path`) the motor angles come from the closed-form inverse kinematics
(primary branch), their path derivatives from central differences of it, and the torque
coefficients from the closed-chain inverse dynamics (:func:`pinarms.robots.delta.motor_torques`)
at three platform states per grid point.

**The fourth axis.** ABB quotes the IRB 360's cycle "with 90 degrees rotation of axis 4"
(:data:`pinarms.papers.IRB360_1600`); we read it as the tool turning by 90 degrees on each one-way move,
rest to rest (the item placed turned, the tool turned back on the way back). The tool's motor sits on
the base and turns the tool through a telescopic shaft: it loads none of the three arm motors (in the
model the tool's axis passes through its centre of mass and the payload's, so the arm motors' closed-chain
torques do not depend on the tool's angle, speed or acceleration: ``tests/robots/delta/test_cycle_turn.py``).
Its shortest rest-to-rest turn (:func:`tool_turn_time`) under its speed limit (the URDF's) and an
acceleration limit of :data:`TOOL_ACCELERATION_FACTOR` times that speed (assumed: a URDF has no
acceleration limit) therefore runs beside the platform's time-optimal move, and a one-way move takes the
longer of the two (:func:`delta_cycle_time`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinarms.optim.errors import InvalidSettings

from pinarms.robots.delta import DeltaRobot, closed_chain_state, inverse_position, motor_torques

from pinarms.optim.standard_cycle.path import StandardCycle, gate_breaks, gate_length, gate_points
from pinarms.optim.standard_cycle.timing import GateTiming, JointPathRows, time_rows

__all__ = ["delta_path_rows", "delta_gate_rows", "delta_standard_cycle", "delta_cycle_time", "DeltaCycleTime",
           "tool_turn_time", "turn_angle", "tool_turn_limits", "TOOL_ACCELERATION_FACTOR"]

_H = 1e-4   # step of the central differences along the path [m]
#: Acceleration limit of the fourth axis: this many times its speed limit [1/s] (assumed).
TOOL_ACCELERATION_FACTOR = 10.0


def tool_turn_time(angle: float, vmax: float, amax: float) -> float:
    """Shortest rest-to-rest time [s] of a turn by ``angle`` [rad] under ``vmax``, ``amax``."""
    a = abs(float(angle))
    if a * amax <= vmax ** 2:
        return 2.0 * np.sqrt(a / amax)
    return a / vmax + vmax / amax


def turn_angle(angle: float, vmax: float, amax: float, tau: np.ndarray) -> np.ndarray:
    """Angle [rad] at ``tau`` [s] of the shortest rest-to-rest turn by ``angle`` under ``vmax``, ``amax``
    (bang-bang, or with a cruise at ``vmax``; :func:`tool_turn_time` long), held after it."""
    a = abs(float(angle))
    if a == 0.0:
        return np.zeros(np.shape(tau))
    total = tool_turn_time(a, vmax, amax)
    ramp = min(vmax / amax, total / 2.0)
    tau = np.clip(np.asarray(tau, float), 0.0, total)
    peak = amax * ramp
    out = np.where(tau < ramp, 0.5 * amax * tau ** 2,
                   np.where(tau > total - ramp, a - 0.5 * amax * (total - tau) ** 2,
                            0.5 * amax * ramp ** 2 + peak * (tau - ramp)))
    return np.sign(angle) * out


def tool_turn_limits(delta: DeltaRobot) -> tuple[float, float]:
    """Speed [rad/s] (the URDF's) and acceleration [rad/s^2] (assumed, :data:`TOOL_ACCELERATION_FACTOR`) of the
    fourth axis; :class:`InvalidSettings` for a delta without one."""
    if delta.tool_q is None:
        raise InvalidSettings(f"{delta.name} has no fourth axis: a cycle with a tool turn needs one (turn=0)")
    v = float(delta.model.velocityLimit[delta.tool_q])
    return v, TOOL_ACCELERATION_FACTOR * v


@dataclass(frozen=True)
class DeltaCycleTime:
    """One way of the standard cycle [s]: the platform's time-optimal ``move`` (:class:`GateTiming`), the
    tool's ``turn_s`` (0 without a turn), ``one_way_s`` the longer of the two; ``binding``: the limits the
    longer one reaches (the motors' usage, or "tool turn")."""

    move: GateTiming
    turn_s: float
    one_way_s: float
    binding: str


def delta_cycle_time(delta: DeltaRobot, cycle: StandardCycle, turn: float = 0.0, n: int = 400) -> DeltaCycleTime:
    """One way of ``cycle`` with the tool turning by ``turn`` [rad] meanwhile, rest to rest (module doc)."""
    move = delta_standard_cycle(delta, cycle, n)
    turn_s = tool_turn_time(turn, *tool_turn_limits(delta)) if turn else 0.0
    if turn_s > move.duration:
        return DeltaCycleTime(move, turn_s, turn_s, "tool turn")
    used = ", ".join(k for k, v in move.usage.items() if v >= 0.999) or "none"
    return DeltaCycleTime(move, turn_s, float(move.duration), used)


def delta_path_rows(delta: DeltaRobot, s: np.ndarray, points) -> tuple[np.ndarray, ...]:
    """Rows (q', q'', torque A, B, C; each (N, 3)) of any platform path: ``points(s)`` gives the platform
    centre's position, first and second derivatives along ``s`` [m] ((N, 3) each) on the grid ``s`` (N,);
    ``delta`` carries its payload already (:meth:`DeltaRobot.with_payload`)."""
    p, dp, ddp = points(s)
    q = {k: inverse_position(delta.geometry, points(s + k * _H)[0]) for k in (-1, 0, 1)}
    # central differences of the closed form, along each point's own segment (its formula extended)
    dq = (q[1] - q[-1]) / (2 * _H)
    ddq = (q[1] - 2 * q[0] + q[-1]) / _H ** 2
    zero = np.zeros_like(p)
    c = motor_torques(delta, closed_chain_state(delta, p, zero, zero))[0]
    ta = motor_torques(delta, closed_chain_state(delta, p, zero, dp))[0] - c
    tb = motor_torques(delta, closed_chain_state(delta, p, dp, ddp))[0] - c
    return dq, ddq, ta, tb, c


def delta_gate_rows(delta: DeltaRobot, cycle: StandardCycle, n: int = 400) -> JointPathRows:
    """The rows of the delta's gate on about ``n`` grid intervals (the TOPP grid must be strictly
    increasing: at a segment end the left and right rows are both imposed at that point)."""
    arm = delta.with_payload(cycle.payload) if cycle.payload > 0 else delta
    s = np.union1d(np.linspace(0.0, gate_length(cycle), n + 1), gate_breaks(cycle))
    rows = [delta_path_rows(arm, s, lambda x, side=side: gate_points(cycle, x, side=side))
            for side in ("left", "right")]
    (dl, ddl, al, bl, cl), (dr, ddr, ar, br, cr) = rows
    return JointPathRows(s, np.hstack([dl, dr]), np.hstack([ddl, ddr]), np.hstack([al, ar]), np.hstack([bl, br]),
                         np.hstack([cl, cr]))


def delta_standard_cycle(delta: DeltaRobot, cycle: StandardCycle, n: int = 400) -> GateTiming:
    """Time-optimal one-way move of the gate (rest to rest) under the motor speed, acceleration and
    torque limits; the cycle (there and back) takes twice its ``duration``."""
    lim = delta.limits
    rows = delta_gate_rows(delta, cycle, n)
    return time_rows(rows, lim.velocity, lim.acceleration, lim.torque)
