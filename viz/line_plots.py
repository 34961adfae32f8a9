"""Plots of a belt line (matplotlib, Agg canvas): the schedule of picks and the sizing curves.

- :func:`plot_line_schedule` — who picked what when: one row per arm, one bar per pick (from
  the arm leaving its box to its return, the item's id on the bar when there is room), and a
  row of red crosses for the missed items at the time they leave the last window;
- :func:`plot_line_sizing` — throughput (picks/min) and miss rate against a swept quantity
  (flow, belt speed, number of arms, ...), one column per quantity, the mean over the seeds
  with its 95 % interval (Student's t over the seeds: :func:`pinarms.optim.line.report.confidence_interval`)
  as a band.

``schedule_figure`` and ``sizing_figure`` return the :class:`matplotlib.figure.Figure`
(for tests and further drawing); the ``plot_*`` functions write it (``.png`` or ``.svg``,
atomically) and return the path. Units: s, items/min, fractions shown in %.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Mapping, Sequence, TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from pinarms.errors import InvalidInput

from pinarms.viz.figure_files import save_figure

if TYPE_CHECKING:
    from distributed import Client

    from pinarms.optim.line.api import LineResult, LineSpec
    from pinarms.optim.line.simulate import SimResult

__all__ = ["schedule_figure", "plot_line_schedule", "sizing_figure", "plot_line_sizing", "line_curve",
           "MAX_LABELLED_PICKS"]

#: Picks shown with their item id on the bar (more: bars only).
MAX_LABELLED_PICKS = 120
_COLORS = ("#2a6fb5", "#e07b19", "#2ca02c", "#9467bd", "#8c564b", "#17becf")
MISS_COLOR = "#d62728"


def _run_of(result: Any, run: int) -> tuple[Any, float | None, float | None]:
    """(SimResult, belt speed, u where items are missed) of a LineResult's run or a bare SimResult."""
    runs = getattr(result, "runs", None)
    if runs is not None:
        if not (isinstance(run, int) and not isinstance(run, bool) and 0 <= run < len(runs)):
            raise InvalidInput(f"run must index result.runs (0..{len(runs) - 1}), got {run!r}")
        u_end = max((w.u_max for w in getattr(result, "windows", ())), default=None)
        return runs[run], float(result.belt_speed) or None, u_end
    if not hasattr(result, "picked_by") or not hasattr(result, "start"):
        raise InvalidInput(f"result must be an optim.line LineResult or SimResult, got {type(result).__name__}")
    return result, None, None


def schedule_figure(result: LineResult | SimResult, *, run: int = 0, window: tuple[float, float] = (0.0, 60.0),
                    title: str | None = None) -> Figure:
    """The schedule of ``result`` (a :class:`pinarms.optim.line.LineResult` or a :class:`SimResult`) over ``window`` [s].

    Bars: picks whose start lies in the window; crosses: missed items whose miss time (the
    item leaving the last window; its arrival for a bare SimResult) lies in it.
    """
    r, speed, u_end = _run_of(result, run)
    try:
        t_a, t_b = (float(x) for x in window)
    except (TypeError, ValueError):
        raise InvalidInput(f"window must be (start, end) in s, got {window!r}") from None
    if not (np.isfinite(t_a) and np.isfinite(t_b) and t_a < t_b):
        raise InvalidInput(f"window must be two finite times, start < end [s], got {window!r}")
    arms = list(r.arms)
    fig = Figure(figsize=(10, 1.4 + 0.55 * (len(arms) + 1)))
    ax = fig.subplots()
    shown = np.flatnonzero((r.picked_by >= 0) & (r.start >= t_a) & (r.start < t_b))
    label = shown.size <= MAX_LABELLED_PICKS
    for k, name in enumerate(arms):
        sel = shown[r.picked_by[shown] == k]
        ax.barh(np.full(sel.size, k), r.finish[sel] - r.start[sel], left=r.start[sel], height=0.6,
                color=_COLORS[k % len(_COLORS)], edgecolor="white", linewidth=0.5, label=None)
        if label:
            for i in sel:
                ax.text(0.5 * (r.start[i] + r.finish[i]), k, str(int(i)), ha="center", va="center", fontsize=6,
                        color="white")
    missed = np.flatnonzero(r.picked_by < 0)
    t_miss = r.t0[missed] + (u_end / speed if speed and u_end is not None else 0.0)
    keep = (t_miss >= t_a) & (t_miss < t_b)
    row = len(arms)
    ax.plot(t_miss[keep], np.full(int(keep.sum()), row), linestyle="none", marker="x", color=MISS_COLOR,
            markersize=7, label="missed")
    if label:
        for j, (i, t) in enumerate(zip(missed[keep], t_miss[keep])):  # staggered: close misses stay legible
            ax.text(t, row + 0.22 + 0.2 * (j % 2), str(int(i)), ha="center", va="top", fontsize=6, color=MISS_COLOR)
    ax.set_yticks(range(row + 1), arms + ["missed"])
    ax.set_ylim(-0.6, row + 0.6)
    ax.set_xlim(t_a, t_b)
    ax.invert_yaxis()
    when = "leaving the last window" if speed and u_end is not None else "arrival"
    ax.set_xlabel(f"time [s]  (bars: pick from leaving the box to returning, item id on it; x: missed item at {when})")
    ax.set_title(title or f"who picked what when: {shown.size} picks, {int(keep.sum())} missed in "
                          f"{t_a:g}-{t_b:g} s ({r.picks_per_minute:.1f} picks/min, miss {100 * r.miss_rate:.1f} % "
                          f"over the run)")
    ax.grid(True, axis="x", alpha=0.3)
    return fig


def plot_line_schedule(path: str | Path, result: LineResult | SimResult, **options: Any) -> Path:
    """Write :func:`schedule_figure` of ``result`` to ``path`` (.png or .svg); return the path."""
    return save_figure(schedule_figure(result, **options), path)


def _band(result: Any) -> tuple[float, float, float, float, float, float]:
    """(throughput mean, low, high, miss mean, low, high) of one LineResult over its seeds."""
    from pinarms.optim.line.report import confidence_interval

    runs = getattr(result, "runs", None)
    fig = getattr(result, "figures", result)
    if not hasattr(fig, "miss_rate_ci") or not hasattr(fig, "picks_per_minute"):
        raise InvalidInput(f"each curve point must be an optim.line LineResult or LineFigures, "
                           f"got {type(result).__name__}")
    if runs:
        tp = confidence_interval([x.picks_per_minute for x in runs])
    else:
        tp = (fig.picks_per_minute,) * 3
    return (*tp, float(fig.miss_rate), float(fig.miss_rate_ci[0]), float(fig.miss_rate_ci[1]))


def sizing_figure(curves: Mapping[str, tuple[Sequence[float], Sequence[LineResult]]], *, target_miss: float | None = 0.01,
                  title: str | None = None) -> Figure:
    """Throughput and miss rate against each swept quantity.

    Args:
        curves: ``{x label: (x values, results)}``: one column per entry; ``results`` are
            :class:`pinarms.optim.line.LineResult` (band from their runs) or :class:`LineFigures`.
        target_miss: the miss rate asked for, drawn as a dashed line (fraction; None: none).
    """
    if not isinstance(curves, Mapping) or not curves:
        raise InvalidInput("curves must be a non-empty mapping {x label: (x values, results)}")
    fig = Figure(figsize=(4.2 * len(curves), 6.0))
    axes = fig.subplots(2, len(curves), squeeze=False)
    for c, (label, pair) in enumerate(curves.items()):
        try:
            xs, results = pair
            x = np.asarray(xs, dtype=float)
        except (TypeError, ValueError):
            raise InvalidInput(f"curve {label!r} must be (x values, results)") from None
        if x.ndim != 1 or x.size == 0 or x.size != len(results) or not np.all(np.isfinite(x)):
            raise InvalidInput(f"curve {label!r}: {x.size} finite x values for {len(results)} results; give one each")
        b = np.array([_band(r) for r in results])
        order = np.argsort(x)
        x, b = x[order], b[order]
        top, bottom = axes[0, c], axes[1, c]
        top.fill_between(x, b[:, 1], b[:, 2], color=_COLORS[0], alpha=0.25, linewidth=0, label="95 % CI over seeds")
        top.plot(x, b[:, 0], marker="o", color=_COLORS[0], label="picks/min (mean)")
        bottom.fill_between(x, 100 * b[:, 4], 100 * b[:, 5], color=MISS_COLOR, alpha=0.2, linewidth=0,
                            label="95 % CI over seeds")
        bottom.plot(x, 100 * b[:, 3], marker="o", color=MISS_COLOR, label="miss rate (mean)")
        if target_miss is not None:
            bottom.axhline(100 * target_miss, color="black", linestyle="--", linewidth=1,
                           label=f"target {100 * target_miss:g} %")
        top.set_ylabel("throughput [picks/min]")
        bottom.set_ylabel("miss rate [%]")
        bottom.set_xlabel(label)
        for ax in (top, bottom):
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7)
    fig.suptitle(title or "line sizing: throughput and miss rate")
    return fig


def plot_line_sizing(path: str | Path, curves: Mapping[str, tuple[Sequence[float], Sequence[LineResult]]],
                     **options: Any) -> Path:
    """Write :func:`sizing_figure` of ``curves`` to ``path`` (.png or .svg); return the path."""
    return save_figure(sizing_figure(curves, **options), path)


def line_curve(make_spec: Callable[[float], LineSpec], values: Sequence[float], *, maps: Any = None,
               scheduler: str | Client | None = None) -> tuple[list[float], list[Any]]:
    """``(values, [run_line(make_spec(v)) ...])``: one curve of :func:`sizing_figure`.

    ``maps``: task maps given to every run (``None``: each run builds its own), or a callable
    ``spec -> maps`` (e.g. :func:`pinarms.studies.line.maps_for`).
    """
    from pinarms.optim.line import run_line

    out = []
    for v in values:
        spec = make_spec(v)
        out.append(run_line(spec, maps=maps(spec) if callable(maps) else maps, scheduler=scheduler))
    return [float(v) for v in values], out
