"""Visualisation and saved sessions: MeshCat scenes in the browser, standalone HTML, plots.

>>> from pinarms import robots, viz
>>> s = viz.Session(robots.load("ur5"), title="demo")
>>> s.save("demo.pinarms")
>>> with viz.show(viz.load_session("demo.pinarms")) as viewer:
...     print(viewer.url)
>>> viz.export_html(s, "demo.html")
>>> viz.plot_trajectory("joints.png", traj, limits=limits)
"""

from __future__ import annotations

from ..lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "SessionFormatError": ".errors",
    "ViewerError": ".errors",
    "VizError": ".errors",
    "export_html": ".html",
    "layout_search_session": ".layout_session",
    "plot_ga_convergence": ".search_plots",
    "plot_joint_curves": ".plots",
    "plot_layout_search": ".search_plots",
    "plot_tool_speed": ".plots",
    "plot_torques": ".plots",
    "plot_trajectory": ".plots",
    "plot_workspace": ".reach_plots",
    "SceneInfo": ".scene",
    "build_scene": ".scene",
    "FORMAT_NAME": ".session",
    "FORMAT_VERSION": ".session",
    "BoxObject": ".session_records",
    "HistoryRecord": ".session_records",
    "PointSet": ".session_records",
    "RobotEntry": ".session_records",
    "Session": ".session",
    "SessionLimits": ".session_archive",
    "TrajectoryRecord": ".session_records",
    "WorkspaceRecord": ".session_records",
    "load_session": ".session",
    "MeshcatServer": ".server",
    "Viewer": ".viewer",
    "show": ".viewer",
}

__all__ = [
    "Session", "load_session", "SessionLimits", "FORMAT_NAME", "FORMAT_VERSION", "RobotEntry", "BoxObject",
    "TrajectoryRecord", "WorkspaceRecord", "PointSet", "HistoryRecord", "show", "Viewer", "MeshcatServer",
    "export_html", "build_scene", "plot_joint_curves", "plot_trajectory", "plot_tool_speed", "plot_ga_convergence",
    "plot_workspace", "plot_torques", "plot_layout_search", "layout_search_session", "SceneInfo", "VizError",
    "SessionFormatError", "ViewerError",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
