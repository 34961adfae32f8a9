"""The standard pick cycle of a delta robot, time-optimal under its motor limits with the payload.

Along the gate (:mod:`.path`) the motor angles come from the closed-form inverse kinematics
(primary branch), their path derivatives from central differences of it, and the torque
coefficients from the closed-chain inverse dynamics (:func:`pinarms.robots.delta.motor_torques`)
at three platform states per grid point. The tool axis does not move (ABB's cycle turns it by
90 degrees: assumed done within the move, not binding).
"""

from __future__ import annotations

import numpy as np

from pinarms.robots.delta import DeltaRobot, closed_chain_state, inverse_position, motor_torques

from pinarms.optim.standard_cycle.path import StandardCycle, gate_breaks, gate_length, gate_points
from pinarms.optim.standard_cycle.timing import GateTiming, JointPathRows, time_rows

__all__ = ["delta_path_rows", "delta_gate_rows", "delta_standard_cycle"]

_H = 1e-4   # step of the central differences along the path [m]


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
