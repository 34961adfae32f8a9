"""Plots of the line: who picked what when (the schedule), and throughput / miss-rate curves."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from .plots import _save

__all__ = ["plot_line_schedule", "plot_line_curve"]


def plot_line_schedule(path: str | Path, result: Any, *, t_max: float | None = 120.0,
                       title: str = "who picked what when") -> Path:
    """Each arm's picks as bars (start → back at its box) with the rendezvous marked; missed items
    as crosses at their arrival time, on a row of their own. ``result``: a
    :class:`optim.line.SimResult`; ``t_max`` [s]: the time shown (None: all)."""
    fig = Figure(figsize=(9.0, 0.6 * len(result.arms) + 1.8))
    ax = fig.add_subplot(1, 1, 1)
    end = result.duration if t_max is None else min(t_max, result.duration)
    for k, name in enumerate(result.arms):
        sel = np.flatnonzero((result.picked_by == k) & (result.start <= end))
        ax.broken_barh(list(zip(result.start[sel], result.finish[sel] - result.start[sel])), (k - 0.35, 0.7),
                       facecolors=f"C{k % 10}", alpha=0.6)
        ax.plot(result.meet[sel], np.full(sel.size, k), "k|", markersize=10)
    missed = np.flatnonzero((result.picked_by < 0) & (result.t0 <= end))
    ax.plot(result.t0[missed], np.full(missed.size, len(result.arms)), "rx", label=f"missed ({missed.size})")
    ax.set_yticks(range(len(result.arms) + 1), [*result.arms, "missed"])
    ax.set_xlim(0.0, end)
    ax.set_xlabel("time [s] (bars: a pick from leaving the box to back at rest; |: rendezvous; x: arrival of a missed item)")
    ax.set_title(title)
    return _save(fig, path)


def plot_line_curve(path: str | Path, curve: Any, *, target: float | None = 0.01, title: str | None = None) -> Path:
    """Picks per minute (left axis, with the arrivals) and the miss rate with its 95 % interval
    (right axis, %) against the curve's parameter (:class:`optim.line.LineCurve`)."""
    labels = {"rate": "flow [items/min]", "speed": "belt speed [m/s]", "arms": "number of arms"}
    fig = Figure(figsize=(7.5, 4.2))
    ax = fig.add_subplot(1, 1, 1)
    x = curve.values
    ax.plot(x, curve.picks_per_minute, "o-", color="C0", label="picks/min")
    ax.plot(x, curve.arrivals_per_minute, "--", color="C7", label="arrivals/min")
    ax.set_xlabel(labels.get(curve.parameter, curve.parameter))
    ax.set_ylabel("items per minute")
    ax2 = ax.twinx()
    ax2.fill_between(x, 100 * curve.miss_low, 100 * curve.miss_high, color="C3", alpha=0.2)
    ax2.plot(x, 100 * curve.miss_rate, "s-", color="C3", label="miss rate")
    if target is not None:
        ax2.axhline(100 * target, color="C3", lw=0.8, ls=":")
    ax2.set_ylabel("miss rate [%] (band: 95 % interval over seeds)")
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], loc="center left")
    ax.set_title(title or f"throughput and misses against {labels.get(curve.parameter, curve.parameter)}")
    return _save(fig, path)
