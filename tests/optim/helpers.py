"""Test helpers for optim: an independent 3-5-3 builder and a dense-sampling checker.

The 3-5-3 builder is written from the closed form of seed 000 (cubic from rest, quintic
matching position/velocity/acceleration at both ends, cubic to rest) and is used to test
the timing code independently of planning's constructors.
"""

from __future__ import annotations

import numpy as np

from pinarms.planning.trajectory import Trajectory


def build_353(times: np.ndarray, positions: np.ndarray) -> Trajectory:
    """3-5-3 trajectory through 4 via points, at rest at both ends."""
    t = np.asarray(times, dtype=float)
    q = np.asarray(positions, dtype=float)
    if q.ndim == 1:
        q = q[:, None]
    h1, h2, h3 = np.diff(t)
    n = q.shape[1]
    coefs = np.zeros((3, 6, n))
    d1 = q[1] - q[0]
    d3 = q[3] - q[2]
    coefs[0, 0], coefs[0, 3] = q[0], d1 / h1**3
    v1, a1 = 3 * d1 / h1, 6 * d1 / h1**2
    # last cubic: q3 - d3 (1 - tau/h3)^3, expanded in tau
    coefs[2, 0] = q[2]
    coefs[2, 1] = 3 * d3 / h3
    coefs[2, 2] = -3 * d3 / h3**2
    coefs[2, 3] = d3 / h3**3
    v2, a2 = 3 * d3 / h3, -6 * d3 / h3**2
    # middle quintic: 6 boundary conditions
    c0, c1, c2 = q[1], v1, a1 / 2
    T = h2
    M = np.array([[T**3, T**4, T**5], [3 * T**2, 4 * T**3, 5 * T**4], [6 * T, 12 * T**2, 20 * T**3]])
    rhs = np.stack([q[2] - (c0 + c1 * T + c2 * T**2), v2 - (c1 + 2 * c2 * T), a2 - 2 * c2])
    c345 = np.linalg.solve(M, rhs)
    coefs[1, 0], coefs[1, 1], coefs[1, 2] = c0, c1, c2
    coefs[1, 3:6] = c345
    return Trajectory(t, coefs)


def dense_peaks(trajectory, n: int = 20001) -> np.ndarray:
    """(3, n_joints) max |v|, |a|, |jerk| on a dense uniform grid (independent check)."""
    t = np.linspace(0.0, trajectory.duration, n)
    _, qd, qdd, qddd = trajectory.sample(t)
    return np.stack([np.abs(qd).max(0), np.abs(qdd).max(0), np.abs(qddd).max(0)])
