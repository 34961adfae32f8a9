"""Both kinds of singularity of a delta, measured and reported.

With ``A p_dot = diag(d) theta_dot`` (:func:`~.jacobian.constraint_matrices`):

* **serial (inverse-kinematic) singularity** of leg i: ``d_i = 0``: the forearm is
  perpendicular to its elbow's velocity (it lies in the plane of the upper arm and the motor
  axis: arm stretched or folded along it); the leg's two IK branches meet and the platform
  loses a direction of motion. Measure ``|d_i| / (L l)`` in [0, 1] (the cosine of the angle
  between forearm and elbow velocity: 1 far from it, 0 on it).
* **parallel (direct-kinematic) singularity**: ``det A = 0``: the three forearms are parallel
  to one plane; the platform gains a direction of motion the motors cannot hold, the two
  assembly modes meet. Measure ``|det(A / l)|`` in [0, 1].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinarms.robots.delta.geometry import DeltaGeometry
from pinarms.robots.delta.jacobian import constraint_matrices

__all__ = ["SingularityReport", "singularities"]


@dataclass(frozen=True)
class SingularityReport:
    """Singularity measures of a batch of motor angles (1 = far, 0 = singular) and flags at ``tol``."""

    serial: np.ndarray      # (N, 3): per leg, |d_i| / (L l)
    parallel: np.ndarray    # (N,): |det(A / l)|
    tol: float

    @property
    def serial_singular(self) -> np.ndarray:
        """(N,) bool: some leg within ``tol`` of a serial singularity."""
        return self.serial.min(axis=1) < self.tol

    @property
    def parallel_singular(self) -> np.ndarray:
        """(N,) bool: within ``tol`` of a parallel singularity."""
        return self.parallel < self.tol

    def describe(self, n: int = 0) -> str:
        """One line for row ``n``: which singularity, which leg, how close."""
        parts = []
        legs = np.flatnonzero(self.serial[n] < self.tol)
        if legs.size:
            parts.append("serial singularity of leg " + ", ".join(str(i + 1) for i in legs)
                         + f" (measure {self.serial[n].min():.2e})")
        if self.parallel[n] < self.tol:
            parts.append(f"parallel singularity (measure {self.parallel[n]:.2e})")
        return "; ".join(parts) if parts else f"regular (serial {self.serial[n].min():.3f}, parallel {self.parallel[n]:.3f})"


def singularities(geom: DeltaGeometry, theta, tol: float = 1e-3) -> SingularityReport:
    """Measure both singularities at motor angles ``theta`` ((3,) or (N, 3)) [rad]."""
    a, d = constraint_matrices(geom, theta)
    serial = np.abs(d) / (geom.upper_arm * geom.forearm)
    parallel = np.abs(np.linalg.det(a / geom.forearm))
    return SingularityReport(serial, parallel, float(tol))
