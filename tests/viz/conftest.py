"""Shared fixtures of the viz tests: a small packing-line session (SCARA, conveyor, crate)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms import robots
from pinarms import viz
from pinarms.papers import SEED000

from session_files import LEVER_URDF

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


@pytest.fixture(scope="module")
def ur5():
    return robots.load("ur5")


@pytest.fixture()
def session(ur5):
    """A UR5 and a lever robot with two trajectories, a cloud, points, a GA history and a box."""
    s = viz.Session(ur5, title="pick & place", metadata={"line": "enoki", "speeds": (1.5, 2)})
    times = np.array([0.0, 1.0, 3.0, 4.0])
    via = ur5.random_q(4, seed=1)
    s.add_trajectory("P1-P4 quintic", planning.multi_quintic(times, via), hz=50)
    s.add_trajectory("raw", (np.linspace(0, 1, 7), ur5.random_q(7, seed=2)))
    q = ur5.random_q(300, seed=3)
    s.add_workspace("cloud", points=ur5.position(q), manipulability=ur5.manipulability(q))
    s.add_points("targets", [[0.4, 0.1, 0.2], [0.3, -0.2, 0.25]], kind="target")
    s.add_points("vias", [[0.1, 0.2, 0.3]], robot="ur5")
    s.add_history("ga", {"best": [5.0, 4.0, 3.6], "mean": [7.0, 5.5, 4.0], "feasible_share": [0.2, 0.6, 1.0]})
    lever = robots.from_urdf_text(LEVER_URDF)
    T = np.eye(4)
    T[:3, 3] = [1.0, 0.5, 0.0]
    s.add_robot(lever, base_to_world=T)
    s.add_box("conveyor", [1.2, 0.3, 0.05], pose=T, color=(0.2, 0.3, 0.8, 0.5))
    return s


@pytest.fixture()
def saved(session, tmp_path):
    """:func:`session` saved in ``tmp_path``."""
    return session.save(tmp_path / "good.pinarms")
