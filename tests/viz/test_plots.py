"""Plots: PNG and SVG files with the expected content, atomic writes, checked inputs."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from PIL import Image

from pinarms import planning
from pinarms import viz
from pinarms.viz.joint_curves import JointCurves
from pinarms.errors import InvalidInput
from pinarms.papers import SEED000


@pytest.fixture(scope="module")
def traj():
    via = SEED000.path_rad[:, None]
    return planning.piecewise_polynomial(SEED000.initial_knot_times_s, via, degrees=(3, 5, 3))


def test_joint_curves_png(traj, tmp_path):
    limits = planning.JointLimits(velocity=np.deg2rad(55.0), acceleration=1.0, jerk=5.0)
    out = viz.plot_trajectory(tmp_path / "j1.png", traj, limits=limits, degrees=True, joint_names=["J1"])
    assert out == tmp_path / "j1.png"
    img = Image.open(out)
    assert img.format == "PNG"
    w, h = img.size
    assert w > 600 and h > 4 * 200  # four panels: position, velocity, acceleration, jerk
    assert os.listdir(tmp_path) == ["j1.png"]


def test_joint_curves_svg_labels(traj, tmp_path):
    t = np.linspace(0.0, 6.0, 50)
    q, qd, _, _ = traj.sample(t)
    out = viz.plot_joint_curves(tmp_path / "c.svg", JointCurves(t, q, qd, knot_times=traj.knot_times), limits={"velocity": 0.9})
    text = out.read_text()
    assert "position" in text and "velocity" in text and "acceleration" not in text
    # ±limit lines: two horizontal dashed lines at ±0.9 in the velocity panel
    assert text.count("stroke-dasharray") >= 2
    ET.parse(out)  # well-formed XML


def test_bad_suffix_writes_nothing(traj, tmp_path):
    with pytest.raises(InvalidInput, match=".png or .svg"):
        viz.plot_trajectory(tmp_path / "j.pdf", traj)
    assert os.listdir(tmp_path) == []


def test_joint_curves_are_one_checked_object(tmp_path):
    """plot_joint_curves takes one JointCurves; its series come back as (N, n) float arrays."""
    c = JointCurves([0.0, 1.0, 2.0], None, [1, 2, 3], knot_times=[[1.0]])
    assert [k for k, _ in c.series] == [1] and c.qd.shape == (3, 1) and c.knot_times.tolist() == [1.0]
    with pytest.raises(InvalidInput, match="give at least one of q, qd, qdd, qddd"):
        JointCurves([0.0, 1.0], None)
    with pytest.raises(InvalidInput, match="curves must be a viz.joint_curves.JointCurves, got list"):
        viz.plot_joint_curves(tmp_path / "c.png", [0.0, 1.0])
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda p: viz.plot_joint_curves(p, JointCurves([0.0, 1.0, 0.5], [1.0, 2.0, 3.0])), "strictly increasing"),
        (lambda p: viz.plot_joint_curves(p, JointCurves([0.0, 1.0, 2.0], [1.0, np.nan, 3.0])), "NaN"),
        (lambda p: viz.plot_joint_curves(p, JointCurves("abc", [1.0, 2.0, 3.0])), "t must be numbers"),
        (lambda p: viz.plot_joint_curves(p, JointCurves([0.0, 1.0, 2.0], [1, 2, 3], [1, 2, 3]), limits={"velocity": -1.0}), "positive"),
        (lambda p: viz.plot_joint_curves(p, JointCurves([0.0, 1.0, 2.0], [1, 2, 3], [1, 2, 3]), limits={"velocity": [1.0, 2.0]}), "one per joint"),
    ],
)
def test_bad_plot_data_raises_invalid_input_and_writes_nothing(call, match, tmp_path):
    with pytest.raises(InvalidInput, match=match):
        call(tmp_path / "bad.png")
    assert os.listdir(tmp_path) == []


def test_trajectory_sample_count_is_checked_not_clamped(traj, tmp_path):
    with pytest.raises(InvalidInput, match="samples must be an integer >= 2"):
        viz.plot_trajectory(tmp_path / "j.png", traj, samples=0)


def _panel_labels(fig) -> list[str]:
    return [ax.get_ylabel() for ax in fig.axes]


def test_joint_axes_say_the_unit_of_the_joints_drawn():
    from pinarms import robots
    from pinarms.viz.plots import _joint_curves_figure

    def figure(robot, q, **kw):
        t = np.linspace(0.0, 1.0, 20)
        qd = np.gradient(q, t, axis=0)
        return _joint_curves_figure(JointCurves(t, q, qd, knot_times=[0.0, 1.0]), limits={"velocity": 2.0}, robot=robot,
                                    joint_names=None, joint_units=None, title="", **kw)

    aubo, scara, gantry = robots.load("aubo_i3"), robots.load("scara_mushroom"), robots.load("gantry_flower")
    q6 = np.linspace(0.0, 1.0, 20)[:, None] * np.ones(6)
    assert _panel_labels(figure(aubo, q6, degrees=False)) == ["position\n[rad]", "velocity\n[rad/s]"]
    assert _panel_labels(figure(aubo, q6, degrees=True)) == ["position\n[°]", "velocity\n[°/s]"]
    assert _panel_labels(figure(gantry, q6[:, :3], degrees=True)) == ["position\n[m]", "velocity\n[m/s]"]
    fig = figure(scara, q6[:, :4], degrees=True)
    assert _panel_labels(fig) == ["position\n[° | m]", "velocity\n[°/s | m/s]"]
    legend = fig.legends[0]
    assert [t.get_text() for t in legend.get_texts()] == ["j1 [°]", "j2 [°]", "j3 [m]", "j4 [°]", "via points"]
    # prismatic values are not converted to degrees; revolute ones are
    lines = fig.axes[0].get_lines()
    assert lines[4].get_ydata().max() == pytest.approx(1.0) and lines[0].get_ydata().max() == pytest.approx(180 / np.pi)
    # the legend stands outside every panel; the limit lines are labelled with their values
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    box = legend.get_window_extent(renderer)
    assert all(not box.overlaps(ax.get_window_extent(renderer)) for ax in fig.axes)
    notes = [t.get_text() for t in fig.axes[1].texts]
    assert notes == ["j1, j2, j4 limit ±114.6 °/s", "j3 limit ±2 m/s"]  # one label per shared limit
    notes = [t.get_text() for t in figure(aubo, q6, degrees=False).axes[1].texts]
    assert notes == ["limit ±2 rad/s"]  # one limit for all: one black pair of lines, one label
    with pytest.raises(InvalidInput, match="robot 'aubo_i3' has 6"):
        figure(aubo, q6[:, :4], degrees=False)
    with pytest.raises(InvalidInput, match="joint_units"):
        _joint_curves_figure(JointCurves(np.linspace(0, 1, 5), np.zeros((5, 2))), limits=None,
                             robot=None, joint_names=None, joint_units=["rad", "deg"], degrees=False, title="")


def test_docs_joint_curves_picture(tmp_path):
    """docs/viz_joint_curves.png: seed 000's joint 1 at the paper's optimised times (``make docs-pictures``)."""
    from pathlib import Path

    from pinarms import robots

    scara = robots.load("scara_mushroom")
    traj = planning.piecewise_polynomial(SEED000.paper_knot_times_s, SEED000.path_rad[:, None], degrees=(3, 5, 3))
    target = tmp_path / "viz_joint_curves.png"
    if os.environ.get("PINARMS_DOCS_PICTURES") == "1":
        target = Path(__file__).resolve().parents[2] / "docs" / "viz_joint_curves.png"
    out = viz.plot_trajectory(target, traj, limits=planning.JointLimits(velocity=np.deg2rad(55.0)), degrees=True,
                              joint_names=[f"{scara.joint_names[0]} (seed 000 joint 1)"], joint_units=["rad"],
                              title="seed 000: 3-5-3 at the paper's optimised times 1.086, 1.243, 1.278 s")
    w, h = Image.open(out).size
    assert w > 800 and h > 900


def test_tool_speed_plot_of_a_straight_lift_and_its_joint_curves(tmp_path):
    from pathlib import Path

    from pinarms import optim, robots
    from pinarms.robots.reach.layout import default_orientation

    arm = robots.load("aubo_i3")
    poses = np.stack([np.eye(4), np.eye(4)])
    poses[:, :3, :3] = default_orientation(arm)
    poses[0, :3, 3], poses[1, :3, 3] = [0.35, 0.20, 0.0], [0.35, 0.20, 0.30]
    path = planning.cartesian_path(arm, poses)
    v, a = arm.velocity_limit, 2.0 * arm.velocity_limit
    timing = optim.time_optimal(path, [planning.JointVelocityConstraint(v), planning.JointAccelerationConstraint(a),
                                       planning.ToolSpeedConstraint(0.5)])
    speed_png, joints_png = tmp_path / "cartesian_lift_tool_speed.png", tmp_path / "cartesian_lift_joints.png"
    if os.environ.get("PINARMS_DOCS_PICTURES") == "1":
        docs = Path(__file__).resolve().parents[2] / "docs"
        speed_png, joints_png = docs / speed_png.name, docs / joints_png.name
    t, lin, ang = planning.tcp_speed(arm, timing.trajectory, 1000.0)
    assert ang.max() < 1e-9  # a pure translation
    out = viz.plot_tool_speed(speed_png, t, lin, limit=0.5,
                              title="AUBO-i3: straight 0.3 m lift, time-optimal, tcp speed <= 0.5 m/s")
    assert Image.open(out).size[0] > 700
    out = viz.plot_trajectory(joints_png, timing.trajectory, limits=planning.JointLimits(v, a), robot=arm,
                              title=f"AUBO-i3: straight 0.3 m lift in {timing.duration:.3f} s (TOPP-RA, 2 v/s)")
    assert Image.open(out).size[1] > 900  # four panels; the dense timing's knots are not drawn
    with pytest.raises(InvalidInput, match="same length"):
        viz.plot_tool_speed(tmp_path / "bad.png", t, lin[:-1])


def test_torque_curves_against_limits(tmp_path):
    from pinarms import robots
    from pinarms.viz.plots import plot_torques

    arm = robots.load("aubo_i3").with_payload(3.0)
    move = planning.multi_quintic([0.0, 0.6], np.array([[0.3, -0.4, 1.2, 0.2, 1.57, 0.0], [-0.9, 0.4, 1.8, 0.5, 1.2, 0.5]]))
    t = np.linspace(0.0, 0.6, 200)
    tau = move.torques(arm, t)
    out = plot_torques(tmp_path / "tau.svg", t, tau, arm.effort_limit, joint_names=arm.joint_names,
                       series={"slower": (t * 1.2, move.scaled(1.2).torques(arm, t * 1.2))}, title="torques")
    text = out.read_text()
    peak = np.abs(tau[:, 1]).max() / arm.effort_limit[1]
    assert "upperArm_joint" in text and f"peak {peak:.0%}" in text and "slower" in text and "±limit" in text
    with pytest.raises(InvalidInput, match="torques must have shape"):
        plot_torques(tmp_path / "bad.png", t, tau[:10])
    with pytest.raises(InvalidInput, match="limits must be positive"):
        plot_torques(tmp_path / "bad.png", t, tau, np.zeros(6))
