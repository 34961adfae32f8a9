"""How fast a cell's collision geometry can move (cell/speed_bound.py): joint levers and peak speeds."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.robots.cell import load_cell
from pinarms.robots.cell.motion import joint_levers
from pinarms.robots.cell.speed_bound import peak_speed
from pinarms.errors import InvalidInput


@pytest.fixture(scope="module")
def line():
    return load_cell("mushroom_line")


def test_levers_of_the_scaras(line):
    lev = joint_levers(line)
    assert lev[2] == 1.0 and lev[6] == 1.0  # prismatic j3: lever 1
    assert 0.45 < lev[0] < 1.5  # j1 carries the whole arm: about the reach (0.45 m) plus the bodies


def test_levers_bound_the_speed_of_every_geometry_centre(line):
    lev = joint_levers(line)
    q = line.random_q(50, seed=11)
    qd = np.random.default_rng(12).uniform(-1.0, 1.0, q.shape)
    h = 1e-6
    _, p0 = line.geometry_placements(q)
    _, p1 = line.geometry_placements(q + h * qd)
    speed = np.linalg.norm(p1 - p0, axis=-1) / h  # (N, G) [m/s], primitives: the frame origin is their centre
    bound = np.abs(qd) @ lev
    assert (speed <= bound[:, None] * (1.0 + 1e-4) + 1e-9).all()
    assert speed.max() > 0.2 * bound.max()  # a bound, not a wild overestimate


class Sampled:
    """A trajectory without peaks(): its speeds are sampled."""

    start_time, end_time = 0.0, 1.0

    def __init__(self, traj) -> None:
        self.traj = traj

    def sample(self, t):
        return self.traj.sample(t)


def test_peak_speeds_are_exact_or_sampled_with_a_reserve(line):
    traj = planning.multi_quintic([0.0, 1.0], line.random_q(2, seed=13)[:, :4])
    exact = peak_speed(traj, 4, "left")
    np.testing.assert_allclose(exact, np.asarray(traj.peaks().velocity))
    sampled = peak_speed(Sampled(traj), 4, "left")
    assert (sampled >= exact).all() and (sampled <= 1.06 * exact).all()
    with pytest.raises(InvalidInput, match="must be 3 finite numbers"):
        peak_speed(traj, 3, "trajectory of arm 'left'")
