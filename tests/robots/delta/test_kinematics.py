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
