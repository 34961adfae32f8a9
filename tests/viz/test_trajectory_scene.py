"""The trajectories of a scene: which play, their frames in time, their world tcp paths (no server needed)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.errors import InvalidInput
from pinarms.viz.trajectory_scene import animated_trajectories, frame_times, interp_rows


def test_frame_times_end_exactly_on_the_duration():
    np.testing.assert_array_equal(frame_times(1.0, 4.0), [0.0, 0.25, 0.5, 0.75, 1.0])
    times = frame_times(1.1, 4.0)
    np.testing.assert_allclose(times, [0.0, 0.25, 0.5, 0.75, 1.0, 1.1], rtol=0, atol=1e-15)
    assert times[-1] == 1.1
    assert frame_times(0.0, 30.0).tolist() == [0.0]


def test_rows_are_interpolated_per_column_and_held_at_the_ends():
    t = np.array([0.0, 1.0, 3.0])
    q = np.array([[0.0, 10.0], [1.0, 20.0], [3.0, 0.0]])
    out = interp_rows(np.array([-1.0, 0.5, 2.0, 5.0]), t, q)
    np.testing.assert_allclose(out, [[0.0, 10.0], [0.5, 15.0], [2.0, 10.0], [3.0, 0.0]], rtol=0, atol=1e-15)


def test_the_first_trajectory_of_each_robot_plays_unless_chosen(line_session):
    first = animated_trajectories(line_session, None)
    assert first == ("pick-place 3-5-3",)
    assert animated_trajectories(line_session, ()) == ()
    with pytest.raises(InvalidInput, match=r"cannot animate \['nope'\]"):
        animated_trajectories(line_session, ["nope"])
    with pytest.raises(InvalidInput, match="at most one trajectory per robot"):
        animated_trajectories(line_session, [first[0], first[0]])
