"""Plots of joint motions (matplotlib, Agg backend): joint curves, trajectories, tcp speed, joint torques.

Figures are drawn on matplotlib's Agg canvas directly (no pyplot state, the user's
backend is left alone). Every function takes data and an output path ending in ``.png`` or ``.svg``, writes the
figure atomically and returns the path. Units: the data's SI units (rad, m, s); pass
``degrees=True`` to label revolute joints in degrees (conversion happens here, at the edge).

The other plot families have their own modules, re-exported here: searches
(:mod:`pinarms.viz.search_plots`: GA convergence, layout search), cells (:mod:`pinarms.viz.cell_plots`:
clearance over time, multi-arm schedules), reach (:mod:`pinarms.viz.reach_plots`: workspace
projections).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping, Sequence, TYPE_CHECKING

import matplotlib
import numpy as np
from numpy.typing import ArrayLike
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from pinarms.errors import InvalidInput

from pinarms.viz.cell_plots import plot_clearance, plot_schedule
from pinarms.viz.figure_files import checked_numbers, save_figure
from pinarms.viz.joint_curves import JointCurves
from pinarms.viz.reach_plots import plot_workspace
from pinarms.viz.search_plots import plot_ga_convergence, plot_layout_search

if TYPE_CHECKING:
    from pinarms.planning.limits import JointLimits
    from pinarms.planning.trajectory import Trajectory
    from pinarms.robots.robot import Robot

__all__ = ["plot_joint_curves", "plot_trajectory", "plot_tool_speed", "plot_ga_convergence", "plot_workspace",
           "plot_clearance", "plot_schedule", "plot_torques",
           "plot_layout_search"]


#: A trajectory with more knots than this (e.g. a time-optimal path timing, one piece per grid
#: interval) is drawn without knot markers and lines.
MAX_DRAWN_KNOTS = 40

_ORDERS = ("position", "velocity", "acceleration", "jerk")
_UNITS = ("", "/s", "/s²", "/s³")


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


def _joint_labels(n: int, robot: Any, joint_names: Sequence[str] | None,
                  joint_units: Sequence[str] | None) -> tuple[list[str], list[str] | None]:
    """Legend names and units (``"rad"``/``"m"`` per joint, or None when unknown) of ``n`` joints."""
    if robot is not None:
        if robot.nq != n:
            raise InvalidInput(f"the curves have {n} joints but robot '{robot.name}' has {robot.nq}: "
                               "pass joint_names= and joint_units= for the joints drawn")
        joint_names = robot.joint_names if joint_names is None else joint_names
        joint_units = robot.joint_units if joint_units is None else joint_units
    names = list(joint_names) if joint_names is not None else [f"joint {j + 1}" for j in range(n)]
    if len(names) != n:
        raise InvalidInput(f"joint_names has {len(names)} names for {n} joints")
    if joint_units is None:
        return names, None
    units = list(joint_units)
    if len(units) != n or any(u not in ("rad", "m") for u in units):
        raise InvalidInput(f"joint_units must give 'rad' or 'm' for each of the {n} joints, got {units!r}")
    return names, units


def plot_joint_curves(
    path: str | Path,
    curves: JointCurves,
    *,
    limits: JointLimits | Mapping[str, ArrayLike] | None = None,
    robot: Robot | None = None,
    joint_names: Sequence[str] | None = None,
    joint_units: Sequence[str] | None = None,
    degrees: bool = False,
    title: str = "",
) -> Path:
    """Joint position/velocity/acceleration/jerk versus time, one panel per derivative order.

    Args:
        path: output file (.png or .svg).
        curves: a :class:`pinarms.viz.joint_curves.JointCurves`: instants, the joint values at them
            (derivatives left ``None`` are not drawn) and the knot instants (vertical dotted
            lines, markers on the curves).
        limits: ``planning.JointLimits`` or a mapping with ``velocity``, ``acceleration``,
            ``jerk`` (per joint or scalar, SI): drawn as dashed ±limit lines, labelled.
        robot: a ``robots.Robot`` whose joints are drawn: the default names and units.
        joint_names: legend labels (default: the robot's joint names, else ``joint 1..n``).
        joint_units: ``"rad"`` or ``"m"`` per joint (default: the robot's); the axes say the
            unit of the joints drawn (``rad or m`` only when it is not known).
        degrees: show revolute joints (unit ``"rad"``) ×180/π, in degrees.

    The legend stands to the right of the panels, outside the curves.
    """
    if not isinstance(curves, JointCurves):
        raise InvalidInput(f"curves must be a viz.joint_curves.JointCurves, got {type(curves).__name__}")
    fig = _joint_curves_figure(curves, limits=limits, robot=robot, joint_names=joint_names, joint_units=joint_units,
                               degrees=degrees, title=title)
    return save_figure(fig, path)


def _joint_curves_figure(curves: JointCurves, *, limits: Any, robot: Any, joint_names: Sequence[str] | None,
                         joint_units: Sequence[str] | None, degrees: bool, title: str) -> Figure:
    """The figure of :func:`plot_joint_curves` (checked inputs)."""
    tt = curves.t
    series = curves.series
    n = series[0][1].shape[1]
    names, units = _joint_labels(n, robot, joint_names, joint_units)
    if units is None:  # unknown kinds: SI values as given
        scale = np.full(n, 180.0 / math.pi if degrees else 1.0)
        shown = ["°" if degrees else "rad or m"] * n
    else:
        scale = np.array([180.0 / math.pi if (degrees and u == "rad") else 1.0 for u in units])
        shown = ["°" if (degrees and u == "rad") else u for u in units]
    kinds = sorted(set(shown), key=shown.index)
    mixed = len(kinds) > 1
    labels = [f"{name} [{u}]" if mixed else name for name, u in zip(names, shown)]
    knots = curves.knot_times

    fig = Figure(figsize=(8.8, 2.3 * len(series) + 0.5), layout="constrained")
    axes = fig.subplots(len(series), 1, sharex=True, squeeze=False)
    colors = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, (order, arr) in zip(axes[:, 0], series):
        for j in range(n):
            c = colors[j % len(colors)]
            ax.plot(tt, arr[:, j] * scale[j], color=c, lw=1.4, label=labels[j])
            if knots is not None:
                ax.plot(knots, np.interp(knots, tt, arr[:, j]) * scale[j], "o", color=c, ms=4)
        lim = _limit_array(limits, _ORDERS[order], n) if order > 0 else None
        if lim is not None:
            _draw_limits(ax, lim * scale, names, [f"{u}{_UNITS[order]}" for u in shown], colors)
        if knots is not None:
            for tk in knots:
                ax.axvline(tk, color="0.6", ls=":", lw=0.8)
        unit_text = " | ".join(f"{u}{_UNITS[order]}" for u in kinds)
        ax.set_ylabel(f"{_ORDERS[order]}\n[{unit_text}]")
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    handles, texts = axes[0, 0].get_legend_handles_labels()
    if knots is not None:
        handles.append(Line2D([], [], color="0.6", ls=":", marker="o", ms=4, lw=0.8))
        texts.append("via points")
    fig.legend(handles, texts, loc="outside right upper", fontsize=8, title="joints", title_fontsize=8)
    if title:
        fig.suptitle(title)
    return fig


def _draw_limits(ax: Any, lim: np.ndarray, names: list[str], units: list[str], colors: list[str]) -> None:
    """Dashed ±limit lines, each pair labelled with its value and the joints it holds for.

    Joints sharing a limit (same value and unit) share one pair of lines: black and
    labelled ``limit`` when every joint does, else black and naming them; a limit of one
    joint only is drawn in that joint's colour.
    """
    groups: dict[tuple[float, str], list[int]] = {}
    for j in range(lim.size):
        if np.isfinite(lim[j]):
            groups.setdefault((float(lim[j]), units[j]), []).append(j)
    for (value, unit), joints in groups.items():
        c = colors[joints[0] % len(colors)] if len(joints) == 1 else "k"
        for sign in (1, -1):
            ax.axhline(sign * value, color=c, ls="--", lw=0.9, alpha=0.8)
        who = "limit" if len(joints) == lim.size else f"{', '.join(names[j] for j in joints)} limit"
        text = np.format_float_positional(value, precision=4, fractional=False, trim="-")
        ax.annotate(f"{who} ±{text} {unit}", xy=(1.0, value), xycoords=("axes fraction", "data"),
                    xytext=(-3, -2), textcoords="offset points", ha="right", va="top", fontsize=7, color=c)


def plot_trajectory(path: str | Path, trajectory: Trajectory, *, limits: JointLimits | Mapping[str, ArrayLike] | None = None, samples: int = 400, **options: Any) -> Path:
    """:func:`plot_joint_curves` of a ``planning.Trajectory`` (sampled at ``samples`` instants plus its knots)."""
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise InvalidInput(f"samples must be an integer >= 2 (instants drawn), got {samples!r}")
    knots = np.asarray(trajectory.knot_times, dtype=float)
    t = np.union1d(np.linspace(knots[0], knots[-1], int(samples)), knots)
    q, qd, qdd, qddd = trajectory.sample(t)
    drawn = knots if knots.size <= MAX_DRAWN_KNOTS else None
    return plot_joint_curves(path, JointCurves(t, q, qd, qdd, qddd, knot_times=drawn), limits=limits, **options)


def plot_tool_speed(path: str | Path, t: ArrayLike, speed: ArrayLike, *, limit: float | None = None, angular: ArrayLike | None = None,
                    title: str = "tcp speed") -> Path:
    """The tcp's Cartesian speed versus time (e.g. from :func:`pinarms.planning.tcp_speed`).

    Args:
        t: instants (N,) [s]; speed: linear speed (N,) [m/s]; angular: optional (N,) [rad/s]
            (second axis); limit: a tool-speed limit [m/s], drawn dashed.
    """
    tt = checked_numbers(t, "t")
    v = checked_numbers(speed, "speed")
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
        w = checked_numbers(angular, "angular")
        if w.shape != tt.shape:
            raise InvalidInput(f"angular must have the shape of t {tt.shape}, got {w.shape}")
        ax2 = ax.twinx()
        ax2.plot(tt, w, lw=1.0, color="tab:orange", label="angular [rad/s]")
        ax2.set_ylabel("angular [rad/s]")
    ax.legend(loc="best", fontsize=8)
    ax.set_title(title)
    return save_figure(fig, path)


def plot_torques(path: str | Path, t: ArrayLike, torques: ArrayLike, limits: ArrayLike | None = None, *, joint_names: Sequence[str] | None = None,
                 units: Sequence[str] | None = None, series: Mapping[str, Any] | None = None, title: str = "joint torques") -> Path:
    """Joint torques against their limits: one panel per joint, ±limit dashed, peaks marked.

    Args:
        path: output file (.png or .svg).
        t: instants (N,) [s].
        torques: (N, n) [N·m, or N for prismatic joints]: the main curve (e.g. with the payload).
        limits: (n,) torque limits (dashed ±lines, with the peak's share of the limit in the
            panel title), or None.
        joint_names: panel titles (default ``joint 1..n``); units: per joint (default N·m).
        series: more curves to compare ``{label: (t (M,), torques (M, n))}`` (e.g. without the
            payload, or a slower timing), drawn thinner.
    """
    tt = checked_numbers(t, "t")
    tau = checked_numbers(torques, "torques")
    if tt.ndim != 1 or tt.size < 2 or np.any(np.diff(tt) <= 0):
        raise InvalidInput("t must be (N,) strictly increasing instants in s with N >= 2")
    tau = tau[:, None] if tau.ndim == 1 else tau
    if tau.ndim != 2 or tau.shape[0] != tt.size:
        raise InvalidInput(f"torques must have shape ({tt.size}, n_joints), got {np.shape(torques)}")
    n = tau.shape[1]
    names = list(joint_names) if joint_names is not None else [f"joint {j + 1}" for j in range(n)]
    if len(names) != n:
        raise InvalidInput(f"joint_names has {len(names)} names for {n} joints")
    unit = list(units) if units is not None else ["N·m"] * n
    if len(unit) != n:
        raise InvalidInput(f"units has {len(unit)} entries for {n} joints")
    lim = None
    if limits is not None:
        lim = np.broadcast_to(checked_numbers(limits, "limits", allow_inf=True), (n,))
        if np.any(lim <= 0):
            raise InvalidInput(f"limits must be positive, got {lim.tolist()}")
    extra = []
    for label, (te, ve) in (series or {}).items():
        te, ve = checked_numbers(te, f"t of {label!r}"), checked_numbers(ve, f"torques of {label!r}")
        ve = ve[:, None] if ve.ndim == 1 else ve
        if ve.shape != (te.size, n):
            raise InvalidInput(f"series {label!r} must be (t (M,), torques (M, {n})), got {te.shape} and {ve.shape}")
        extra.append((str(label), te, ve))
    cols = 2 if n > 3 else 1
    rows = int(math.ceil(n / cols))
    fig = Figure(figsize=(8.8 if cols == 2 else 7.0, 2.1 * rows + 0.6), layout="constrained")
    axes = fig.subplots(rows, cols, sharex=True, squeeze=False).reshape(-1)
    colors = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    for j in range(n):
        ax = axes[j]
        for k, (label, te, ve) in enumerate(extra):
            ax.plot(te, ve[:, j], color=colors[(k + 1) % len(colors)], lw=0.9, alpha=0.8, label=label)
        ax.plot(tt, tau[:, j], color=colors[0], lw=1.5, label="torque")
        k = int(np.argmax(np.abs(tau[:, j])))
        ax.plot(tt[k], tau[k, j], "o", color=colors[0], ms=4)
        head = names[j]
        if lim is not None and np.isfinite(lim[j]):
            for sign in (1, -1):
                ax.axhline(sign * lim[j], color="k", ls="--", lw=0.9, alpha=0.8)
            head += f"  (peak {abs(tau[k, j]) / lim[j]:.0%} of ±{np.format_float_positional(lim[j], 4, fractional=False, trim='-')})"
        ax.set_title(head, fontsize=9)
        ax.set_ylabel(f"[{unit[j]}]")
        ax.grid(True, alpha=0.3)
    for ax in axes[n:]:
        ax.set_visible(False)
    for ax in axes[max(0, n - cols):n]:
        ax.set_xlabel("time [s]")
    handles, texts = axes[0].get_legend_handles_labels()
    if lim is not None:
        handles.append(Line2D([], [], color="k", ls="--", lw=0.9))
        texts.append("±limit")
    fig.legend(handles, texts, loc="outside lower center", ncols=min(len(texts), 3), fontsize=8)
    if title:
        fig.suptitle(title)
    return save_figure(fig, path)


