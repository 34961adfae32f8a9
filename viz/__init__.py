"""Visualisation and saved sessions: MeshCat scenes in the browser, standalone HTML, plots.

>>> from pinarms import robots, viz
>>> s = viz.Session(robots.load("ur5"), title="demo")
>>> s.save("demo.pinarms")
>>> with viz.show(viz.load_session("demo.pinarms")) as viewer:
...     print(viewer.url)
>>> viz.export_html(s, "demo.html")
>>> viz.plot_trajectory("joints.png", traj, limits=limits)
"""

from .errors import SessionFormatError, ViewerError, VizError
from .html import export_html
from .layout_session import layout_search_session
from .plots import (
    plot_ga_convergence,
    plot_joint_curves,
    plot_layout_search,
    plot_tool_speed,
    plot_torques,
    plot_trajectory,
    plot_workspace,
)
from .scene import SceneInfo, build_scene
from .session import (
    FORMAT_NAME,
    FORMAT_VERSION,
    BoxObject,
    HistoryRecord,
    PointSet,
    RobotEntry,
    Session,
    SessionLimits,
    TrajectoryRecord,
    WorkspaceRecord,
    load_session,
)
from .server import MeshcatServer
from .viewer import Viewer, show

__all__ = [
    "Session",
    "load_session",
    "SessionLimits",
    "FORMAT_NAME",
    "FORMAT_VERSION",
    "RobotEntry",
    "BoxObject",
    "TrajectoryRecord",
    "WorkspaceRecord",
    "PointSet",
    "HistoryRecord",
    "show",
    "Viewer",
    "MeshcatServer",
    "export_html",
    "build_scene",
    "plot_joint_curves",
    "plot_trajectory",
    "plot_tool_speed",
    "plot_ga_convergence",
    "plot_workspace",
    "plot_torques",
    "plot_layout_search",
    "layout_search_session",
    "SceneInfo",
    "VizError",
    "SessionFormatError",
    "ViewerError",
]
