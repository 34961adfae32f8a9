"""Plots of a belt line: the schedule (one bar per pick, one cross per miss) and the sizing curves."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.container import BarContainer

from pinarms.optim.line import SimResult, summarise
from pinarms.optim.line.report import confidence_interval
from pinarms.errors import InvalidInput
from pinarms.viz.line_plots import plot_line_schedule, plot_line_sizing, schedule_figure, sizing_figure


def _run(seed: int, n: int = 40, arms: int = 2) -> SimResult:
    """A made-up run: items every 1.5 s, roughly a third missed, picks lasting 2 s."""
    rng = np.random.default_rng(seed)
    t0 = np.arange(n) * 1.5
    picked_by = np.where(rng.random(n) < 0.35, -1, rng.integers(0, arms, n))
    meet = np.where(picked_by >= 0, t0 + 3.0, np.nan)
    start, finish = meet - 1.0, meet + 1.0
    busy = np.array([2.0 * np.count_nonzero(picked_by == k) for k in range(arms)])
    return SimResult(tuple(f"arm {k + 1}" for k in range(arms)), picked_by, meet, np.full(n, 1.0), start, finish,
                     60.0, busy, n, t0)


class _Result:
    """What plot_line_* read of an optim.line LineResult: runs, figures, windows, belt speed."""

    def __init__(self, runs, speed=0.2, u_max=1.5):
        self.runs = tuple(runs)
        self.figures = summarise(self.runs)
        self.belt_speed = speed
        self.windows = (type("W", (), {"u_max": u_max})(),)


def _bars(ax) -> int:
    return sum(len(c.patches) for c in ax.containers if isinstance(c, BarContainer))


def test_schedule_has_one_bar_per_pick_and_one_cross_per_miss(tmp_path):
    run = _run(0)
    fig = schedule_figure(run, window=(0.0, 30.0))
    ax = fig.axes[0]
    in_window = (run.picked_by >= 0) & (run.start >= 0.0) & (run.start < 30.0)
    assert _bars(ax) == int(in_window.sum()) > 5
    crosses = [line for line in ax.lines if line.get_marker() == "x"]
    missed = (run.picked_by < 0) & (run.t0 < 30.0)  # a bare SimResult: misses at arrival
    assert len(crosses) == 1 and len(crosses[0].get_xdata()) == int(missed.sum()) > 3
    # each bar spans its pick; the item ids are written on the bars and by the crosses
    widths = sorted(round(p.get_width(), 9) for c in ax.containers for p in c.patches)
    assert widths == [2.0] * int(in_window.sum())
    texts = {t.get_text() for t in ax.texts}
    assert {str(i) for i in np.flatnonzero(in_window | missed)} <= texts
    assert [t.get_text() for t in ax.get_yticklabels()] == ["arm 1", "arm 2", "missed"]
    out = plot_line_schedule(tmp_path / "schedule.svg", run, window=(0.0, 30.0))
    assert "missed" in out.read_text()


def test_schedule_of_a_line_result_marks_misses_leaving_the_last_window():
    res = _Result([_run(1)], speed=0.2, u_max=1.5)
    run = res.runs[0]
    fig = schedule_figure(res, window=(10.0, 40.0))
    t_miss = run.t0[run.picked_by < 0] + 1.5 / 0.2
    cross = next(line for line in fig.axes[0].lines if line.get_marker() == "x")
    np.testing.assert_allclose(cross.get_xdata(), t_miss[(t_miss >= 10.0) & (t_miss < 40.0)])
    with pytest.raises(InvalidInput, match="run must index"):
        schedule_figure(res, run=2)
    with pytest.raises(InvalidInput, match="window"):
        schedule_figure(res, window=(5.0, 5.0))
    with pytest.raises(InvalidInput, match="LineResult or SimResult"):
        schedule_figure(object())


def test_sizing_curves_show_means_and_bands(tmp_path):
    flows = [30.0, 60.0, 90.0]
    results = [_Result([_run(10 * k + s) for s in range(4)]) for k in range(3)]
    arms = [_Result([_run(s, arms=n) for s in range(3)]) for n in (1, 2)]
    fig = sizing_figure({"flow [items/min]": (flows, results), "arms": ([2, 1], arms[::-1])}, target_miss=0.01)
    axes = fig.axes
    assert len(axes) == 4  # throughput and miss rate per swept quantity
    top, bottom = axes[0], axes[2]
    mean_tp = next(line for line in top.lines if line.get_marker() == "o")
    np.testing.assert_allclose(mean_tp.get_ydata(), [r.figures.picks_per_minute for r in results])
    ci = np.array([confidence_interval([x.picks_per_minute for x in r.runs])[1:] for r in results])
    band = top.collections[0].get_paths()[0].vertices  # the 95 % band over the seeds
    assert np.isclose(band[:, 1].min(), ci[:, 0].min()) and np.isclose(band[:, 1].max(), ci[:, 1].max())
    assert np.all(ci[:, 1] > ci[:, 0])
    miss = next(line for line in bottom.lines if line.get_marker() == "o")
    np.testing.assert_allclose(miss.get_ydata(), [100 * r.figures.miss_rate for r in results])
    assert len(bottom.collections) == 1 and any(line.get_linestyle() == "--" for line in bottom.lines)
    # x sorted: the arms column was given 2, 1
    np.testing.assert_allclose(next(line for line in axes[1].lines if line.get_marker() == "o").get_xdata(), [1, 2])
    assert plot_line_sizing(tmp_path / "sizing.png", {"flow": (flows, results)}).stat().st_size > 10_000
    with pytest.raises(InvalidInput, match="one each"):
        sizing_figure({"flow": ([1.0, 2.0], results)})
    with pytest.raises(InvalidInput, match="non-empty mapping"):
        sizing_figure({})
