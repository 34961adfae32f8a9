"""Workspace clouds in a MeshCat scene: translucent points coloured by manipulability, and their colour bar.

A cloud is drawn under ``<root>/workspace/<name>`` in the world frame, as points of a fixed
size on screen; a cloud larger than asked is drawn as a seeded uniform subsample (the page
says so; the session keeps every point). Colours scale each cloud's manipulability by its
maximum (0 → the colormap's low end).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, TYPE_CHECKING

import matplotlib
import numpy as np

from pinarms.viz._meshcat import meshcat, mg
from pinarms.viz.page import colorbar_stops, manipulability_unit
from pinarms.viz.shapes import transform_points

if TYPE_CHECKING:
    from pinarms.viz.session import Session

__all__ = ["colors_by_value", "Clouds", "draw_clouds", "cloud_colorbar"]


def colors_by_value(values: np.ndarray, colormap: str = "viridis") -> np.ndarray:
    """RGB colours (N, 3) in [0, 1] of ``values`` scaled by their maximum (0 → low end of the colormap)."""
    v = np.asarray(values, dtype=float)
    top = v.max() if v.size else 0.0
    x = v / top if top > 0 else np.zeros_like(v)
    return np.asarray(matplotlib.colormaps[colormap](x))[:, :3]


class _CloudMaterial(mg.PointsMaterial):
    """MeshCat's point material, translucent and of a fixed size on screen [px]: the cloud never
    hides what stands inside it, and points near the camera do not grow into squares."""

    def __init__(self, pixels: float, opacity: float) -> None:
        super().__init__(size=pixels)
        self.opacity = opacity

    def lower(self, object_data: Any) -> dict:
        data = super().lower(object_data)
        data.update(transparent=True, opacity=self.opacity, depthWrite=False, sizeAttenuation=False)
        return data


@dataclass
class Clouds:
    """The workspace clouds drawn: scene paths, their robots, (shown, total) points, the largest manipulability."""

    paths: dict[str, str] = field(default_factory=dict)
    robots: list[str] = field(default_factory=list)
    shown: dict[str, tuple[int, int]] = field(default_factory=dict)
    w_max: float = 0.0


def draw_clouds(vis: meshcat.Visualizer, session: Session, root: str, bounds: list[np.ndarray], *, colormap: str,
                 point_pixels: float, cloud_opacity: float, show_clouds: bool, max_cloud_points: int) -> Clouds:
    """Draw the workspace clouds under ``<root>/workspace/<name>`` in the world frame (joining ``bounds``), coloured by manipulability, a seeded subsample when too large."""
    clouds = Clouds()
    for name, ws in session.workspaces.items():
        world = transform_points(session.robots[ws.robot].base_to_world, ws.points)
        colors = colors_by_value(ws.manipulability, colormap)  # scaled by the whole cloud's maximum
        shown = np.arange(world.shape[0])
        if world.shape[0] > max_cloud_points:
            shown = np.sort(np.random.default_rng(0).choice(world.shape[0], size=int(max_cloud_points), replace=False))
        clouds.shown[name] = (shown.size, world.shape[0])
        path = f"{root}/workspace/{name}"
        vis[path].set_object(mg.Points(
            mg.PointsGeometry(world[shown].T.astype(np.float32), colors[shown].T.astype(np.float32)),
            _CloudMaterial(point_pixels, cloud_opacity)))
        if not show_clouds:
            vis[path].set_property("visible", False)
        clouds.paths[name] = path
        clouds.robots.append(ws.robot)
        clouds.w_max = max(clouds.w_max, float(np.max(ws.manipulability)))
        bounds.append(world)
    return clouds


def cloud_colorbar(session: Session, clouds: Clouds, colormap: str) -> dict[str, Any] | None:
    """The page's manipulability colour bar, or None without clouds."""
    if not clouds.paths:
        return None
    units = {manipulability_unit(session.robot(k).joint_units) for k in clouds.robots}
    return {
        "label": "position manipulability √det(J_v J_vᵀ)",
        "unit": units.pop() if len(units) == 1 else "",
        "min": 0.0,
        "max": clouds.w_max,
        "colors": colorbar_stops(colormap),
    }
