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

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "SessionFormatError": "pinarms.viz.errors",
    "ViewerError": "pinarms.viz.errors",
    "VizError": "pinarms.viz.errors",
    "export_html": "pinarms.viz.html",
    "layout_search_session": "pinarms.viz.layout_session",
    "plot_ga_convergence": "pinarms.viz.search_plots",
    "plot_joint_curves": "pinarms.viz.plots",
    "plot_layout_search": "pinarms.viz.search_plots",
    "plot_tool_speed": "pinarms.viz.plots",
    "plot_torques": "pinarms.viz.plots",
    "plot_trajectory": "pinarms.viz.plots",
    "plot_workspace": "pinarms.viz.reach_plots",
    "SceneInfo": "pinarms.viz.scene",
    "build_scene": "pinarms.viz.scene",
    "FORMAT_NAME": "pinarms.viz.session",
    "FORMAT_VERSION": "pinarms.viz.session",
    "BoxObject": "pinarms.viz.session_records",
    "HistoryRecord": "pinarms.viz.session_records",
    "PointSet": "pinarms.viz.session_records",
    "RobotEntry": "pinarms.viz.session_records",
    "Session": "pinarms.viz.session",
    "SessionLimits": "pinarms.viz.session_archive",
    "TrajectoryRecord": "pinarms.viz.session_records",
    "WorkspaceRecord": "pinarms.viz.session_records",
    "DeltaRecord": "pinarms.viz.delta_record",
    "load_session": "pinarms.viz.session",
    "MeshcatServer": "pinarms.viz.server",
    "Viewer": "pinarms.viz.viewer",
    "show": "pinarms.viz.viewer",
}

__all__ = [
    "Session", "load_session", "SessionLimits", "FORMAT_NAME", "FORMAT_VERSION", "RobotEntry", "BoxObject",
    "TrajectoryRecord", "WorkspaceRecord", "PointSet", "HistoryRecord", "show", "Viewer", "MeshcatServer",
    "export_html", "build_scene", "plot_joint_curves", "plot_trajectory", "plot_tool_speed", "plot_ga_convergence",
    "plot_workspace", "plot_torques", "plot_layout_search", "layout_search_session", "SceneInfo", "VizError",
    "SessionFormatError", "ViewerError", "DeltaRecord",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
