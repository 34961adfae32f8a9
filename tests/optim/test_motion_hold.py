"""The idle arm at its hold pose: planning, checks and sessions use the cell's hold; an idle arm in collision is named."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pinarms import planning, viz
from pinarms.optim import GoalInCollision, StartInCollision, plan_motion
from pinarms.optim.motion import MotionChecker, MotionLimits, MotionOptions, MotionRequest, MotionStatus
from pinarms.robots import load_cell
from tests.robots.cell.bent_pair import bent_pair

def _cell(tmp_path: Path, hold: str = "", a_y: float = 0.6) -> object:
    return load_cell(bent_pair(tmp_path, "freeze = { finger_joint = 0.0 }\n" + hold, a_y=a_y))


def test_an_idle_arm_in_collision_at_its_hold_is_named_before_any_search(tmp_path):
    cell = _cell(tmp_path)  # b holds at neutral: in the table
    plan = plan_motion(MotionRequest(cell, "a", [0.0, -1.0, 0.0], [0.5, -1.0, 0.0],
                                     options=MotionOptions(time_limit=1.0), limits=MotionLimits(amax=2.0)))
    assert plan.status is MotionStatus.HOLD_IN_COLLISION and plan.which == "hold" and plan.states == 0
    assert ("b_link2", "table") in plan.pairs and min(plan.distances) < 0.0  # penetration depth, from coal
    np.testing.assert_array_equal(plan.configurations, cell.hold[None])  # the cell configuration in collision
    with pytest.raises(StartInCollision, match=r"idle arm 'b'.*b_link2 – table.*hold") as info:
        plan.raise_for_status()
    assert info.value.which == "hold" and info.value.pairs == plan.pairs


def test_a_goal_that_touches_the_idle_arm_names_it(tmp_path):
    cell = _cell(tmp_path, "hold = [1.5707963267948966, 0.0]", a_y=0.2)  # b's upper arm turned towards a, flat
    checker = MotionChecker(cell, ["a"])
    np.testing.assert_array_equal(checker.hold, cell.hold)  # the default hold is the cell's
    goal = [-1.5707963267948966, 0.0, 0.0]  # a's upper arm towards b: the two forearms meet
    assert cell.in_collision(cell.q_from_arms({"a": goal}))
    plan = plan_motion(MotionRequest(cell, "a", [0.0, -1.0, 0.0], goal, options=MotionOptions(time_limit=1.0),
                                     limits=MotionLimits(amax=2.0)))
    assert plan.status is MotionStatus.GOAL_IN_COLLISION and "arm 'b', idle at its hold pose" in plan.reason
    with pytest.raises(GoalInCollision, match=r"arm 'b', idle at its hold pose"):
        plan.raise_for_status()


def test_checks_and_sessions_hold_the_idle_arm_at_the_cells_hold(tmp_path):
    cell = _cell(tmp_path, "hold = [0.0, -1.2]")
    a, b = cell.arm("a"), cell.arm("b")
    traj = planning.multi_quintic([0.0, 1.0], np.array([[0.0, -1.0, 0.0], [0.5, -1.0, 0.0]]))
    check = cell.check_motion({"a": traj}, margin=0.01)
    assert check.collision_free  # with b at neutral, in the table, it would not be
    assert not cell.check_motion({"a": traj}, margin=0.01, hold=cell.neutral).collision_free
    session = viz.Session(title="hold")
    key = session.add_cell(cell, motions={"a": traj}, check=check)
    q = session.trajectories["cell motion"].q
    np.testing.assert_array_equal(q[:, b.q_slice], np.tile([0.0, -1.2], (q.shape[0], 1)))
    assert session.metadata["cells"][key]["hold"] == [float(v) for v in cell.hold]
    assert q[:, a.q_slice].std(axis=0)[0] > 0.1


def test_a_saved_cell_without_motions_rests_at_its_hold(tmp_path):
    cell = _cell(tmp_path, "hold = [0.0, -1.2]")
    session = viz.Session(title="rest")
    key = session.add_cell(cell)
    session.save(tmp_path / "s.pinarms")
    loaded = viz.load_session(tmp_path / "s.pinarms")
    np.testing.assert_array_equal(loaded.cell_hold(key), cell.hold)
    assert not cell.in_collision(loaded.cell_hold(key))
    loaded.metadata["cells"][key]["hold"] = [0.0, "x"]  # a hostile file's value: ignored, never drawn
    assert loaded.cell_hold(key) is None
    loaded.metadata["cells"][key]["hold"] = [0.0] * (cell.nq + 1)
    assert loaded.cell_hold(key) is None


def test_a_layout_worker_rebuilds_the_cell_with_its_hold(tmp_path):
    import pickle

    from pinarms.optim.layout import LayoutRequest
    from pinarms.optim.layout.evaluate import _cell_of, forget_cell
    from pinarms.optim.layout.search import _cell_recipe

    cell = _cell(tmp_path, "hold = [0.0, -1.2]")
    request = LayoutRequest(cell, np.array([0.3, 0.0, 0.8]), np.array([0.0, 0.3, 0.8]), np.zeros((1, 4)), arm="a",
                            clearance=0.02)
    recipe = _cell_recipe(request, "hold-test-token")
    forget_cell("hold-test-token")  # as in a worker process: the cell is rebuilt from the (pickled) recipe
    rebuilt = _cell_of(pickle.loads(pickle.dumps(recipe)))
    forget_cell("hold-test-token")
    assert rebuilt is not cell
    np.testing.assert_array_equal(rebuilt.hold, cell.hold)
    assert dict(rebuilt.arm("b").frozen) == {"finger_joint": 0.0}


def test_a_cycle_next_to_an_idle_arm_in_collision_names_it_before_any_attempt(tmp_path):
    from pinarms import optim
    from pinarms.errors import CollisionError

    cell = _cell(tmp_path)  # b at neutral, in the table
    a = cell.arm("a")
    spec = optim.PickPlace(pick=[0.3, 0.1, 0.1], place=[0.3, -0.1, 0.1], lift=0.03)
    with pytest.raises(CollisionError, match=r"idle arm 'b' is in collision at its hold pose: b_link2 – table"):
        optim.plan_cycle(optim.CycleRequest(a.robot, spec, cell=optim.CellSettings(cell, clearance=0.01)))


@pytest.mark.slow
def test_a_motion_beside_an_arm_held_clear_of_the_table_is_planned_and_proven(tmp_path):
    cell = _cell(tmp_path, "hold = [0.0, -1.2]")  # at neutral, b lies in the table: the re-check failed after the search
    plan = plan_motion(MotionRequest(cell, "a", [0.0, -1.0, 0.0], [0.8, -0.6, 0.0],
                                     options=MotionOptions(time_limit=5.0), limits=MotionLimits(amax=2.0)))
    assert plan.check.collision_free
    np.testing.assert_array_equal(plan.hold, cell.hold)
    q = plan.cell_trajectory().sample(np.linspace(0.0, plan.duration, 20))[0]
    np.testing.assert_array_equal(q[:, cell.arm("b").q_slice], np.tile([0.0, -1.2], (20, 1)))
