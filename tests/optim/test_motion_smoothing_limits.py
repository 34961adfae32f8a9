"""optim.motion.smoothing: a spline kept inside the joint limits, and refused where its exact extrema leave them.

The cell is tests/optim/data/aubo_wall.urdf.xacro (the AUBO-i3 by a wall, as in
test_motion_smoothing.py). A planner's polyline may have vertices on a joint limit (an IK goal
or a shortcut vertex there): a C² spline through such a vertex where the joint turns overshoots
the limit by a sliver between the proof's samples, which no vertex insertion removes.
"""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.optim.motion.smoothing import prove_path, smooth_path, within_limits
from pinarms.optim.motion.spline_proof import joint_extrema
from pinarms.planning import joint_spline

from tests.optim.test_motion_smoothing import checker  # noqa: F401 (fixture: the AUBO-i3 by the wall)


@pytest.fixture(scope="module")
def on_limit(checker):
    """Waypoints on one side of the wall; joint 6 (the tool flange) turns on its upper limit at vertex 2."""
    from tests.optim.test_motion import _tool_down

    qa, _ = _tool_down(checker.cell, [0.35, 0.3, 0.90])
    W = np.stack([qa + d for d in np.linspace(0.0, 0.3, 5)[:, None] * np.array([1.0, 0.5, -0.5, 0.3, 0.2, 0.0])])
    W[:, 5] = checker.upper[5] - np.array([1.2, 0.4, 0.0, 0.3, 1.0])
    return W


def _overshoot(checker, path):
    lo, hi = joint_extrema(np.asarray(path.breaks, dtype=float), path.coefficients)
    return float(np.max(np.maximum(checker.lower - lo, hi - checker.upper)))


def test_the_exact_extrema_are_those_of_dense_samples(checker, on_limit):
    path = joint_spline(on_limit)
    lo, hi = joint_extrema(np.asarray(path.breaks, dtype=float), path.coefficients)
    for k in range(lo.shape[0]):
        Q = path(np.linspace(path.breaks[k], path.breaks[k + 1], 20_001))
        np.testing.assert_allclose(hi[k], Q.max(axis=0), atol=1e-9)
        np.testing.assert_allclose(lo[k], Q.min(axis=0), atol=1e-9)
        assert np.all(hi[k] >= Q.max(axis=0) - 1e-12) and np.all(lo[k] <= Q.min(axis=0) + 1e-12)


def test_a_spline_over_a_limit_between_samples_is_refused(checker, on_limit):
    path = joint_spline(on_limit)
    assert _overshoot(checker, path) > 1e-4  # the flange turns on its limit with a slope: it overshoots
    verdict, piece = prove_path(checker, path)
    assert not verdict.ok and piece in (1, 2)  # a piece around the vertex on the limit
    assert not prove_path(checker, path, compiled=False)[0].ok


def test_within_limits_changes_only_the_joint_that_leaves_and_keeps_the_waypoints(checker, on_limit):
    path = joint_spline(on_limit)
    kept = within_limits(path, on_limit, checker.lower, checker.upper)
    assert _overshoot(checker, kept) <= 1e-12
    np.testing.assert_array_equal(kept.coefficients[:, :, :5], path.coefficients[:, :, :5])  # other joints: the C² spline
    np.testing.assert_allclose(kept(kept.breaks), on_limit, atol=1e-12)  # through every waypoint
    _, dq, _ = kept.sample(kept.breaks[1:-1] - 1e-9)
    _, dq_after, _ = kept.sample(kept.breaks[1:-1] + 1e-9)
    np.testing.assert_allclose(dq, dq_after, atol=1e-6)  # C¹ at every knot
    assert within_limits(kept, on_limit, checker.lower, checker.upper) is kept  # nothing leaves: the path itself


def test_smoothing_a_polyline_through_a_limit_gives_a_proven_spline_inside(checker, on_limit):
    path, method, rounds = smooth_path(checker, on_limit)
    # the plain spline refused once at the vertex on the limit (no refinement), then kept inside the limits
    assert (method, rounds) == ("cubic spline", 1)
    assert smooth_path(checker, on_limit, compiled=False)[1:] == (method, rounds)
    assert _overshoot(checker, path) <= 1e-12
    assert prove_path(checker, path, compiled=False)[0].ok  # the exact proof alone agrees
