"""Reachability maps in a MeshCat scene: coloured voxels in horizontal layers, and a colour bar.

Scene paths (under MeshCat's root ``/meshcat``):

- ``pinarms/reachability/<name>/layers/z<mm>mm`` — the voxels of one horizontal layer (the
  robot's base frame ``z`` of their centres, in mm) as square points the size of a voxel,
  coloured by reachability index on a fixed scale (0 → the colormap's low end, 1 → its high
  end). One object per layer is the slice control: the viewer's Controls panel lists the
  layers and toggles each; the standalone page adds a slider (:mod:`viz.reach_overlay`).
- ``pinarms/reachability/<name>/colorbar`` — a vertical colour bar with its scale (a textured
  plate drawn by matplotlib) standing beside the map, so the live viewer shows it too.
"""

from __future__ import annotations

import io
from typing import Any

import matplotlib
import numpy as np

from ._meshcat import meshcat, mg

__all__ = ["draw_reachability", "layer_name", "colorbar_png", "INDEX_COLORMAP"]

#: Colormap of the reachability index (0 → low end, 1 → high end; fixed scale).
INDEX_COLORMAP = "viridis"


def layer_name(z: float) -> str:
    """Scene name of the layer whose voxel centres have height ``z`` [m] (millimetres, rounded)."""
    return f"z{int(round(z * 1000.0))}mm"


def colorbar_png(label: str = "reachability index", colormap: str = INDEX_COLORMAP) -> bytes:
    """A vertical colour bar 0..1 as PNG bytes (about 160 × 640 pixels)."""
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(1.6, 6.4), dpi=100)
    ax = fig.add_axes([0.15, 0.05, 0.25, 0.9])
    norm = matplotlib.colors.Normalize(0.0, 1.0)
    cb = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=colormap), cax=ax)
    cb.set_label(label, fontsize=14)
    cb.ax.tick_params(labelsize=12)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", facecolor="white")
    plt.close(fig)
    return buf.getvalue()


def _transform(T: np.ndarray, p: np.ndarray) -> np.ndarray:
    return p @ T[:3, :3].T + T[:3, 3]


def draw_reachability(vis: Any, session: Any, root: str, bounds: list) -> dict[str, list[str]]:
    """Draw every reachability record of ``session``; return name → scene paths (layers, then the colour bar).

    ``bounds`` (a list of ``(n, 3)`` world points) is extended with each map's voxels.
    """
    out: dict[str, list[str]] = {}
    cmap = matplotlib.colormaps[INDEX_COLORMAP]
    png = None
    for name, rec in getattr(session, "reachability", {}).items():
        T = session.robots[rec.robot].base_to_world
        z_layers = np.round(rec.centres[:, 2] / rec.resolution - 0.5).astype(np.int64)
        paths = []
        for layer in np.unique(z_layers):
            sel = z_layers == layer
            world = _transform(T, rec.centres[sel])
            colors = np.asarray(cmap(np.clip(rec.index[sel], 0.0, 1.0)))[:, :3]
            path = f"{root}/reachability/{name}/layers/{layer_name((layer + 0.5) * rec.resolution)}"
            vis[path].set_object(mg.PointCloud(world.T.astype(np.float32), colors.T.astype(np.float32),
                                               size=0.9 * rec.resolution))
            paths.append(path)
        world_all = _transform(T, rec.centres)
        bounds.append(world_all)
        lo, hi = world_all.min(axis=0), world_all.max(axis=0)
        height = max(float(hi[2] - lo[2]), 4 * rec.resolution)
        width = height / 4.0
        if png is None:
            png = colorbar_png()
        bar = f"{root}/reachability/{name}/colorbar"
        material = mg.MeshBasicMaterial(map=mg.ImageTexture(image=mg.PngImage(png)))
        vis[bar].set_object(mg.Box([width, 0.002, height]), material)
        # to the right of the map as the default camera sees it, facing that camera
        # (viz.scene places it towards (0.75, -0.55, 0.45) from the origin)
        yaw = np.arctan2(0.75, 0.55)
        right = np.array([0.55, 0.75, 0.0]) / np.hypot(0.55, 0.75)
        mid = 0.5 * (lo + hi)
        reach = 0.5 * float(np.hypot(hi[0] - lo[0], hi[1] - lo[1]))
        pose = meshcat.transformations.rotation_matrix(yaw, [0.0, 0.0, 1.0])
        pose[:3, 3] = [*(mid[:2] + (reach + 2 * rec.resolution + width) * right[:2]), mid[2]]
        vis[bar].set_transform(pose)
        paths.append(bar)
        out[name] = paths
    return out
