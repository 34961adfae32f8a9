"""Plots of a cell's motions (matplotlib Agg): clearance over time, and the arms' schedule in a shared zone.

Every function takes data and an output path ending in ``.png`` or ``.svg``, writes the figure
atomically (:func:`pinarms.viz.figure_files.save_figure`) and returns the path. Units: SI inside;
``mm=True`` labels distances in millimetres.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from pinarms.errors import InvalidInput

from pinarms.viz.figure_files import checked_numbers, save_figure

if TYPE_CHECKING:
    from pinarms.optim.line.schedule import LineSchedule
    from pinarms.robots.cell.motion_report import MotionCheck
    from pinarms.optim.motion.report import ClearanceProfile

__all__ = ["plot_clearance", "plot_schedule"]


def plot_clearance(path: str | Path, check: MotionCheck | ClearanceProfile, *, title: str = "clearance over time", mm: bool = True) -> Path:
    """Each moving arm's distance to everything else against time, one curve per group of pairs.

    ``check`` is a :class:`pinarms.robots.cell.MotionCheck` checked with ``curve=True`` (its
    ``curves``: each moving arm against the fixtures, each other arm and its own links, shapes
    that do not move left out, so an idle arm's constant distance never hides the moving
    one's) or a planned motion's :class:`pinarms.optim.motion.ClearanceProfile`. A check without
    curves draws its smallest distance over every pair (screened samples as dots: at least
    that far). Samples in contact are marked red, the required clearance is a dashed line,
    the closest point is annotated with its pair.
    """
    t = checked_numbers(getattr(check, "times", None), "check.times")
    curves = {str(k): checked_numbers(v, f"check.curves[{k!r}]") for k, v in (getattr(check, "curves", None) or {}).items()}
    if not curves:
        curves = {"smallest distance (every pair)": checked_numbers(getattr(check, "clearance", None), "check.clearance")}
    for name, d in curves.items():
        if t.ndim != 1 or t.shape != d.shape or t.size == 0:
            raise InvalidInput(f"check.times and the curve {name!r} must be equal 1-D arrays, got {t.shape} and {d.shape}")
    k = 1000.0 if mm else 1.0
    unit = "mm" if mm else "m"
    fig = Figure(figsize=(9, 3.6))
    ax = fig.subplots()
    colors = ["#2a6fb5", "#e07b19", "#2ca02c", "#9467bd", "#8c564b", "#17becf"]
    exact = np.asarray(getattr(check, "exact", np.ones(t.size, bool)), dtype=bool)
    if getattr(check, "curves", None):
        exact = np.ones(t.size, dtype=bool)  # every curve is exact at every sample
    lowest = (np.inf, "", 0)
    for n, (name, d) in enumerate(curves.items()):
        ax.plot(t[exact], d[exact] * k, lw=1.0, color=colors[n % len(colors)], label=name)
        finite = np.where(exact, d, np.inf)
        i = int(np.argmin(finite))
        if finite[i] < lowest[0]:
            lowest = (float(finite[i]), name, i)
        touch = d <= 0.0
        if touch.any():
            ax.plot(t[touch], d[touch] * k, ".", ms=4, color="#d62728", label="contact" if n == 0 else None)
    if (~exact).any():
        d = next(iter(curves.values()))
        ax.plot(t[~exact], d[~exact] * k, ".", ms=2, color="#9aa7b5", label="screened (at least)")
    required = float(getattr(check, "required", 0.0))
    if required > 0.0:
        ax.axhline(required * k, ls="--", color="#555555", lw=0.8, label=f"required {required * k:g} {unit}")
    ax.axhline(0.0, color="black", lw=0.6)
    _annotate_closest(ax, check, t, lowest, k, unit)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"distance [{unit}]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    return save_figure(fig, path)


def _annotate_closest(ax: Any, check: Any, t: np.ndarray, lowest: tuple, k: float, unit: str) -> None:
    """Name the pair at the closest point drawn: a curve's closest pair, or the check's."""
    value, name, i = lowest
    if not np.isfinite(value):
        return
    pair = (getattr(check, "curve_pairs", None) or {}).get(name)
    if pair is None and not getattr(check, "curves", None):
        pair = getattr(check, "min_clearance_pair", None)
        if pair is not None and math.isfinite(getattr(check, "min_clearance", math.nan)):
            value, i = float(check.min_clearance), int(np.argmin(np.abs(t - check.min_clearance_time)))
    if pair is None:
        return
    text = pair if isinstance(pair, str) else f"{pair.body_a} ↔ {pair.body_b}"
    ax.annotate(f"{value * k:.1f} {unit}: {text}", (t[i], value * k), textcoords="offset points", xytext=(6, 10),
                fontsize=8)


def plot_schedule(path: str | Path, schedule: LineSchedule, *, periods: int = 2, title: str | None = None) -> Path:
    """Each arm's busy intervals in the shared zone over ``periods`` line periods (a Gantt chart).

    ``schedule`` is an :class:`pinarms.optim.LineSchedule`; each arm's cycle start is marked.
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
