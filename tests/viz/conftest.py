"""Shared fixtures of the viz tests: a small packing-line session (SCARA, conveyor, crate)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms import robots
from pinarms import viz
from pinarms.papers import SEED000

DEG = np.pi / 180.0


def _pose(x: float, y: float, z: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = [x, y, z]
    return T


@pytest.fixture(scope="session")
def line_session() -> viz.Session:
    """SCARA on a 3-5-3 pick-and-place through seed 000's joint-1 path points, plus a UR5 cell."""
    arm = robots.load("scara_mushroom")
    s = viz.Session(arm, title="enoki packing line", key="scara")
    j1 = SEED000.path_rad
    via = np.column_stack([j1, np.array([-60.0, -40.0, 30.0, 60.0]) * DEG, [0.02, 0.10, 0.10, 0.02],
                           np.array([0.0, 30.0, 60.0, 90.0]) * DEG])
    traj = planning.piecewise_polynomial(SEED000.paper_knot_times_s, via, degrees=(3, 5, 3))
    s.add_trajectory("pick-place 3-5-3", traj, hz=60)
    q = arm.random_q(1500, seed=7)
    s.add_workspace("scara cloud", points=arm.position(q), manipulability=arm.manipulability(q, part="position"))
    s.add_points("crate targets", [[0.3, -0.3, 0.05], [0.35, -0.3, 0.05]], kind="target")
    s.add_box("conveyor", [1.2, 0.25, 0.06], pose=_pose(0.35, 0.3, 0.03), color=(0.3, 0.3, 0.35, 1.0))
    s.add_box("crate", [0.3, 0.2, 0.1], pose=_pose(0.32, -0.3, 0.05), color=(0.8, 0.6, 0.3, 1.0))
    return s


@pytest.fixture(scope="session")
def belt_line():
    """Seed 000's line of two SCARAs at 90 bunches/min (one seed, 20 s) and its result (package task maps)."""
    from pinarms.optim.line import run_line
    from pinarms.studies.line import maps_for, scara_line

    spec = scara_line(2, 90.0, seeds=(0,), duration=20.0)
    return spec, run_line(spec, maps=maps_for(spec, build=False))


@pytest.fixture(scope="session")
def belt_session(belt_line) -> viz.Session:
    """The first 8 s of :func:`belt_line` in a session (arms replanned pick by pick)."""
    spec, result = belt_line
    s = viz.Session(title="enoki belt line")
    s.add_line(spec, result, duration=8.0, name="belt")
    return s
