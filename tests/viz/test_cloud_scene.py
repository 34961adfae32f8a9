"""Workspace clouds in a scene: their colours."""

from __future__ import annotations

import numpy as np

from pinarms.viz.cloud_scene import colors_by_value


def test_colors_by_value_scale():
    c = colors_by_value(np.array([0.0, 0.5, 1.0]))
    assert c.shape == (3, 3)
    np.testing.assert_allclose(c[0], [0.267004, 0.004874, 0.329415], atol=1e-6)  # viridis(0)
    np.testing.assert_allclose(c[2], [0.993248, 0.906157, 0.143936], atol=1e-6)  # viridis(1)
    assert np.all(colors_by_value(np.zeros(4)) == colors_by_value(np.zeros(4))[0])
