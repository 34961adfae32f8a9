"""The torque screen before the refined peaks: clearly within the limit, the dilation is 1 without refining;
near the limit it defers to the refined peaks (same dilation as before the screen)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning, robots
from pinarms.planning.torque import clearly_within, torque_dilation, torque_peaks


@pytest.fixture(scope="module")
def arm_move():
    aubo = robots.load("aubo_i3").with_payload(3.0)
    q = np.array([[0.3, -0.4, 1.2, 0.2, 1.57, 0.0], [0.0, 0.1, 1.6, 0.4, 1.3, 0.3], [-1.2, 0.3, 1.5, 0.2, 1.57, 0.0]])
    move = planning.multi_quintic([0.0, 0.5, 1.1], q)
    return aubo, move, torque_peaks(move, aubo).torque


def test_screen_passes_far_below_and_defers_near_the_limit(arm_move):
    aubo, move, peak = arm_move
    assert clearly_within(move, aubo, 3.0 * peak)
    assert torque_dilation(move, aubo, 3.0 * peak) == 1.0
    # at 1.001 × the refined peak the screen cannot tell: the refined peaks decide (still 1)
    assert not clearly_within(move, aubo, 1.001 * peak)
    assert torque_dilation(move, aubo, 1.001 * peak) == 1.0
    # the shoulder's limit below its peak (the others far above): a dilation > 1 that meets the limits
    limit = 3.0 * peak
    limit[1] = 0.9 * peak[1]
    assert not clearly_within(move, aubo, limit)
    f = torque_dilation(move, aubo, limit)
    assert 1.0 < f < 2.0
    assert np.all(torque_peaks(move.scaled(f), aubo).torque <= limit * (1.0 + 1e-9))


def test_screen_never_passes_a_trajectory_whose_refined_peak_exceeds_the_limit(arm_move):
    aubo, move, peak = arm_move
    for scale in (0.9, 0.99, 0.999999):
        limit = peak * scale
        assert not clearly_within(move, aubo, limit)
