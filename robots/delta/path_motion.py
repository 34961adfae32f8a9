"""A platform path as a motion of a delta's motors, with a proven cap on the motors' speed along it.

A cell's continuous check (:meth:`pinarms.robots.cell.Cell.check_motion`) takes joint trajectories
with exact peak speeds. A delta's pick is planned as a platform path ``p(τ)`` (a line, a Hermite
curve; ``τ`` its parameter, in seconds or any unit): :class:`PlatformPath` plays it as the motors'
motion ``θ(τ)`` = the closed-form inverse position (primary branch) of ``p(τ)``, exact at every
``τ``, and bounds ``|dθ_i/dτ|`` from a bound ``G`` of ``|dp/dτ|`` that the caller proves for its
path (:func:`tangent_bound` for a polynomial).

The cap: with ``t_i`` the unit tangent of elbow ``i``'s circle (``∂E_i/∂θ_i = L t_i``) and
``n_i`` the unit rod direction, each forearm keeping its length gives
``dθ_i/dτ = (n_i · dp/dτ) / (L n_i · t_i)``, so ``|dθ_i/dτ| ≤ G / (L κ)`` with ``κ = min_i |n_i · t_i|``
(zero at a serial singularity: an arm stretched along its rods). From a sample with ``κ_a``,
suppose ``κ ≥ κ_a / 2`` on a step of length ``h``: each motor turns by at most
``Θ = 2 G h / (L κ_a)``, ``t_i`` by ``Θ``, ``n_i`` by ``(G h + L Θ) / l``, so ``κ`` drops by at
most their sum; a step that keeps this below ``κ_a / 2`` makes the supposition hold on the whole
step, and on it ``|dθ_i/dτ| ≤ 2 G / (L κ_a)``. The cap is the largest of these over steps that
cover the path (from 64 even steps, each too long for the rule at its start cut into pieces).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from pinarms.robots.delta.errors import DeltaInputError, DeltaUnreachable
from pinarms.robots.delta.geometry import DeltaGeometry
from pinarms.robots.delta.kinematics import elbow_positions, inverse_position
from pinarms.robots.delta.model import DeltaRobot

__all__ = ["PlatformPath", "PathPeaks", "tangent_bound", "MAX_PATH_STEPS"]

#: Most steps the cap's cover of a path may take (a path that nears a serial singularity needs tiny ones).
MAX_PATH_STEPS = 200_000


def tangent_bound(coefficients) -> float:
    """The largest ``|p'(t)|`` for ``t ∈ [0, 1]`` of a polynomial ``p'(t) = Σ_k c_k t^k`` with vector
    coefficients ``coefficients (K, 3)``: ``|p'|²`` is a polynomial whose largest value on [0, 1] is at an
    end or at a real root of its derivative (all found by ``numpy.roots``), plus 1e-9 relative for rounding."""
    c = np.atleast_2d(np.asarray(coefficients, dtype=float))
    square = np.zeros(2 * len(c) - 1)            # |p'|² coefficients, increasing powers
    for i in range(len(c)):
        for j in range(len(c)):
            square[i + j] += float(c[i] @ c[j])
    slope = np.arange(1, square.size) * square[1:]
    roots = np.roots(slope[::-1]) if np.any(slope) else np.array([])
    t = np.concatenate([[0.0, 1.0], roots.real[(np.abs(roots.imag) < 1e-9) & (roots.real > 0) & (roots.real < 1)]])
    value = np.polyval(square[::-1], t).max()
    return float(np.sqrt(max(value, 0.0)) * (1.0 + 1e-9) + 1e-12)


@dataclass(frozen=True)
class PathPeaks:
    """Peaks of a :class:`PlatformPath` as a trajectory: ``velocity`` (proven caps per joint), ``acceleration``
    and ``jerk`` (not bounded: ``inf``)."""

    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray


def _kappa(geom: DeltaGeometry, theta: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit rod directions (N, 3, 3), elbow tangents (N, 3, 3) and ``min_i |n_i · t_i|`` (N,)."""
    e, z = geom.radial, np.array([0.0, 0.0, 1.0])
    rods = (p[:, None, :] + geom.platform_radius * e[None] - elbow_positions(geom, theta)) / geom.forearm
    tangent = -np.sin(theta)[:, :, None] * e[None] - np.cos(theta)[:, :, None] * z
    return rods, tangent, np.abs(np.einsum("nij,nij->ni", rods, tangent)).min(axis=1)


class PlatformPath:
    """The motors' motion along a platform path ``points(τ) -> (p, dp/dτ)`` ((M, 3) each, base frame [m]) for
    ``τ ∈ [0, duration]``, with ``|dp/dτ| ≤ tangent`` proven by the caller (module doc).

    A trajectory for :class:`pinarms.robots.cell.ArmMotion`: ``start_time``, ``end_time``, ``sample(τ)`` (motor
    angles and their rates, the tool axis held at ``tool`` [rad]), ``peaks().velocity`` (the proven caps),
    ``platform_speed`` (= ``tangent``: the platform's speed bound, which the cell's check uses directly).

    Raises:
        DeltaInputError: a duration or bound that is not a positive finite number, or a path that leaves the
            motors' range; DeltaUnreachable: a point out of reach or at a serial singularity.
    """

    def __init__(self, delta: DeltaRobot, points: Callable, duration: float, tangent: float, *, tool: float = 0.0):
        if not (np.isfinite(duration) and duration > 0.0 and np.isfinite(tangent) and tangent >= 0.0):
            raise DeltaInputError(f"duration must be > 0 and the tangent bound >= 0, finite; got {duration!r}, {tangent!r}")
        self.delta, self.points, self.tool = delta, points, float(tool)
        self.start_time, self.end_time, self.tangent = 0.0, float(duration), float(tangent)
        self._cap = self._motor_cap()

    @property
    def platform_speed(self) -> float:
        """The proven bound of the platform's speed ``|dp/dτ|`` (the caller's ``tangent``)."""
        return self.tangent

    @property
    def duration(self) -> float:
        return self.end_time - self.start_time

    def _rule(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """At each ``τ``: the longest step the rule allows and the motor speed bound on it (module doc)."""
        g, G = self.delta.geometry, self.tangent
        p = np.asarray(self.points(tau)[0], dtype=float)
        theta = inverse_position(g, p)
        lim = self.delta.limits
        if np.isnan(theta).any():
            raise DeltaUnreachable(f"{self.delta.name}: the path leaves the delta's reach near τ = "
                                   f"{float(tau[np.flatnonzero(np.isnan(theta).any(axis=1))[0]]):.4f}")
        if theta.min() < lim.lower - 1e-9 or theta.max() > lim.upper + 1e-9:
            raise DeltaInputError(f"{self.delta.name}: the path leaves the motors' range "
                                  f"[{lim.lower:.4f}, {lim.upper:.4f}] rad")
        _, _, kappa = _kappa(g, theta, p)
        if not np.all(kappa > 0.0):
            raise DeltaUnreachable(f"{self.delta.name}: the path reaches a serial singularity (an upper arm along its rods)")
        big_l, small_l = g.upper_arm, g.forearm
        with np.errstate(divide="ignore"):
            h = 0.999 * (0.5 * kappa) / (G / small_l + 2.0 * G / (kappa * small_l) + 2.0 * G / (kappa * big_l))
        return h, 2.0 * G / (big_l * kappa)

    def _motor_cap(self) -> float:
        tau = np.linspace(self.start_time, self.end_time, 65)
        step, cap = self._rule(tau)
        while True:
            length = np.diff(tau)
            over = length > step[:-1]
            if not over.any():
                return float(cap[:-1].max())
            pieces = np.ceil(length[over] / step[:-1][over]).astype(int)
            if tau.size + pieces.sum() > MAX_PATH_STEPS:
                raise DeltaInputError(f"{self.delta.name}: bounding the motors' speed along this path needs more than "
                                      f"{MAX_PATH_STEPS} steps: it comes too close to a serial singularity")
            new = np.concatenate([a + (b - a) * np.arange(1, k) / k
                                  for a, b, k in zip(tau[:-1][over], tau[1:][over], pieces)])
            s_new, c_new = self._rule(new)
            order = np.argsort(np.concatenate([tau, new]), kind="stable")
            tau = np.concatenate([tau, new])[order]
            step, cap = np.concatenate([step, s_new])[order], np.concatenate([cap, c_new])[order]

    def sample(self, tau) -> tuple[np.ndarray, np.ndarray]:
        """Motor angles (and the tool) ``(M, 3 or 4)`` and their rates at ``τ (M,)`` (``(3 or 4,)`` each for one
        ``τ``): the closed form."""
        single = np.ndim(tau) == 0
        t = np.atleast_1d(np.asarray(tau, dtype=float))
        p, dp = (np.asarray(v, dtype=float) for v in self.points(t)[:2])
        g = self.delta.geometry
        theta = inverse_position(g, p)
        rods, tangent, _ = _kappa(g, theta, p)
        rate = np.einsum("nij,nj->ni", rods, dp) / (g.upper_arm * np.einsum("nij,nij->ni", rods, tangent))
        if self.delta.has_tool_axis:
            theta = np.hstack([theta, np.full((t.size, 1), self.tool)])
            rate = np.hstack([rate, np.zeros((t.size, 1))])
        return (theta[0], rate[0]) if single else (theta, rate)

    def peaks(self) -> PathPeaks:
        """The proven motor speed cap (rad per unit of ``τ``) for each motor, 0 for the held tool axis."""
        n = 4 if self.delta.has_tool_axis else 3
        v = np.full(n, self._cap)
        if n == 4:
            v[3] = 0.0
        return PathPeaks(v, np.full(n, np.inf), np.full(n, np.inf))
