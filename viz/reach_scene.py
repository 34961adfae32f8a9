"""Reachability maps in a MeshCat scene: voxels coloured by reachability index, one object per layer.

Scene paths (under MeshCat's root ``/meshcat``):
``pinarms/reachability/<name>/layers/z<mm>mm`` — the voxels of one horizontal layer (their
centres' height in the robot's base frame, in mm) as square points the size of a voxel,
coloured by reachability index on a fixed scale (0 → the colormap's low end, 1 → its high
end). One object per layer is what the page's slice control switches (:mod:`pinarms.viz.page`, key
``"reachability"``): all layers, the layers up to a height, or one layer; MeshCat's own
Controls panel lists them too.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib
import numpy as np

from pinarms.viz._meshcat import meshcat, mg

if TYPE_CHECKING:
    from pinarms.viz.session import Session

__all__ = ["draw_reachability", "layer_name", "INDEX_COLORMAP"]

#: Colormap of the reachability index (0 → low end, 1 → high end; fixed scale).
INDEX_COLORMAP = "viridis"


def layer_name(z: float) -> str:
    """Scene name of the layer whose voxel centres have height ``z`` [m] (millimetres, rounded)."""
    return f"z{int(round(z * 1000.0))}mm"


def _transform(T: np.ndarray, p: np.ndarray) -> np.ndarray:
    return p @ T[:3, :3].T + T[:3, 3]


def draw_reachability(vis: meshcat.Visualizer, session: Session, root: str, bounds: list) -> tuple[dict[str, list[str]], list[dict]]:
    """Draw every reachability record of ``session``.

    Returns ``name → layer paths`` (lowest layer first) and the page entries (``name``,
    ``description``, ``label``, ``colors``, ``layers``: ``path`` and ``z_mm``). ``bounds``
    (a list of ``(n, 3)`` world points) is extended with each map's voxels.
    """
    from pinarms.viz.page import colorbar_stops

    out: dict[str, list[str]] = {}
    page: list[dict] = []
    cmap = matplotlib.colormaps[INDEX_COLORMAP]
    for name, rec in getattr(session, "reachability", {}).items():
        T = session.robots[rec.robot].base_to_world
        z_layers = np.floor(rec.centres[:, 2] / rec.resolution).astype(np.int64)
        paths, layers = [], []
        for layer in np.unique(z_layers):
            sel = z_layers == layer
            world = _transform(T, rec.centres[sel])
            colors = np.asarray(cmap(np.clip(rec.index[sel], 0.0, 1.0)))[:, :3]
            z = float(np.mean(rec.centres[sel, 2]))
            path = f"{root}/reachability/{name}/layers/{layer_name(z)}"
            vis[path].set_object(mg.PointCloud(world.T.astype(np.float32), colors.T.astype(np.float32),
                                               size=0.9 * rec.resolution))
            vis[path].set_property("visible", False)  # opaque voxels would hide the robot: the page's slice control shows them
            paths.append(path)
            layers.append({"path": path, "z_mm": int(round(z * 1000.0))})
        bounds.append(_transform(T, rec.centres))
        out[name] = paths
        page.append({"name": name, "description": rec.description, "label": "reachability index",
                     "colors": colorbar_stops(INDEX_COLORMAP), "layers": layers})
    return out, page
