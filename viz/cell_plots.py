"""Plots of a cell's motions (matplotlib Agg): clearance over time, and the arms' schedule in a shared zone.

Every function takes data and an output path ending in ``.png`` or ``.svg``, writes the figure
atomically (:func:`viz.figure_files.save_figure`) and returns the path. Units: SI inside;
``mm=True`` labels distances in millimetres.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from pinarms.robots.errors import InvalidInput

from .figure_files import checked_numbers, save_figure

__all__ = ["plot_clearance", "plot_schedule"]


def plot_clearance(path: str | Path, check: Any, *, title: str = "clearance over time", mm: bool = True) -> Path:
    """Smallest distance over the checked pairs against time, from a cell's motion check.

    ``check`` is a :class:`robots.cell.MotionCheck` (best with ``curve=True``: exact at
    every sample). Samples in contact are marked red, the required clearance is a dashed
    line, the closest sample is annotated with its pair.
    """
    t = checked_numbers(getattr(check, "times", None), "check.times")
    d = checked_numbers(getattr(check, "clearance", None), "check.clearance")
    if t.ndim != 1 or t.shape != d.shape or t.size == 0:
        raise InvalidInput(f"check.times and check.clearance must be equal 1-D arrays, got {t.shape} and {d.shape}")
    k = 1000.0 if mm else 1.0
    unit = "mm" if mm else "m"
    fig = Figure(figsize=(9, 3.6))
    ax = fig.subplots()
    exact = np.asarray(getattr(check, "exact", np.ones(t.size, bool)), dtype=bool)
    ax.plot(t[exact], d[exact] * k, lw=1.0, color="#2a6fb5", label="smallest distance")
    if (~exact).any():
        ax.plot(t[~exact], d[~exact] * k, ".", ms=2, color="#9aa7b5", label="screened (at least)")
    touch = d <= 0.0
    if touch.any():
        ax.plot(t[touch], d[touch] * k, ".", ms=4, color="#d62728", label="contact")
    required = float(getattr(check, "required", 0.0))
    if required > 0.0:
        ax.axhline(required * k, ls="--", color="#555555", lw=0.8, label=f"required {required * k:g} {unit}")
    ax.axhline(0.0, color="black", lw=0.6)
    i = int(np.argmin(np.where(exact, d, np.inf))) if exact.any() else int(np.argmin(d))
    pair = getattr(check, "min_clearance_pair", None)
    if pair is not None:
        ax.annotate(f"{d[i] * k:.1f} {unit}: {pair}", (t[i], d[i] * k), textcoords="offset points", xytext=(6, 10),
                    fontsize=8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"distance [{unit}]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    return save_figure(fig, path)


def plot_schedule(path: str | Path, schedule: Any, *, periods: int = 2, title: str | None = None) -> Path:
    """Each arm's busy intervals in the shared zone over ``periods`` line periods (a Gantt chart).

    ``schedule`` is an :class:`optim.LineSchedule`; each arm's cycle start is marked.
    """
    arms = list(getattr(schedule, "arms", ()))
    period = float(getattr(schedule, "period", float("nan")))
    if not arms or not math.isfinite(period) or period <= 0.0:
        raise InvalidInput("schedule must be an optim.LineSchedule with arms and a positive period")
    if isinstance(periods, bool) or not isinstance(periods, int) or periods < 1:
        raise InvalidInput(f"periods must be a positive integer, got {periods!r}")
    colors = ["#2a6fb5", "#e07b19", "#2ca02c", "#9467bd"]
    fig = Figure(figsize=(9, 1.2 + 0.6 * len(arms)))
    ax = fig.subplots()
    for row, name in enumerate(arms):
        bars = [(a + p * period, b - a) for p in range(periods) for a, b in schedule.busy.get(name, [])]
        ax.broken_barh(bars, (row - 0.35, 0.7), color=colors[row % len(colors)], alpha=0.85)
        for p in range(periods):
            start = schedule.offsets[name] + p * period
            ax.plot([start, start], [row - 0.45, row + 0.45], color="black", lw=1.2)
    ax.set_yticks(range(len(arms)), [f"{a} ({schedule.cycle_times[a]:.2f} s)" for a in arms])
    ax.set_xlim(0.0, periods * period)
    ax.set_xlabel("time [s]  (bars: tcp in the shared zone; ticks: cycle starts)")
    ax.set_title(title or f"{schedule.cell}: {schedule.picks_per_minute:.1f} picks/min, period {period:.2f} s")
    ax.grid(True, axis="x", alpha=0.3)
    return save_figure(fig, path)
