"""The workspace of a delta: Monte Carlo over the motor ranges, and its cylinder-plus-dome description.

Datasheets describe a delta's working range as a vertical cylinder (diameter D, height H)
with a dome under it down to the lowest point on the axis. :func:`cylinder_dome` measures it
from the closed form: at each height the largest radius whose whole circle is reachable on the
primary IK branch within the motor range (with every smaller circle), then the cylinder of largest volume under that
profile, then the dome to the deepest reachable point of the axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinarms.robots.delta.errors import DeltaInputError
from pinarms.robots.delta.kinematics import PRIMARY_BRANCH, forward_position, inverse_position_branches
from pinarms.robots.delta.model import DeltaRobot

__all__ = ["WorkspaceSamples", "sample_workspace", "reachable", "CylinderDome", "cylinder_dome"]


@dataclass(frozen=True)
class WorkspaceSamples:
    """Monte Carlo samples: motor angles (N, 3) [rad] uniform in the range, platform centres (N, 3) [m]."""

    theta: np.ndarray
    points: np.ndarray


def sample_workspace(delta: DeltaRobot, n: int = 20000, seed: int | np.random.Generator = 0) -> WorkspaceSamples:
    """Platform centres of ``n`` motor-angle triples drawn uniformly in the motor range (seeded)."""
    if not (isinstance(n, (int, np.integer)) and 0 < n <= 10**8):
        raise DeltaInputError(f"n must be an integer in 1..1e8, got {n!r}")
    rng = np.random.default_rng(seed)
    lim = delta.limits
    theta = rng.uniform(lim.lower, lim.upper, size=(int(n), 3))
    p = forward_position(delta.geometry, theta)
    ok = ~np.isnan(p).any(axis=1)
    return WorkspaceSamples(theta[ok], p[ok])


def reachable(delta: DeltaRobot, p, branch: int = PRIMARY_BRANCH) -> np.ndarray:
    """(N,) bool: platform centres ``p`` (N, 3) [m] reachable on ``branch`` within the motor range."""
    theta, real = inverse_position_branches(delta.geometry, np.atleast_2d(p))
    th = theta[:, branch]
    lim = delta.limits
    with np.errstate(invalid="ignore"):
        inside = np.all((th >= lim.lower - 1e-12) & (th <= lim.upper + 1e-12), axis=1)
    return real[:, branch] & inside


@dataclass(frozen=True)
class CylinderDome:
    """Working range [m]: a cylinder of ``diameter`` from ``z_top`` down to ``z_bottom`` (base frame, z up),
    and a dome under it down to ``z_dome`` on the axis."""

    diameter: float
    z_top: float
    z_bottom: float
    z_dome: float

    @property
    def height(self) -> float:
        """Height of the cylinder [m]."""
        return self.z_top - self.z_bottom

    @property
    def dome_depth(self) -> float:
        """Depth of the dome under the cylinder [m]."""
        return self.z_bottom - self.z_dome


def _radius_profile(delta: DeltaRobot, z: np.ndarray, n_azimuth: int, dr: float) -> np.ndarray:
    """Largest radius [m] at each height such that every circle of radius k dr up to it (``n_azimuth``
    points each) is reachable: the disc is reachable even where the section is not star-shaped."""
    az = np.linspace(0.0, 2.0 * np.pi, n_azimuth, endpoint=False)
    radii = np.arange(0.0, delta.geometry.upper_arm + delta.geometry.forearm, dr)
    out = np.empty(len(z))
    for k, zk in enumerate(z):
        pts = np.stack([radii[:, None] * np.cos(az), radii[:, None] * np.sin(az), np.full((len(radii), n_azimuth), zk)],
                       axis=-1)
        ok = reachable(delta, pts.reshape(-1, 3)).reshape(len(radii), n_azimuth).all(axis=1)
        first_bad = np.flatnonzero(~ok)
        out[k] = radii[first_bad[0] - 1] if first_bad.size and first_bad[0] > 0 else (0.0 if first_bad.size else radii[-1])
    return out


def cylinder_dome(delta: DeltaRobot, *, height: float | None = None, dz: float = 0.005, dr: float = 0.005,
                  n_azimuth: int = 36) -> CylinderDome:
    """The cylinder-plus-dome description of the workspace (profile sampled every ``dz`` and ``dr`` [m]).

    Args:
        height: the cylinder's height [m] (a datasheet's); default: the cylinder of largest volume.
    """
    g = delta.geometry
    z = np.arange(-(g.upper_arm + g.forearm), g.upper_arm, dz)
    axis_ok = reachable(delta, np.stack([np.zeros_like(z), np.zeros_like(z), z], axis=1))
    if not axis_ok.any():
        raise DeltaInputError(f"{delta.name}: no point of the vertical axis is reachable within the motor range")
    z = z[axis_ok]
    radius = _radius_profile(delta, z, n_azimuth, dr)
    best = (0.0, 0, 0, 0.0)
    for r in np.unique(radius[radius > 0.0]):
        edges = np.diff(np.concatenate([[0], (radius >= r).astype(int), [0]]))
        starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)   # runs [start, end)
        k = int(np.argmax(ends - starts))
        volume = np.pi * r * r * (ends[k] - starts[k] - 1) * dz
        if height is not None:
            volume = r if (ends[k] - starts[k] - 1) * dz >= height - 1e-12 else 0.0
        if volume > best[0]:
            best = (volume, starts[k], ends[k] - 1, r)
    if best[0] <= 0.0:
        raise DeltaInputError(f"{delta.name}: no cylinder of height {height} m fits in the workspace")
    _, i0, i1, r = best
    return CylinderDome(2.0 * float(r), float(z[i1]), float(z[i0]), float(z[0]))
