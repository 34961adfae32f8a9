"""The line's plots: schedule and curves written as images."""

import numpy as np

from pinarms.optim.line import Belt, LineCurve, TaskMap, poisson_items, simulate
from pinarms.optim.line.simulate import SimArm
from pinarms.viz.line_plots import plot_line_curve, plot_line_schedule


def test_schedule_and_curve_plots(tmp_path):
    belt = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=3.0)
    m = TaskMap("a", np.linspace(-0.3, 0.3, 7), np.array([-0.15, 0.15]), np.full((7, 2), 0.8), np.full((7, 2), 0.8),
                0.5, 0.1, 0.2, 0.1)
    r = simulate([SimArm("a", 1.0, (m,)), SimArm("b", 2.0, (m,))], poisson_items(belt, 1.0, 60.0, seed=0), 0.2,
                 duration=60.0)
    p = plot_line_schedule(tmp_path / "s.png", r)
    assert p.stat().st_size > 5_000 and p.read_bytes()[:4] == b"\x89PNG"
    c = LineCurve("arms", np.array([1.0, 2.0]), np.array([20.0, 40.0]), np.array([0.5, 0.1]), np.array([0.4, 0.05]),
                  np.array([0.6, 0.15]), np.array([60.0, 60.0]))
    q = plot_line_curve(tmp_path / "c.svg", c)
    assert b"<svg" in q.read_bytes()[:400]


def test_line_session_replays_the_picks(tmp_path):
    from pinarms import viz
    from pinarms.optim.line import run_line
    from pinarms.studies.line import maps_for, scara_line
    from pinarms.viz.line_session import line_session

    spec = scara_line(2, 30.0, seeds=(0,), duration=60.0)
    res = run_line(spec, maps=maps_for(spec, build=False))
    run = res.runs[0]
    s = line_session(spec, run, t_max=10.0)
    assert set(s.robots) == {"scara_1", "scara_2"} and "belt" in s.objects
    picked = int(((run.picked_by == 0) & (run.start < 10.0)).sum())
    assert picked > 0 and s.point_sets["scara_1 grasps"].points.shape == (picked, 3)
    # the arm's replay passes through each grasp point: FK of the recorded joints at the grasp
    rec = s.trajectories["scara_1 picks"]
    tcp = spec.stations[0].robot.fk(rec.q)[:, :3, 3]
    gaps = np.linalg.norm(tcp[None, :, :] - s.point_sets["scara_1 grasps"].points[:, None, :], axis=2).min(axis=1)
    assert gaps.max() < 0.01  # within 10 mm at the 50 Hz samples (the item moves 4 mm per sample)
    back = viz.load_session(s.save(tmp_path / "line.pinarms"))
    assert back == s
