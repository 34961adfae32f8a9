"""The pieces of a tool path: what is left of a straight line, and a circular blend at a corner.

Each piece is pure geometry in its own local arc length σ [m] (the weighted metric of
:mod:`pinarms.planning.tool_path`): ``length`` and ``evaluate(σ)`` → tcp poses (N, 4, 4) and the
first and second derivatives (N, 6) of position and rotation (base axes) in σ.
:func:`pinarms.planning.tool_path` cuts the lines and places the blends.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinarms.planning.errors import TrajectoryError
from pinarms.robots import so3 as _so3

__all__ = ["Line", "Blend", "BlendCorner"]

#: Nodes of the arc-length table of a blend that rotates (its s(ℓ) is integrated numerically).
_TABLE = 257


def _smoothstep(x: np.ndarray) -> np.ndarray:
    """Quintic smoothstep 10x³ − 15x⁴ + 6x⁵: 0 → 1 with zero first and second derivatives at both ends."""
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x))


class Line:
    """Part ``λ ∈ [lam0, lam1]`` of the segment T_a → T_b (length ``L``); local s = (λ − lam0) L."""

    kind = "line"

    def __init__(self, Ta: np.ndarray, Tb: np.ndarray, phi: np.ndarray, L: float, lam0: float, lam1: float) -> None:
        self.pa, self.pb = Ta[:3, 3], Tb[:3, 3]
        self.Ra, self.Rb = Ta[:3, :3], Tb[:3, :3]
        self.phi, self.L, self.lam0 = phi, L, lam0
        self.length = (lam1 - lam0) * L
        self.d1 = np.concatenate([(self.pb - self.pa) / L, self.Ra @ phi / L])

    def evaluate(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        lam = self.lam0 + sigma / self.L
        n = lam.size
        T = np.zeros((n, 4, 4))
        T[:, 3, 3] = 1.0
        T[:, :3, 3] = (1.0 - lam)[:, None] * self.pa + lam[:, None] * self.pb
        first = lam <= 0.5  # each half from its own end: exact end poses
        R = np.empty((n, 3, 3))
        R[first] = self.Ra @ _so3.exp(lam[first, None] * self.phi)
        R[~first] = self.Rb @ _so3.exp(-(1.0 - lam[~first])[:, None] * self.phi)
        T[:, :3, :3] = R
        return T, np.broadcast_to(self.d1, (n, 6)).copy(), np.zeros((n, 6))


@dataclass(frozen=True)
class BlendCorner:
    """The position part of a :class:`Blend`: the corner it rounds (base frame, m).

    Attributes:
        point: (3,) the corner (the via point).
        e_in, e_out: (3,) unit directions of the incoming and outgoing lines.
        b: distance from the corner where the blend leaves each line [m] (> 0).
        r: the arc's radius [m] (used when ``arc``).
        arc: a circular arc (else a parabolic blend of length ``2 b``).

    Raises:
        TrajectoryError: a blend distance that is not a positive length, or an arc radius that is not one.
    """

    point: np.ndarray
    e_in: np.ndarray
    e_out: np.ndarray
    b: float
    r: float
    arc: bool

    def __post_init__(self) -> None:
        if not (np.isfinite(self.b) and self.b > 0.0):
            raise TrajectoryError(f"BlendCorner: b must be a positive length in m, got {self.b!r}")
        if self.arc and not (np.isfinite(self.r) and self.r > 0.0):
            raise TrajectoryError(f"BlendCorner: an arc needs a positive radius r in m, got {self.r!r}")


class Blend:
    """Blend at a corner, local parameter ℓ ∈ [0, ℓ_b] (arc length of the position curve, m).

    ``R1(ℓ) = R_c exp(φ_in (ℓ − b) / d_in)`` and ``R2(ℓ) = R_c exp(φ_out (ℓ − ℓ_b + b) / d_out)``
    continue the SLERPs of the incoming and outgoing lines (R_c: the corner's orientation).
    """

    kind = "blend"

    def __init__(self, at: BlendCorner, Rc: np.ndarray, phi_in: np.ndarray, d_in: float, phi_out: np.ndarray,
                 d_out: float, weight: float) -> None:
        corner, e_in, e_out, b, r, arc = at.point, at.e_in, at.e_out, at.b, at.r, at.arc
        self.corner, self.e_in, self.b, self.r, self.arc = corner, e_in, b, r, arc
        self.Rc, self.w_in, self.w_out = Rc, phi_in / d_in, phi_out / d_out
        self.weight = weight
        if arc:
            alpha = float(np.arccos(np.clip(e_in @ e_out, -1.0, 1.0)))
            self.lb = r * alpha
            inward = e_out - e_in
            inward /= np.linalg.norm(inward)
            centre = corner + (r / np.cos(0.5 * alpha)) * inward
            start = corner - b * e_in
            self.centre, self.u, self.v = centre, (start - centre) / r, e_in
        else:
            self.lb = 2.0 * b
        self.rotates = bool(np.linalg.norm(self.w_in) + np.linalg.norm(self.w_out) > 0.0)
        if self.rotates:
            ell = np.linspace(0.0, self.lb, _TABLE)
            g = self._speed(ell)
            # composite Simpson on pairs of table intervals, trapezoid-consistent at odd nodes
            h = ell[1] - ell[0]
            s = np.zeros(_TABLE)
            s[2::2] = np.cumsum(h / 3.0 * (g[0:-2:2] + 4.0 * g[1:-1:2] + g[2::2]))
            mid = 0.5 * (ell[:-2:2] + ell[1:-1:2])
            s[1::2] = s[0:-2:2] + h / 6.0 * (g[0:-2:2] + 4.0 * self._speed(mid) + g[1:-1:2])
            self.table = (s, ell, 1.0 / g)
            self.length = float(s[-1])
        else:
            self.length = self.lb

    # ---------------------------------------------------------------- in ℓ
    def _rotation(self, ell: np.ndarray) -> np.ndarray:
        R1 = self.Rc @ _so3.exp((ell - self.b)[:, None] * self.w_in)
        R2 = self.Rc @ _so3.exp((ell - self.lb + self.b)[:, None] * self.w_out)
        beta = _smoothstep(ell / self.lb)
        return R1 @ _so3.exp(beta[:, None] * _so3.log(np.swapaxes(R1, 1, 2) @ R2))

    def _omega(self, ell: np.ndarray, h: float) -> np.ndarray:
        """Angular rate dθ/dℓ (N, 3) [rad/m] in base axes: central differences, Richardson-extrapolated (O(h⁴))."""
        def central(step: float) -> np.ndarray:
            Rp, Rm = self._rotation(ell + step), self._rotation(ell - step)
            return _so3.log(Rp @ np.swapaxes(Rm, 1, 2)) / (2.0 * step)

        return (4.0 * central(h) - central(2.0 * h)) / 3.0

    def _speed(self, ell: np.ndarray) -> np.ndarray:
        om = self._omega(ell, 1e-3 * self.lb)
        return np.sqrt(1.0 + self.weight**2 * np.sum(om * om, axis=1))

    def _ell(self, sigma: np.ndarray) -> np.ndarray:
        if not self.rotates:
            return sigma.copy()
        s, ell, slope = self.table
        k = np.clip(np.searchsorted(s, sigma, side="right") - 1, 0, s.size - 2)
        h = s[k + 1] - s[k]
        t = (sigma - s[k]) / h
        h00, h10 = (1 + 2 * t) * (1 - t) ** 2, t * (1 - t) ** 2
        h01, h11 = t * t * (3 - 2 * t), t * t * (t - 1)
        return h00 * ell[k] + h10 * h * slope[k] + h01 * ell[k + 1] + h11 * h * slope[k + 1]

    def evaluate(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        ell = self._ell(sigma)
        n = ell.size
        T = np.zeros((n, 4, 4))
        T[:, 3, 3] = 1.0
        if self.arc:
            c, s_ = np.cos(ell / self.r), np.sin(ell / self.r)
            T[:, :3, 3] = self.centre + self.r * (c[:, None] * self.u + s_[:, None] * self.v)
            p1 = -s_[:, None] * self.u + c[:, None] * self.v
            p2 = -(c[:, None] * self.u + s_[:, None] * self.v) / self.r
        else:
            T[:, :3, 3] = self.corner + (ell - self.b)[:, None] * self.e_in
            p1 = np.broadcast_to(self.e_in, (n, 3))
            p2 = np.zeros((n, 3))
        d1, d2 = np.zeros((n, 6)), np.zeros((n, 6))
        if not self.rotates:
            T[:, :3, :3] = self.Rc
            d1[:, :3], d2[:, :3] = p1, p2
            return T, d1, d2
        T[:, :3, :3] = self._rotation(ell)
        h = 1e-3 * self.lb
        om = self._omega(ell, h)
        om2 = (8.0 * (self._omega(ell + h, h) - self._omega(ell - h, h))
               - (self._omega(ell + 2.0 * h, h) - self._omega(ell - 2.0 * h, h))) / (12.0 * h)
        w2 = self.weight**2
        g = np.sqrt(1.0 + w2 * np.sum(om * om, axis=1))
        g1 = w2 * np.sum(om * om2, axis=1) / g
        l1 = 1.0 / g
        l2 = -g1 / g**3
        d1[:, :3] = p1 * l1[:, None]
        d1[:, 3:] = om * l1[:, None]
        d2[:, :3] = p2 * (l1 * l1)[:, None] + p1 * l2[:, None]
        d2[:, 3:] = om2 * (l1 * l1)[:, None] + om * l2[:, None]
        return T, d1, d2
