"""IK along a tool path by continuation: knots are exact IK solutions, and a named stop where it cannot go on."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.planning import cartesian_path, tool_path
from pinarms.planning.ik_continuation import MAX_JOINT_STEP, PathSolver, Stop, continue_to, solve_knots
from pinarms.robots.reach.layout import default_orientation


def pose(R, p):
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


def test_continuation_gives_exact_ik_solutions_in_small_joint_steps(aubo):
    R = default_orientation(aubo)
    P = np.stack([pose(R, [0.35, 0.20, 0.0]), pose(R, [0.35, 0.20, 0.30])])
    q0 = cartesian_path(aubo, P).q_knots[0]
    tool = tool_path(P)
    sv = PathSolver(aubo, tool, "tcp", 1e-4)
    start = solve_knots(sv, np.array([0.0]), q0[None])[0]
    knots = continue_to(sv, start, tool.length, 1e-5)
    assert knots[-1].s == tool.length
    s = np.array([k.s for k in knots])
    q = np.array([k.q for k in knots])
    assert np.all(np.diff(s) > 0.0)
    F = aubo.fk(q)
    assert np.linalg.norm(F[:, :3, 3] - tool.position(s), axis=1).max() < 1e-9
    assert np.abs(np.diff(np.vstack([q0, q]), axis=0)).max() <= MAX_JOINT_STEP


def test_continuation_stops_where_the_path_leaves_the_workspace(aubo):
    R = default_orientation(aubo)
    P = np.stack([pose(R, [0.35, 0.20, 0.0]), pose(R, [0.05, 0.0, 0.9])])
    q0 = cartesian_path(aubo, np.stack([P[0], pose(R, [0.35, 0.20, 0.1])])).q_knots[0]
    tool = tool_path(P)
    sv = PathSolver(aubo, tool, "tcp", 1e-4)
    start = solve_knots(sv, np.array([0.0]), q0[None])[0]
    with pytest.raises(Stop) as stop:
        continue_to(sv, start, tool.length, 1e-5)
    assert 0.0 < stop.value.s < tool.length
    assert stop.value.kind in ("newton", "jump", "limit", "singular")
