"""What a study of the demo returns, and the helpers the studies share (units, sessions, plots).

A study (one module per paper seed under :mod:`pinarms.studies`, plus the cell, line and
hand-off studies) builds its robot, redoes the paper's computation with pinarms and returns a
:class:`Study`: the rows of the paper-vs-pinarms table, a :class:`pinarms.viz.Session` and plot
writers. :mod:`pinarms.demo` lists the studies and runs them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from pinarms.report import Row

if TYPE_CHECKING:
    from pinarms.optim.ga.engine import GAHistory
    from pinarms.planning import JointLimits, Trajectory
    from pinarms.robots import Robot
    from pinarms.robots.reach.workspace import Workspace
    from pinarms.viz import Session

__all__ = ["Study", "DEG", "MM", "study_session", "trajectory_plots", "workspace_plots"]


DEG = np.pi / 180.0
MM = 1e-3


@dataclass
class Study:
    """What one seed's study produced."""

    key: str
    title: str
    rows: list[Row]
    session: Any = None  # viz.Session
    plots: dict[str, Callable[[Path], Any]] = field(default_factory=dict)  # name -> writer(path)
    seconds: float = 0.0
    exports: dict[str, Callable[[Path], list[Path]]] = field(default_factory=dict)  # name -> writer(folder) -> files


def study_session(robot: Robot, title: str) -> Session:
    """An empty :class:`pinarms.viz.Session` of ``robot`` for a study's scene."""
    from pinarms import viz

    return viz.Session(robot, title=title)


def trajectory_plots(traj: Trajectory, limits: JointLimits, history: GAHistory | None, title: str,
                     degrees: bool = False, **joints: Any) -> dict[str, Callable[[Path], Any]]:
    """Plot writers (path → file) of a trajectory's joint curves and a GA history.

    ``joints``: ``robot=`` or ``joint_names=`` and ``joint_units=`` of the joints drawn.
    """
    from pinarms.viz import plots as vplots

    out: dict[str, Callable[[Path], Any]] = {
        "joints": lambda path: vplots.plot_trajectory(path, traj, limits=limits, title=title, degrees=degrees, **joints),
    }
    if history is not None:
        out["ga"] = lambda path: vplots.plot_ga_convergence(path, history, title=f"{title}: GA", ylabel="total time [s]")
    return out


def workspace_plots(ws: Workspace, title: str) -> dict[str, Callable[[Path], Any]]:
    """The plot writer (path → file) of a sampled workspace, in mm."""
    from pinarms.viz import plots as vplots

    return {"workspace": lambda path: vplots.plot_workspace(path, ws, title=title, mm=True)}
