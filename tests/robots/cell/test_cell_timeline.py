"""The arms' motions on the cell's clock (cell/timeline.py): windows, configurations, sampling."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.robots.cell.timeline import arm_motions, configurations, motion_window, sample_motions
from pinarms.errors import InvalidInput


@pytest.fixture(scope="module")
def line():
    return load_cell("mushroom_line")


@pytest.fixture(scope="module")
def moves(line):
    q = line.random_q(2, seed=5)
    left = planning.multi_quintic([0.0, 1.0], q[:, :4])
    right = planning.multi_quintic([0.0, 2.0], q[:, 4:])
    return left, right


def test_the_window_spans_the_motions_or_the_longest_period(moves):
    left, right = moves
    assert motion_window([ArmMotion("left", left, 0.5), ArmMotion("right", right, -0.2)]) == (-0.2, 1.8)
    assert motion_window([ArmMotion("left", left, 0.5, 3.0), ArmMotion("right", right)]) == (0.0, 3.0)


def test_configurations_follow_offsets_periods_and_hold(line, moves):
    left, _ = moves
    hold = line.random_q(1, seed=6)[0]
    motion = ArmMotion("left", left, offset=0.2, period=1.5)
    t = np.array([0.0, 0.2, 0.7, 1.2, 1.6, 1.7, 2.2])
    Q = configurations(line, [motion], t, hold)
    expected = left.sample(np.array([1.0, 0.0, 0.5, 1.0, 1.0, 0.0, 0.5]))[0]  # wrapped, held at the ends
    np.testing.assert_allclose(Q[:, :4], expected, atol=1e-12)
    np.testing.assert_array_equal(Q[:, 4:], np.tile(hold[4:], (t.size, 1)))


def test_sampling_includes_the_window_end(line, moves):
    left, right = moves
    t, Q = sample_motions(line, {"left": left, "right": (right, 0.5)}, hz=10.0)
    assert t[0] == 0.0 and t[-1] == 2.5 and t.size == 26
    np.testing.assert_allclose(Q[:, 4:], right.sample(np.clip(t - 0.5, 0.0, 2.0))[0], atol=1e-12)


def test_schedules_are_checked(line, moves):
    left, right = moves
    with pytest.raises(InvalidInput, match="has two motions"):
        arm_motions(line, [ArmMotion("left", left), ArmMotion("left", left, 1.0)])
    with pytest.raises(InvalidInput, match="has no 'start_time'"):
        arm_motions(line, {"left": object()})
    with pytest.raises(InvalidInput, match="must be ArmMotion objects"):
        arm_motions(line, [("left", left)])
    with pytest.raises(InvalidInput, match="offset of arm 'right'"):
        arm_motions(line, {"right": (right, float("nan"))})
    with pytest.raises(InvalidInput, match="hz must be a positive"):
        sample_motions(line, {"left": left}, hz=-1.0)
