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
