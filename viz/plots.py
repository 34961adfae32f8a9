"""Plots (matplotlib, Agg backend): joint curves, tcp speed, GA convergence, workspace projections.

Figures are drawn on matplotlib's Agg canvas directly (no pyplot state, the user's
backend is left alone). Every function takes data and an output path ending in ``.png`` or ``.svg``, writes the
figure atomically and returns the path. Units: the data's SI units (rad, m, s); pass
``degrees=True`` to label revolute joints in degrees (conversion happens here, at the edge).
"""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any, Mapping, Sequence

import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from pinarms.robots.errors import InvalidInput

from ._atomic import atomic_write

__all__ = ["plot_joint_curves", "plot_trajectory", "plot_tool_speed", "plot_ga_convergence", "plot_workspace"]

#: A trajectory with more knots than this (e.g. a time-optimal path timing, one piece per grid
#: interval) is drawn without knot markers and lines.
MAX_DRAWN_KNOTS = 40

_FORMATS = {".png": "png", ".svg": "svg"}
_ORDERS = ("position", "velocity", "acceleration", "jerk")
_UNITS = ("", "/s", "/s²", "/s³")


def _save(fig: Figure, path: str | Path) -> Path:
    p = Path(path)
    fmt = _FORMATS.get(p.suffix.lower())
    if fmt is None:
        raise InvalidInput(f"plot path {str(p)!r} must end in .png or .svg")
    buf = io.BytesIO()
    FigureCanvasAgg(fig)
    fig.savefig(buf, format=fmt, dpi=120, bbox_inches="tight", metadata={"Date": None} if fmt == "svg" else None)
    data = buf.getvalue()
    return atomic_write(p, lambda f: f.write(data))


def _numbers(values: Any, what: str, allow_inf: bool = False) -> np.ndarray:
    """``values`` as a finite float array (±inf kept if ``allow_inf``), or InvalidInput naming ``what``."""
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be numbers, got {type(values).__name__}") from exc
    if np.any(np.isnan(arr)) if allow_inf else not np.all(np.isfinite(arr)):
        raise InvalidInput(f"{what} holds NaN{'' if allow_inf else ' or infinite'} values")
    return arr


def _limit_array(limits: Any, kind: str, n: int) -> np.ndarray | None:
    """Per-joint limit of ``kind`` from a JointLimits-like object or a mapping, or None."""
    if limits is None:
        return None
    value = limits.get(kind) if isinstance(limits, Mapping) else getattr(limits, kind, None)
    if value is None:
        return None
    try:
        arr = np.broadcast_to(np.asarray(value, dtype=float), (n,))
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{kind} limit must be one number or one per joint ({n}), got {value!r}") from exc
    if np.any(np.isnan(arr)) or np.any(arr <= 0):
        raise InvalidInput(f"{kind} limit must be positive (inf: no limit), got {arr.tolist()}")
    return arr


def plot_joint_curves(
    path: str | Path,
    t: Any,
    q: Any,
    qd: Any = None,
    qdd: Any = None,
    qddd: Any = None,
    *,
    knot_times: Any = None,
    limits: Any = None,
    joint_names: Sequence[str] | None = None,
    degrees: bool = False,
    title: str = "",
) -> Path:
    """Joint position/velocity/acceleration/jerk versus time, one panel per derivative order.

    Args:
        path: output file (.png or .svg).
        t: instants (N,), s. q, qd, qdd, qddd: (N, n) (or (N,)) in rad, rad/s, ... (or m, m/s, ...);
            derivatives left ``None`` are not drawn.
        knot_times: knot (via point) instants (s): vertical dotted lines, markers on the curves.
        limits: ``planning.JointLimits`` or a mapping with ``velocity``, ``acceleration``,
            ``jerk`` (per joint or scalar, SI): drawn as dashed ±limit lines.
        joint_names: legend labels (default ``joint 1..n``).
        degrees: show values ×180/π (revolute joints).
    """
    tt = _numbers(t, "t")
    if tt.ndim != 1 or tt.size < 2:
        raise InvalidInput(f"t must be (N,) instants in s with N >= 2, got shape {tt.shape}")
    if np.any(np.diff(tt) <= 0):
        raise InvalidInput("t must be strictly increasing instants in s")
    series = []
    for order, values in enumerate((q, qd, qdd, qddd)):
        if values is None:
            continue
        arr = _numbers(values, _ORDERS[order])
        arr = arr[:, None] if arr.ndim == 1 else arr
        if arr.ndim != 2 or arr.shape[0] != tt.size:
            raise InvalidInput(f"{_ORDERS[order]} must have shape ({tt.size}, n_joints), got {np.shape(values)}")
        series.append((order, arr))
    if not series:
        raise InvalidInput("give at least one of q, qd, qdd, qddd")
    n = series[0][1].shape[1]
    if any(a.shape[1] != n for _, a in series):
        raise InvalidInput("q, qd, qdd and qddd must have the same number of joints")
    names = list(joint_names) if joint_names is not None else [f"joint {j + 1}" for j in range(n)]
    if len(names) != n:
        raise InvalidInput(f"joint_names has {len(names)} names for {n} joints")
    scale = 180.0 / math.pi if degrees else 1.0
    unit = "°" if degrees else "rad or m"
    knots = None if knot_times is None else _numbers(knot_times, "knot_times").ravel()

    fig = Figure(figsize=(7.5, 2.3 * len(series) + 0.4))
    axes = fig.subplots(len(series), 1, sharex=True, squeeze=False)
    colors = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, (order, arr) in zip(axes[:, 0], series):
        for j in range(n):
            c = colors[j % len(colors)]
            ax.plot(tt, arr[:, j] * scale, color=c, lw=1.4, label=names[j])
            if knots is not None:
                ax.plot(knots, np.interp(knots, tt, arr[:, j]) * scale, "o", color=c, ms=4)
        lim = _limit_array(limits, _ORDERS[order], n) if order > 0 else None
        if lim is not None:
            shared = bool(np.all(lim == lim[0]))  # one limit for every joint: one black pair of lines
            for j in range(1 if shared else n):
                if np.isfinite(lim[j]):
                    c = "k" if shared else colors[j % len(colors)]
                    for sign in (1, -1):
                        ax.axhline(sign * lim[j] * scale, color=c, ls="--", lw=0.9, alpha=0.8)
        if knots is not None:
            for tk in knots:
                ax.axvline(tk, color="0.6", ls=":", lw=0.8)
        ax.set_ylabel(f"{_ORDERS[order]}\n[{unit}{_UNITS[order]}]")
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].legend(loc="best", fontsize=8, ncol=min(n, 4))
    if title:
        axes[0, 0].set_title(title)
    return _save(fig, path)


def plot_trajectory(path: str | Path, trajectory: Any, *, limits: Any = None, samples: int = 400, **options: Any) -> Path:
    """:func:`plot_joint_curves` of a ``planning.Trajectory`` (sampled at ``samples`` instants plus its knots)."""
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise InvalidInput(f"samples must be an integer >= 2 (instants drawn), got {samples!r}")
    knots = np.asarray(trajectory.knot_times, dtype=float)
    t = np.union1d(np.linspace(knots[0], knots[-1], int(samples)), knots)
    q, qd, qdd, qddd = trajectory.sample(t)
    drawn = knots if knots.size <= MAX_DRAWN_KNOTS else None
    return plot_joint_curves(path, t, q, qd, qdd, qddd, knot_times=drawn, limits=limits, **options)


def plot_tool_speed(path: str | Path, t: Any, speed: Any, *, limit: float | None = None, angular: Any = None,
                    title: str = "tcp speed") -> Path:
    """The tcp's Cartesian speed versus time (e.g. from :func:`planning.tcp_speed`).

    Args:
        t: instants (N,) [s]; speed: linear speed (N,) [m/s]; angular: optional (N,) [rad/s]
            (second axis); limit: a tool-speed limit [m/s], drawn dashed.
    """
    tt = _numbers(t, "t")
    v = _numbers(speed, "speed")
    if tt.ndim != 1 or tt.size < 2 or v.shape != tt.shape:
        raise InvalidInput(f"t and speed must be (N,) arrays of the same length, N >= 2; got {tt.shape} and {v.shape}")
    fig = Figure(figsize=(7.5, 3.0))
    ax = fig.subplots()
    ax.plot(tt, v, lw=1.5, label="linear [m/s]")
    if limit is not None:
        ax.axhline(float(limit), color="k", ls="--", lw=0.9, label=f"limit {float(limit):g} m/s")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("tcp speed [m/s]")
    ax.grid(True, alpha=0.3)
    if angular is not None:
        w = _numbers(angular, "angular")
        if w.shape != tt.shape:
            raise InvalidInput(f"angular must have the shape of t {tt.shape}, got {w.shape}")
        ax2 = ax.twinx()
        ax2.plot(tt, w, lw=1.0, color="tab:orange", label="angular [rad/s]")
        ax2.set_ylabel("angular [rad/s]")
    ax.legend(loc="best", fontsize=8)
    ax.set_title(title)
    return _save(fig, path)


def plot_ga_convergence(path: str | Path, history: Any, *, title: str = "GA convergence", ylabel: str = "objective") -> Path:
    """Best and mean objective per generation (and the feasible share when recorded).

    ``history``: a GA history (``best``, ``mean``, optional ``feasible_share``), a result
    with ``.history``, a :class:`viz.HistoryRecord` or a mapping of columns. Generations
    recorded as ``inf`` (no finite objective) are left as gaps in the curves.
    """
    if hasattr(history, "columns"):
        history = history.columns
    elif hasattr(history, "history") and not isinstance(history, Mapping):
        history = history.history
    get = (lambda k: history.get(k)) if isinstance(history, Mapping) else (lambda k: getattr(history, k, None))
    best = get("best")
    if best is None:
        raise InvalidInput("history needs a 'best' column (objective of the best individual per generation)")
    best = _numbers(best, "best", allow_inf=True)
    if best.ndim != 1 or best.size == 0:
        raise InvalidInput(f"best must hold one objective per generation (G,) with G >= 1, got shape {best.shape}")
    gens = np.arange(best.size)

    def column(key: str) -> np.ndarray | None:
        values = get(key)
        if values is None:
            return None
        arr = _numbers(values, key, allow_inf=True)
        if arr.shape != best.shape:
            raise InvalidInput(f"{key} must have one value per generation {best.shape}, got shape {arr.shape}")
        return arr

    fig = Figure(figsize=(7, 3.6))
    ax = fig.subplots()
    ax.plot(gens, best, lw=1.8, label="best")
    mean = column("mean")
    if mean is not None:
        ax.plot(gens, mean, lw=1.2, ls="--", label="population mean")
    feasible = column("feasible_share")
    if feasible is not None:
        ax2 = ax.twinx()
        ax2.plot(gens, feasible, color="0.55", lw=0.9, label="feasible share")
        ax2.set_ylim(0, 1.05)
        ax2.set_ylabel("feasible share")
        ax2.legend(loc="center right", fontsize=8)
    ax.set_xlabel("generation")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right", fontsize=8)
    return _save(fig, path)


def plot_workspace(path: str | Path, points: Any, manipulability: Any = None, *, title: str = "workspace",
                   colormap: str = "viridis", mm: bool = False) -> Path:
    """Top (x-y) and side (x-z) projections of a workspace cloud coloured by manipulability.

    ``points`` (n, 3) m (or a ``Workspace``/:class:`viz.WorkspaceRecord` with ``points`` and
    ``manipulability``); ``mm=True`` labels the axes in millimetres.
    """
    if hasattr(points, "points"):
        points, manipulability = points.points, points.manipulability
    pts = _numbers(points, "points")
    if pts.ndim != 2 or pts.shape[1] != 3 or pts.shape[0] == 0:
        raise InvalidInput(f"points must have shape (n, 3) with n >= 1, got {pts.shape}")
    if colormap not in matplotlib.colormaps:
        raise InvalidInput(f"unknown matplotlib colormap {colormap!r}")
    w = None if manipulability is None else _numbers(manipulability, "manipulability")
    if w is not None and w.shape != (pts.shape[0],):
        raise InvalidInput(f"manipulability must have shape ({pts.shape[0]},), got {w.shape}")
    k = 1000.0 if mm else 1.0
    unit = "mm" if mm else "m"
    fig = Figure(figsize=(10, 4.4))
    axes = fig.subplots(1, 2)
    order = np.argsort(w) if w is not None else slice(None)  # high manipulability drawn on top
    sc = None
    for ax, (i, j), view in zip(axes, ((0, 1), (0, 2)), ("top view", "side view")):
        sc = ax.scatter(pts[order, i] * k, pts[order, j] * k, c=None if w is None else w[order], cmap=colormap,
                        s=3, linewidths=0)
        ax.set_xlabel(f"{'xyz'[i]} [{unit}]")
        ax.set_ylabel(f"{'xyz'[j]} [{unit}]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(f"{title}: {view}")
        ax.grid(True, alpha=0.3)
    if w is not None and sc is not None:
        fig.colorbar(sc, ax=axes, label="manipulability", shrink=0.85)
    return _save(fig, path)
