"""The standard pick cycle's path: 25 mm up, 305 mm across, 25 mm down (and back), corners rounded.

The benchmark of delta and SCARA datasheets (ABB quotes it as "a 25 - 305 - 25 movement").
The corners' rounding is each vendor's own; here each corner is a quarter circle of
``corner_radius`` (default 25 mm: the whole rise is the arc), so the path is C1 and the time-optimal
motion need not stop at the corners. The path lies in the vertical plane through ``start``
along the horizontal ``direction``; arc length ``s`` [m] parametrises it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinarms.optim.errors import InvalidSettings

__all__ = ["StandardCycle", "gate_length", "gate_points", "gate_breaks"]


@dataclass(frozen=True)
class StandardCycle:
    """The gate [m]: ``up`` from ``start``, ``across`` along ``direction`` (a horizontal unit vector
    after normalising), ``down``; corners of ``corner_radius``; payload [kg] carried both ways."""

    start: tuple[float, float, float]
    direction: tuple[float, float, float] = (1.0, 0.0, 0.0)
    up: float = 0.025
    across: float = 0.305
    down: float = 0.025
    corner_radius: float = 0.025
    payload: float = 0.0

    def __post_init__(self) -> None:
        d = np.asarray(self.direction, dtype=float)
        if d.shape != (3,) or abs(d[2]) > 1e-12 or np.linalg.norm(d) < 1e-9:
            raise InvalidSettings(f"direction must be a horizontal vector (x, y, 0), got {self.direction!r}")
        r = self.corner_radius
        if not (0 < r <= min(self.up, self.down) and 2 * r <= self.across) or self.payload < 0:
            raise InvalidSettings(f"need 0 < corner_radius ({r}) <= up ({self.up}), down ({self.down}), "
                                  f"2 corner_radius <= across ({self.across}) and payload >= 0 ({self.payload})")

    @property
    def unit(self) -> np.ndarray:
        d = np.asarray(self.direction, dtype=float)
        return d / np.linalg.norm(d)


def _segments(c: StandardCycle) -> list[tuple[str, float]]:
    r = c.corner_radius
    return [("up", c.up - r), ("arc1", 0.5 * np.pi * r), ("across", c.across - 2 * r), ("arc2", 0.5 * np.pi * r),
            ("down", c.down - r)]


def gate_length(c: StandardCycle) -> float:
    """Length of one way [m]."""
    return float(sum(length for _, length in _segments(c)))


def gate_breaks(c: StandardCycle) -> np.ndarray:
    """Arc lengths [m] where the curvature jumps (segment ends), start and end included."""
    return np.concatenate([[0.0], np.cumsum([length for _, length in _segments(c)])])


def gate_points(c: StandardCycle, s: np.ndarray, *, side: str = "right") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points (N, 3) [m], unit tangents p' and curvature vectors p'' [1/m] at arc lengths ``s`` (N,).

    At a segment end, ``side="right"`` takes the next segment's p'' and ``"left"`` the previous one's.
    """
    s = np.asarray(s, dtype=float)
    d, z, r = c.unit, np.array([0.0, 0.0, 1.0]), c.corner_radius
    a = np.asarray(c.start, dtype=float)
    breaks = gate_breaks(c)
    k = np.clip(np.searchsorted(breaks, s, side=side) - 1, 0, 4)
    u = s - breaks[k]
    p, dp, ddp = np.zeros((len(s), 3)), np.zeros((len(s), 3)), np.zeros((len(s), 3))
    corner1 = a + (c.up - r) * z
    top = corner1 + r * d + r * z
    corner2 = a + (c.across - r) * d + (c.up - r) * z
    for seg, (name, _) in enumerate(_segments(c)):
        m = k == seg
        um = u[m][:, None]
        if name == "up":
            p[m], dp[m] = a + um * z, z
        elif name == "across":
            p[m], dp[m] = top + um * d, d
        elif name == "down":
            start = a + c.across * d + (c.up - r) * z
            p[m], dp[m] = start - um * z, -z
        else:
            phi = (np.pi - um / r) if name == "arc1" else (0.5 * np.pi - um / r)
            centre = corner1 + r * d if name == "arc1" else corner2
            radial = np.cos(phi) * d + np.sin(phi) * z
            p[m] = centre + r * radial
            dp[m] = np.sin(phi) * d - np.cos(phi) * z
            ddp[m] = -radial / r
    return p, dp, ddp
