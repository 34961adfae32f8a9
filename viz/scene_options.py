"""How a session's scene is drawn: :class:`SceneOptions`, checked when made.

:func:`pinarms.viz.scene.build_scene`, :func:`pinarms.viz.show` and :func:`pinarms.viz.export_html` take one; the
defaults draw every robot's first trajectory at 30 frames per second, playing, with translucent
clouds of at most 20 000 points.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import matplotlib
import numpy as np

from pinarms.errors import InvalidInput

__all__ = ["SceneOptions"]


@dataclass(frozen=True)
class SceneOptions:
    """What a scene draws and how (every field has a default).

    Attributes:
        animate: trajectory names to animate (at most one per robot); ``None``: the first
            trajectory of each robot; ``()`` for no animation.
        fps: animation frame rate [1/s].
        play: start playing (looping) when a browser opens the page.
        point_pixels: size of the workspace points on screen [px].
        cloud_opacity: their opacity in (0, 1].
        show_clouds: whether the clouds are shown when the page opens (the page has a switch either way).
        max_cloud_points: a larger cloud is drawn as a seeded uniform subsample of that many
            points (the page says so; the session keeps all).
        sphere_radius: via-point sphere radius [m]; ``None``: 1.5 % of the framed radius, at
            least 12 mm; the tcp path tube's radius is 40 % of it.
        colormap: matplotlib colormap for manipulability (low → high).
        hide_background: hide MeshCat's background, grid and axes (plain white page).

    Raises:
        InvalidInput: an option out of its range, naming the option and its unit.
    """

    animate: Sequence[str] | None = None
    fps: float = 30.0
    play: bool = True
    point_pixels: float = 3.0
    cloud_opacity: float = 0.3
    show_clouds: bool = True
    max_cloud_points: int = 20_000
    sphere_radius: float | None = None
    colormap: str = "viridis"
    hide_background: bool = False

    def __post_init__(self) -> None:
        if self.animate is not None and not isinstance(self.animate, str):
            object.__setattr__(self, "animate", tuple(self.animate))
        fps = self.fps
        if not (np.isfinite(fps) and fps > 0):
            raise InvalidInput(f"fps must be a positive frame rate in 1/s, got {fps!r}")
        if self.colormap not in matplotlib.colormaps:
            raise InvalidInput(f"unknown matplotlib colormap {self.colormap!r}")
        if not (isinstance(self.cloud_opacity, (int, float)) and 0.0 < self.cloud_opacity <= 1.0):
            raise InvalidInput(f"cloud_opacity must be in (0, 1], got {self.cloud_opacity!r}")
        for name, value, unit in (("point_pixels", self.point_pixels, "px"), ("sphere_radius", self.sphere_radius, "m")):
            if value is None and name == "sphere_radius":
                continue
            if isinstance(value, bool) or not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
                raise InvalidInput(f"{name} must be a positive size in {unit}, got {value!r}")
        n = self.max_cloud_points
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise InvalidInput(f"max_cloud_points must be a positive integer, got {n!r}")
