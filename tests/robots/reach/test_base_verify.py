"""Candidate bases checked by exact IK: a base within reach is verified with its best manipulability, one out of reach is not."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.robots.reach.inverse_reach import tool_down_poses
from pinarms.robots.reach.base_verify import verify_bases
from pinarms.robots.reach.reachability import ReachabilityRequest, reachability_map


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


def test_a_base_within_reach_is_verified_and_one_out_of_reach_is_not(aubo):
    m = reachability_map(ReachabilityRequest(aubo, 0.2, 4, tool_down=np.radians(15), roll_steps=2, keep_solutions=False))
    tasks = tool_down_poses([[0.4, 0.0, 0.1]], m.orientations.tool_axis)
    bases = np.array([[0.0, 0.0, 0.0, 0.0], [3.0, 0.0, 0.0, 0.0]])  # x, y, z, yaw [m, rad]
    verified, w = verify_bases(aubo, m, bases, tasks, roll_free=False, roll_steps=1, self_collision=False,
                               collision=None)
    assert verified.tolist() == [True, False] and np.isnan(w[1])
    q = aubo.ik_all(tasks[0])  # the base at the origin sees the task as it is
    assert w[0] == pytest.approx(np.abs(np.linalg.det(aubo.jacobian(q))).max(), rel=1e-12)
