"""Closed-form kinematics of the delta against Pinocchio's closed-chain model."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.robots.delta import (BRANCH_COUNT, DeltaInputError, DeltaUnreachable, forward_position, inverse_position,
                                  inverse_position_branches)


def _serpentine(theta: np.ndarray, lower: float, upper: float, k: int = 12) -> np.ndarray:
    """Order samples cell by cell along a serpentine through a k^3 grid (neighbours close)."""
    c = np.minimum(((theta - lower) / (upper - lower) * k).astype(int), k - 1)
    i, j, m = c.T
    j2 = np.where(i % 2, k - 1 - j, j)
    m2 = np.where((i * k + j2) % 2, k - 1 - m, m)
    return np.lexsort((m2, j2, i))


#: R. L. Williams II, "The Delta Parallel Robot: Kinematics Solutions" (Ohio University, 2015), worked
#: examples for the ABB FlexPicker dimensions (sB 567, sP 76, L 524, l 1244 mm), as printed there and
#: reproduced by github.com/Pieces98/Deltarobot_Kinematics: motor angles [deg] -> platform [mm], in
#: Williams' frame (leg 1 along -y, so his frame is ours turned by -90 degrees about z).
WILLIAMS_EXAMPLES = (((0.0, 0.0, 0.0), (0.0, 0.0, -1064.4517)),
                     ((10.0, 20.0, 30.0), (108.1354, -180.3484, -1243.5413)),
                     ((-20.5, -20.5, -20.5), (0.0, 0.0, -900.3195)),
                     ((47.5, -11.6, 21.4), (300.4598, 499.9385, -1099.8281)))


@pytest.mark.parametrize("theta_deg, p_mm", WILLIAMS_EXAMPLES)
def test_the_shipped_delta_reproduces_williams_worked_examples(delta, theta_deg, p_mm):
    """The shipped geometry is the published one: each example to its printed 0.1 um, both ways."""
    ours_to_williams = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    p = ours_to_williams @ forward_position(delta.geometry, np.radians(theta_deg)) * 1000.0
    assert np.round(p, 4) + 0.0 == pytest.approx(p_mm, abs=1e-4)
    back = inverse_position(delta.geometry, ours_to_williams.T @ np.asarray(p_mm) / 1000.0)
    assert np.degrees(back) == pytest.approx(theta_deg, abs=1e-3)


@pytest.mark.slow
def test_closed_form_equals_pinocchio_projection_on_10000_configurations(delta):
    """Every passive joint solved by Newton's projection onto the closures (Pinocchio's constraint
    Jacobians), from the home configuration and then from the previous sample: the platform
    equals the closed form within 1e-9 m, every closure holds within 1e-12 m."""
    lim = delta.limits
    theta = np.random.default_rng(38).uniform(lim.lower, lim.upper, size=(10_000, 3))
    theta = theta[_serpentine(theta, lim.lower, lim.upper)]
    q = delta.project(theta, chain=True, tol=1e-12)
    err = np.linalg.norm(q[:, delta.platform_q] - forward_position(delta.geometry, theta), axis=1)
    assert err.max() <= 1e-9, err.max()
    every = q[::50]
    assert delta.closure_residuals(every).max() <= 2e-12      # norm of a 1e-12 m largest component
    # the passive joints themselves agree with the closed form's
    closed = delta.configuration(theta)
    assert np.abs(q - closed).max() <= 1e-8


def test_projection_from_home_reaches_the_closed_form(delta):
    theta = np.array([[0.1, 0.9, 0.4], [1.2, -0.5, 0.3], [0.0, 0.0, 0.0]])
    q = delta.project(theta)
    assert np.abs(q[:, delta.platform_q] - forward_position(delta.geometry, theta)).max() <= 1e-9
    assert delta.closure_residuals(q).max() <= 1e-12


def test_ik_round_trip_on_every_branch(delta):
    g = delta.geometry
    rng = np.random.default_rng(7)
    p = forward_position(g, rng.uniform(delta.limits.lower, delta.limits.upper, size=(500, 3)))
    theta, real = inverse_position_branches(g, p)
    assert theta.shape == (500, BRANCH_COUNT, 3) and real.all()
    for b in range(BRANCH_COUNT):
        lower, upper = forward_position(g, theta[:, b]), forward_position(g, theta[:, b], assembly="upper")
        err = np.minimum(np.linalg.norm(lower - p, axis=1), np.linalg.norm(upper - p, axis=1))
        assert err.max() <= 1e-9, (b, err.max())
    assert np.abs(forward_position(g, inverse_position(g, p)) - p).max() <= 1e-9
    # the branches differ: leg i's two roots are distinct away from a serial singularity
    assert np.abs(theta[:, 1, 0] - theta[:, 0, 0]).min() > 1e-3


def test_the_primary_branch_reproduces_the_sampled_angles(delta):
    g = delta.geometry
    theta = np.random.default_rng(3).uniform(delta.limits.lower, delta.limits.upper, size=(500, 3))
    assert np.abs(inverse_position(g, forward_position(g, theta)) - theta).max() <= 1e-9


def test_out_of_reach_and_bad_input_are_named_errors(delta):
    g = delta.geometry
    with pytest.raises(DeltaUnreachable, match="out of the delta's reach"):
        inverse_position(g, [0.0, 0.0, -5.0])
    assert np.isnan(inverse_position(g, [[0.0, 0.0, -5.0], [0.0, 0.0, -1.0]])[0]).all()
    with pytest.raises(DeltaUnreachable, match="cannot be assembled"):
        forward_position(g, [3.0, 0.0, 0.0])
    with pytest.raises(DeltaInputError, match="shape"):
        forward_position(g, [0.1, 0.2])
    with pytest.raises(DeltaInputError, match="not finite"):
        inverse_position(g, [0.0, np.nan, -1.0])


def test_the_six_rods_are_parallelograms_of_the_forearm_length(delta):
    from pinarms.robots.delta import rod_endpoints

    g = delta.geometry
    q = delta.configuration(np.random.default_rng(4).uniform(delta.limits.lower, delta.limits.upper, size=(50, 3)))
    ends = rod_endpoints(delta, q)                                       # (N, leg, rod, end, xyz)
    rods = ends[:, :, :, 1] - ends[:, :, :, 0]
    assert np.abs(np.linalg.norm(rods, axis=-1) - g.forearm).max() < 1e-12
    assert np.abs(rods[:, :, 0] - rods[:, :, 1]).max() < 1e-12          # the two rods of a leg are parallel
    spacing = np.linalg.norm(ends[:, :, 0, 0] - ends[:, :, 1, 0], axis=-1)
    assert np.abs(spacing - g.rod_spacing).max() < 1e-12
    assert rod_endpoints(delta, q[0]).shape == (3, 2, 2, 3)
