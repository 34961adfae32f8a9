"""Time-optimal timing of a joint path under speed, acceleration and torque limits, from arrays.

Any arm: the caller gives, at each grid point of the path parameter s, the joint path's
derivatives ``q'(s)``, ``q''(s)`` and the torque's coefficients ``tau = A s_ddot + B s_dot^2 + C``
(``C`` the static torque, ``A = ID(q, 0, q') - C``, ``B = ID(q, q', q'') - C``). The limits
become rows ``lo <= a u + b x <= hi`` in ``x = s_dot^2``, ``u = s_ddot``, and the project's
TOPP-RA (:func:`pinarms.optim.topp.topp_profile`) gives the time-optimal profile, rest to rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinarms.optim.topp import topp_profile

__all__ = ["profile_position", "JointPathRows", "GateTiming", "time_rows", "limit_usage"]


@dataclass(frozen=True)
class JointPathRows:
    """Per grid point (N,) of s: q' (N, n), q'' (N, n), torque coefficients A, B, C (N, n)."""

    s: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    torque_a: np.ndarray
    torque_b: np.ndarray
    torque_c: np.ndarray


@dataclass(frozen=True)
class GateTiming:
    """A time-optimal one-way move: its ``duration`` [s], the profile ``s`` [m], ``sd`` [m/s], ``sdd`` on
    each interval [m/s^2], and the largest fraction of each limit used (speed, acceleration, torque)."""

    duration: float
    s: np.ndarray
    sd: np.ndarray
    sdd: np.ndarray
    usage: dict[str, float]


def _rows(path: JointPathRows, vmax: np.ndarray, amax: np.ndarray, tmax: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    n, big = len(path.s), 1e30
    a = np.hstack([np.zeros_like(path.dq), path.dq, path.torque_a])
    b = np.hstack([path.dq ** 2, path.ddq, path.torque_b])
    lo = np.hstack([np.full_like(path.dq, -big), np.repeat(-amax[None], n, 0), -tmax[None] - path.torque_c])
    hi = np.hstack([np.repeat(vmax[None] ** 2, n, 0), np.repeat(amax[None], n, 0), tmax[None] - path.torque_c])
    return a, b, lo, hi


def limit_usage(path: JointPathRows, x: np.ndarray, u: np.ndarray, vmax, amax, tmax) -> dict[str, float]:
    """Largest |value| / limit of speed, acceleration and torque at the grid points (u of the interval after)."""
    uu = np.append(u, u[-1])[:, None]
    sd = np.sqrt(np.maximum(x, 0.0))[:, None]
    return {"speed": float(np.max(np.abs(path.dq * sd) / vmax)),
            "acceleration": float(np.max(np.abs(path.dq * uu + path.ddq * sd ** 2) / amax)),
            "torque": float(np.max(np.abs(path.torque_a * uu + path.torque_b * sd ** 2 + path.torque_c) / tmax))}


def time_rows(path: JointPathRows, vmax, amax, tmax, *, sd_start: float = 0.0, sd_end: float = 0.0) -> GateTiming:
    """Time-optimal profile along ``path`` under per-joint limits (scalars or (n,)), rest to rest, or
    with the path speed ``sd_start`` / ``sd_end`` [s-units/s] imposed at its ends (a move onto or off a belt)."""
    n_joints = path.dq.shape[1]
    vmax, amax, tmax = (np.broadcast_to(np.asarray(v, dtype=float), (n_joints,)) for v in (vmax, amax, tmax))
    profile = topp_profile(*_rows(path, vmax, amax, tmax), path.s, x_start=float(sd_start) ** 2,
                           x_end=float(sd_end) ** 2)
    return GateTiming(profile.duration, profile.s, profile.sd, profile.u,
                      limit_usage(path, profile.x, profile.u, vmax, amax, tmax))


def profile_position(timing, tau: np.ndarray) -> np.ndarray:
    """Path position ``s`` [m] at instants ``tau`` [s] of a time-optimal profile (``timing.s``, ``timing.sd``:
    constant path acceleration on each interval, so ``dt = 2 ds / (sd_k + sd_k+1)``), held at its end."""
    s, sd = np.asarray(timing.s, float), np.asarray(timing.sd, float)
    ds = np.diff(s)
    dt = 2.0 * ds / np.maximum(sd[:-1] + sd[1:], 1e-300)
    t_nodes = np.concatenate([[0.0], np.cumsum(dt)])
    tau = np.clip(np.asarray(tau, float), 0.0, t_nodes[-1])
    k = np.clip(np.searchsorted(t_nodes, tau, side="right") - 1, 0, ds.size - 1)
    local = tau - t_nodes[k]
    acc = (sd[k + 1] - sd[k]) / dt[k]
    return np.minimum(s[k] + sd[k] * local + 0.5 * acc * local ** 2, s[k + 1])
