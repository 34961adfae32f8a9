"""What a session takes from its user: every bad value refused, naming it."""

from __future__ import annotations


import numpy as np
import pytest

from pinarms import planning
from pinarms import viz
from pinarms.errors import InvalidInput



def test_bad_inputs_name_the_problem(ur5, tmp_path):
    s = viz.Session(ur5)
    with pytest.raises(InvalidInput, match="6 joints"):
        s.add_trajectory("x", (np.linspace(0, 1, 5), np.zeros((5, 4))))
    with pytest.raises(InvalidInput, match="strictly increasing"):
        s.add_trajectory("x", (np.array([0.0, 1.0, 1.0]), np.zeros((3, 6))))
    with pytest.raises(InvalidInput, match="not allowed"):
        s.add_points("a/b", [[0, 0, 0]])
    s.add_points("p", [[0, 0, 0]])
    with pytest.raises(InvalidInput, match="already exists"):
        s.add_points("p", [[0, 0, 0]])
    with pytest.raises(InvalidInput, match="kind"):
        s.add_points("q", [[0, 0, 0]], kind="waypoint")
    with pytest.raises(InvalidInput, match="rigid transform"):
        s.add_robot("panda", base_to_world=np.diag([2.0, 1, 1, 1]))
    with pytest.raises(InvalidInput, match="JSON-able"):
        viz.Session(ur5, metadata={"x": float("nan")})
    with pytest.raises(InvalidInput, match="folder"):
        s.save(tmp_path / "no" / "such" / "dir.pinarms")
    two = viz.Session(ur5)
    two.add_robot("ur5", key="ur5_b")
    with pytest.raises(InvalidInput, match="2 robots"):
        two.add_trajectory("t", (np.array([0.0, 1.0]), np.zeros((2, 6))))


def test_more_bad_inputs_name_the_problem(ur5):
    s = viz.Session(ur5)
    with pytest.raises(InvalidInput, match="must be a robots.Workspace"):
        s.add_workspace("w", 42)
    with pytest.raises(InvalidInput, match="no points"):
        s.add_workspace("w", points=np.zeros((0, 3)), manipulability=np.zeros(0))
    with pytest.raises(InvalidInput, match="no points"):
        s.add_points("p", np.zeros((0, 3)))
    with pytest.raises(InvalidInput, match="must be numbers"):
        s.add_points("p", "conveyor")
    with pytest.raises(InvalidInput, match="RGBA"):
        s.add_box("b", [1.0, 1.0, 1.0], color="red")
    with pytest.raises(InvalidInput, match="no generations"):
        s.add_history("h", {"best": []})
    with pytest.raises(InvalidInput, match="NaN"):
        s.add_history("h", {"best": [1.0, float("nan")]})
    # 1000 s at 1e5 Hz would be 1e8 samples (tens of GB): refused before sampling
    long = planning.multi_quintic(np.array([0.0, 1000.0]), ur5.random_q(2, seed=0))
    with pytest.raises(InvalidInput, match="lower hz"):
        s.add_trajectory("long", long, hz=1e5)
    assert s.trajectories == {} and s.workspaces == {} and s.point_sets == {} and s.histories == {}


def test_history_with_generations_without_finite_objective_round_trips(ur5, tmp_path):
    """optim's GA records inf as the mean of a generation with no finite objective."""
    s = viz.Session(ur5)
    s.add_history("ga", {"best": [np.inf, 4.0, 3.5], "mean": [np.inf, np.inf, 5.0]})
    back = viz.load_session(s.save(tmp_path / "h.pinarms"))
    assert back == s
    np.testing.assert_array_equal(back.histories["ga"].mean, [np.inf, np.inf, 5.0])
    out = viz.plot_ga_convergence(tmp_path / "ga.png", back.histories["ga"])
    assert out.stat().st_size > 0
