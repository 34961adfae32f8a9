"""TimedCurve names what the torque and limit constraints read: a Trajectory offers each member."""

from __future__ import annotations

import numpy as np

from pinarms.planning.point_to_point import trapezoidal
from pinarms.planning.timed_curve import CurvePeaks, TimedCurve


def _members(protocol: type) -> set[str]:
    return {n for n in vars(protocol) if not n.startswith("_")} | set(getattr(protocol, "__annotations__", {}))


def test_trajectory_offers_every_member_of_the_protocol():
    traj = trapezoidal([0.0, 0.0], [1.0, -0.5], vmax=1.0, amax=2.0)
    assert _members(TimedCurve) == {"n_joints", "knot_times", "coefficients", "peaks", "sample"}
    for name in _members(TimedCurve):
        assert hasattr(traj, name), name
    assert traj.n_joints == 2 and traj.coefficients.shape[2] == 2 and traj.knot_times.ndim == 1
    peaks = traj.peaks()
    for name in _members(CurvePeaks):
        assert np.asarray(getattr(peaks, name)).shape == (2,), name
    q, qd, qdd, qddd = traj.sample(np.array([0.0, traj.knot_times[-1]]))
    np.testing.assert_allclose(q[-1], [1.0, -0.5], atol=1e-12)
