"""Dexterity of the tool's position: manipulability and inverse condition of the position Jacobian."""

from __future__ import annotations

import numpy as np

from pinarms.robots.reach.dexterity import position_dexterity


def test_position_dexterity_of_known_jacobians():
    J = np.zeros((3, 3, 4))
    J[0, :, :3] = np.diag([2.0, 1.0, 0.5])  # σ = 2, 1, 0.5
    J[1, :, :3] = np.diag([1.0, 1.0, 0.0])  # singular
    J[2, :, :3] = np.eye(3)  # isotropic
    w, c = position_dexterity(J)
    np.testing.assert_allclose(w, [1.0, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(c, [0.25, 0.0, 1.0], atol=1e-9)
