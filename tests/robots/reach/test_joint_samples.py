"""Slices of the seeded joint-sample stream: the samples of robot.random_q, drawn without the others."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.errors import InvalidInput
from pinarms.robots.reach.joint_samples import random_q_slice
from pinarms.robots.reach.workspace import sample_workspace


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


def test_slices_of_the_stream_are_the_samples(aubo):
    in_memory = sample_workspace(aubo, 12_400, seed=5, frame="flange")
    assert np.array_equal(random_q_slice(aubo, 5, 12_345, 7), in_memory.q[12_345:12_352])
    assert np.array_equal(random_q_slice(aubo, 5, 0, 3), aubo.random_q(3, seed=5))


@pytest.mark.parametrize("seed, start, count, match", [(-1, 0, 1, "seed"), (0, -2, 1, "start"), (0, 0, 1.5, "count")])
def test_bad_slices_name_the_argument(aubo, seed, start, count, match):
    with pytest.raises(InvalidInput, match=match):
        random_q_slice(aubo, seed, start, count)
