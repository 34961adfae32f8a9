"""Bad input: named errors that carry the offending value."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.planning import JointLimits
from pinarms.planning.errors import ConditionCountError, TrajectoryError
from pinarms.errors import PinarmsError


@pytest.mark.parametrize(
    "build",
    [
        lambda t, q: planning.multi_quintic(t, q),
        lambda t, q: planning.quintic_bspline(t, q),
        lambda t, q: planning.piecewise_polynomial(t, q, "3-5-3"),
        lambda t, q: planning.polynomial(t, q, 7),
    ],
)
def test_non_increasing_times(build):
    with pytest.raises(TrajectoryError, match=r"times\[2\] = 1.0 does not come after times\[1\] = 1.0"):
        build([0.0, 1.0, 1.0, 2.0], [0.0, 1.0, 2.0, 3.0])


def test_nan_and_shape_errors_name_the_value():
    with pytest.raises(TrajectoryError, match=r"positions must be finite; entry \(1, 0\) is nan"):
        planning.multi_quintic([0, 1, 2], [[0.0], [np.nan], [1.0]])
    with pytest.raises(TrajectoryError, match="positions has 2 points but there are 3 times"):
        planning.quintic_bspline([0, 1, 2], [0.0, 1.0])
    with pytest.raises(TrajectoryError, match="at least 2 instants, got 1"):
        planning.multi_quintic([0.0], [0.0])
    err = None
    try:
        planning.multi_quintic([0, np.inf], [0, 1])
    except PinarmsError as exc:  # the whole family is catchable at once
        err = exc
    assert isinstance(err, ValueError) and "inf" in str(err)


def test_too_few_points_or_wrong_parity_for_a_degree():
    with pytest.raises(ConditionCountError, match="degree-3 polynomial has 4 coefficients but 5 points"):
        planning.polynomial([0, 1, 2, 3, 4], [0, 1, 2, 3, 4], 3)
    with pytest.raises(ConditionCountError, match="leaves 1 end condition"):
        planning.polynomial([0, 1, 2], [0, 1, 2], 3)
    with pytest.raises(TrajectoryError, match="positive integer"):
        planning.polynomial([0, 1], [0, 1], 2.5)


@pytest.mark.parametrize(
    "degree, points, rest_orders",
    [(3, 2, 1), (5, 2, 2), (7, 4, 2), (5, 4, 1), (7, 2, 3)],
)
def test_polynomial_end_conditions(degree, points, rest_orders):
    t = np.linspace(0.0, 2.0, points)
    q = np.sin(3 * t) + t
    traj = planning.polynomial(t, q, degree)
    out = traj.sample(t)
    np.testing.assert_allclose(out[0][:, 0], q, atol=1e-10)
    for r in range(1, min(rest_orders, 3) + 1):
        np.testing.assert_allclose(out[r][[0, -1], 0], 0.0, atol=1e-9)


def test_joint_limits_validation():
    with pytest.raises(TrajectoryError, match="velocity limit must be positive, got -1.0"):
        JointLimits(velocity=[1.0, -1.0])
    with pytest.raises(TrajectoryError, match="lower position limit must be below upper"):
        JointLimits(velocity=1.0, lower=[0.0, 1.0], upper=[1.0, 0.5])
    with pytest.raises(TrajectoryError, match="velocity limit is required"):
        JointLimits(velocity=None)
    lim = JointLimits(velocity=[1.0, 2.0], acceleration=3.0)
    np.testing.assert_array_equal(lim.for_joints("acceleration", 2), [3.0, 3.0])
    traj = planning.multi_quintic([0, 1], np.zeros((2, 3)) + [[0, 0, 0], [1, 1, 1]])
    with pytest.raises(TrajectoryError, match="2 entries but the trajectory has 3 joints"):
        traj.check(lim)
    with pytest.raises(TrajectoryError, match="JointLimits"):
        traj.check({"velocity": 1.0})
    assert lim.as_dict()["jerk"] is None


def test_joint_limits_from_a_robot_like_object():
    class Arm:
        velocity_limit = np.array([1.0, 2.0])
        lower = np.array([-1.0, -2.0])
        upper = np.array([1.0, 2.0])

    lim = JointLimits.from_robot(Arm(), acceleration=5.0)
    np.testing.assert_array_equal(lim.upper, [1.0, 2.0])
    traj = planning.multi_quintic([0, 1], [[0.0, 0.0], [0.5, 2.5]])
    kinds = {(v.joint, v.kind) for v in traj.check(lim).violations}
    assert kinds == {(1, "position_upper"), (1, "velocity"), (1, "acceleration")}  # 2.5 rad in 1 s


@pytest.mark.parametrize("degrees", [None, 5, 3.0])
def test_degrees_that_are_not_a_sequence_are_named(degrees):
    with pytest.raises(TrajectoryError, match=f"degrees must be a sequence.*got {degrees!r}"):
        planning.piecewise_polynomial([0, 1, 2, 3], [0.0, 1.0, 0.5, 2.0], degrees)


def test_scalar_arguments_refuse_arrays_and_huge_sample_counts():
    traj = planning.quintic_bspline([0.0, 1.0, 3.0], [0.0, 1.0, 2.0])
    with pytest.raises(TrajectoryError, match=r"hz must be a single number, got shape \(2,\)"):
        traj.at_rate([1, 2])
    with pytest.raises(TrajectoryError, match=r"factor must be a single number"):
        traj.scaled([1.0, 2.0])
    with pytest.raises(TrajectoryError, match=r"start_time must be a single number"):
        traj.shifted(np.zeros(3))
    # 1e12 Hz over 3 s would be 3e12 instants: refused, named, before any allocation.
    with pytest.raises(TrajectoryError, match=r"hz = 1e\+12 over 3 s gives 3000000000004 instants"):
        traj.at_rate(1e12)
    assert traj.at_rate(np.float64(10.0))[0].shape == (31,)


def test_joint_limits_with_position_bounds_of_different_lengths():
    with pytest.raises(TrajectoryError, match="same number of joints, got 2 and 3"):
        JointLimits(velocity=1.0, lower=[0.0, 1.0], upper=[1.0, 2.0, 3.0])
