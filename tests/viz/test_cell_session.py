"""A cell in a session: all arms and fixtures drawn, both arms animated together, contacts red."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning, viz
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.errors import InvalidInput
from pinarms.viz.scene import build_scene
from pinarms.viz.scene_options import SceneOptions
from pinarms.viz.viewer import MeshcatServer


@pytest.fixture(scope="module")
def line_with_motion():
    cell = load_cell("mushroom_line")
    trajs = {}
    for name, pick, place in (("left", (-0.05, -0.03, 0.84), (0.22, 0.68, 0.84)),
                              ("right", (0.05, 0.03, 0.84), (0.22, -0.68, 0.84))):
        arm = cell.arm(name)
        q0 = arm.robot.ik(arm.to_base(np.array(pick)), position_only=True)
        q1 = arm.robot.ik(arm.to_base(np.array(place)), position_only=True)
        trajs[name] = planning.multi_quintic([0.0, 1.0], np.array([q0, q1]))  # straight: through the box walls
    motions = [ArmMotion("left", trajs["left"]), ArmMotion("right", trajs["right"], offset=0.5)]
    check = cell.check_motion(motions, margin=0.01, curve=True)
    return cell, motions, check


def test_a_cell_session_round_trips_with_its_arms_and_contacts(line_with_motion, tmp_path):
    cell, motions, check = line_with_motion
    assert check.first_contact is not None
    session = viz.Session(title="two arms")
    key = session.add_cell(cell, motions=motions, check=check)
    path = session.save(tmp_path / "line.pinarms")
    back = viz.load_session(path)
    assert back == session
    assert back.robots[key].source == "urdf" and back.robots[key].urdf_text == cell.urdf_text  # embedded
    assert back.cell_tcp_frames(key) == {"left": "left_tcp", "right": "right_tcp"}
    rec = back.trajectories["cell motion"]
    assert rec.q.shape[1] == cell.nq and rec.t[-1] == pytest.approx(1.5)
    # both arms move in the one trajectory, the right one starting 0.5 s later
    moving = np.abs(np.diff(rec.q, axis=0)).sum(axis=0) > 0
    assert moving[cell.arm("left").q_slice].any() and moving[cell.arm("right").q_slice].any()
    i = int(np.searchsorted(rec.t, 0.25))
    np.testing.assert_allclose(rec.q[i, cell.arm("right").q_slice], rec.q[0, cell.arm("right").q_slice])
    contacts = back.point_sets["cell motion contacts"]
    assert contacts.kind == "contact" and contacts.points.shape[0] == int(np.sum(check.clearance <= 0.0))
    # the arms hit each other over the belt (|y| small) and the boxes' walls (|y| about 0.6-0.77 m)
    y = np.abs(contacts.points[:, 1])
    assert (y < 0.1).any() and ((y > 0.58) & (y < 0.78)).any()
    assert np.all((contacts.points[:, 2] > 0.75) & (contacts.points[:, 2] < 1.2))


def test_the_scene_draws_every_fixture_and_one_tcp_path_per_arm(line_with_motion):
    cell, motions, check = line_with_motion
    session = viz.Session(title="two arms")
    session.add_cell(cell, motions=motions, check=check)
    with MeshcatServer() as server:
        info = build_scene(server.visualizer, session, SceneOptions(fps=20))
    drawn = " ".join(info.robots["mushroom_line"])
    for fixture in ("conveyor_belt", "conveyor_leg_1", "left_box_wall_xpos", "right_table", "left_pedestal"):
        assert fixture in drawn, fixture
    assert set(info.paths) == {"cell motion: left", "cell motion: right"}
    assert info.animated == ("cell motion",) and info.duration == pytest.approx(1.5)
    assert len(info.points["cell motion contacts"]) == int(np.sum(check.clearance <= 0.0))


def test_a_mesh_fixture_is_drawn_and_the_html_page_is_written(tmp_path):
    cell = load_cell("aubo_food_station")
    session = viz.Session(title="station")
    session.add_cell(cell)
    with MeshcatServer() as server:
        info = build_scene(server.visualizer, session)
    assert any("hopper" in p for p in info.robots["aubo_food_station"])
    out = viz.export_html(viz.load_session(session.save(tmp_path / "s.pinarms")), tmp_path / "s.html")
    assert out.stat().st_size > 100_000


def test_add_cell_checks_its_arguments(line_with_motion):
    cell, motions, check = line_with_motion
    session = viz.Session()
    with pytest.raises(InvalidInput, match="robots.cell.Cell"):
        session.add_cell("mushroom_line")
    with pytest.raises(InvalidInput, match="motions"):
        session.add_cell(cell, check=check)
