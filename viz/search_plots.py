"""Plots of searches (matplotlib Agg): a GA's convergence, and a layout search's picks per minute by base position.

Every function takes data and an output path ending in ``.png`` or ``.svg``, writes the figure
atomically (:func:`pinarms.viz.figure_files.save_figure`) and returns the path.
"""

from __future__ import annotations

from pathlib import Path
from typing import Mapping, TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput

from pinarms.viz.figure_files import checked_numbers, save_figure

if TYPE_CHECKING:
    from pinarms.optim.ga.engine import GAHistory, GAResult
    from pinarms.viz.session_records import HistoryRecord
    from pinarms.optim.layout.result import LayoutSearch

__all__ = ["plot_ga_convergence", "plot_layout_search"]


def plot_ga_convergence(path: str | Path, history: GAHistory | GAResult | HistoryRecord | Mapping[str, ArrayLike], *,
                        title: str = "GA convergence", ylabel: str = "objective") -> Path:
    """Best-so-far and mean objective per generation, and the feasible share when recorded.

    ``history``: a GA history (``best``, ``feasible_mean`` or ``mean``, optional
    ``feasible_share``), a result with ``.history``, a :class:`pinarms.viz.HistoryRecord` or a
    mapping of columns. Generations recorded as ``inf`` (no finite objective) are left as
    gaps in the curves.

    The mean drawn is that of the *feasible* individuals (``feasible_mean``) when the
    history has it: never below the best-so-far. The whole population's ``mean`` counts
    infeasible individuals with their raw objective (faster than the limits allow), so it
    can dip below the best when few are feasible; drawn only for histories without
    ``feasible_mean``, and then labelled so.
    """
    if hasattr(history, "columns"):
        history = history.columns
    elif hasattr(history, "history") and not isinstance(history, Mapping):
        history = history.history
    get = (lambda k: history.get(k)) if isinstance(history, Mapping) else (lambda k: getattr(history, k, None))
    best = get("best")
    if best is None:
        raise InvalidInput("history needs a 'best' column (objective of the best individual per generation)")
    best = checked_numbers(best, "best", allow_inf=True)
    if best.ndim != 1 or best.size == 0:
        raise InvalidInput(f"best must hold one objective per generation (G,) with G >= 1, got shape {best.shape}")
    gens = np.arange(best.size)

    def column(key: str) -> np.ndarray | None:
        values = get(key)
        if values is None:
            return None
        arr = checked_numbers(values, key, allow_inf=True)
        if arr.shape != best.shape:
            raise InvalidInput(f"{key} must have one value per generation {best.shape}, got shape {arr.shape}")
        return arr

    fig = Figure(figsize=(8.8, 3.8), layout="constrained")
    ax = fig.subplots()
    lines = ax.plot(gens, best, lw=1.8, label="best so far")
    feasible_mean, mean = column("feasible_mean"), column("mean")
    if feasible_mean is not None:
        gap = "\n(gaps: no feasible individual)" if np.any(~np.isfinite(feasible_mean)) else ""
        lines += ax.plot(gens, feasible_mean, lw=1.2, ls="--", label=f"mean of the feasible individuals{gap}")
    elif mean is not None:
        lines += ax.plot(gens, mean, lw=1.2, ls="--", label="population mean (infeasible ones too:\ncan lie below the best)")
    feasible = column("feasible_share")
    if feasible is not None:
        ax2 = ax.twinx()
        lines += ax2.plot(gens, feasible, color="0.55", lw=0.9, label="feasible share (right axis)")
        ax2.set_ylim(0, 1.05)
        ax2.set_ylabel("feasible share")
    ax.set_xlabel("generation")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    fig.legend(lines, [ln.get_label() for ln in lines], loc="outside right upper", fontsize=8)
    return save_figure(fig, path)


def plot_layout_search(path: str | Path, result: LayoutSearch, *, title: str | None = None, colormap: str = "viridis",
                       mm: bool = True) -> Path:
    """Picks per minute over the (x, y) placements of a layout search (:class:`pinarms.optim.LayoutSearch`).

    One square per (x, y) of the candidates, coloured by the best picks/min over their z and
    yaw; placements where no candidate could run the cycle are grey crosses. The picks
    (triangles), places (squares), the best grid placement (black frame) and the refined one
    (diamond, when the refinement gained) are marked. Line frame; ``mm`` labels millimetres.
    """
    if not all(hasattr(result, a) for a in ("candidates", "picks_per_minute", "picks", "places")):
        raise InvalidInput(f"result must be an optim.LayoutSearch, got {type(result).__name__}")
    if colormap not in matplotlib.colormaps:
        raise InvalidInput(f"unknown matplotlib colormap {colormap!r}")
    cand = checked_numbers(result.candidates, "candidates")
    ppm = checked_numbers(result.picks_per_minute, "picks per minute")
    k = 1000.0 if mm else 1.0
    unit = "mm" if mm else "m"
    xy, inverse = np.unique(np.round(cand[:, :2], 9), axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    best = np.zeros(xy.shape[0])
    np.maximum.at(best, inverse, ppm)
    ok = best > 0
    fig = Figure(figsize=(7.5, 6.0))
    ax = fig.subplots()
    size = 36.0 if xy.shape[0] > 400 else 90.0
    sc = ax.scatter(xy[ok, 0] * k, xy[ok, 1] * k, c=best[ok], cmap=colormap, marker="s", s=size, linewidths=0)
    if (~ok).any():
        ax.scatter(xy[~ok, 0] * k, xy[~ok, 1] * k, marker="x", s=size * 0.4, color="0.6", linewidths=1.0,
                   label="cycle not possible")
    picks, places = checked_numbers(result.picks, "picks"), checked_numbers(result.places, "places")
    ax.scatter(picks[:, 0] * k, picks[:, 1] * k, marker="^", s=80, color="tab:red", edgecolors="k", label="pick")
    ax.scatter(places[:, 0] * k, places[:, 1] * k, marker="s", s=80, color="tab:orange", edgecolors="k",
               label="place")
    index = getattr(result, "best_index", -1)
    if index >= 0:
        ax.scatter([cand[index, 0] * k], [cand[index, 1] * k], marker="s", s=size * 2.2, facecolors="none",
                   edgecolors="k", linewidths=2.0, label=f"best grid placement ({ppm[index]:.1f}/min)")
    refined = getattr(result, "refinement", None)
    if refined is not None and refined.gain > 0:
        j = int(np.argmax(refined.picks_per_minute))
        ax.scatter([refined.placements[j, 0] * k], [refined.placements[j, 1] * k], marker="D", s=90,
                   color="magenta", edgecolors="k", label=f"refined ({refined.picks_per_minute[j]:.1f}/min)")
    if ok.any():
        fig.colorbar(sc, ax=ax, label="picks per minute (best over z, yaw)", shrink=0.85)
    ax.set_xlabel(f"base x [{unit}]")
    ax.set_ylabel(f"base y [{unit}]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title(title or f"layout search of {getattr(result, 'robot', 'the arm')}: picks per minute by base position")
    return save_figure(fig, path)
