"""Plots of what an arm reaches (matplotlib Agg): workspace clouds, and the reachability index over a section.

:func:`plot_workspace` draws a workspace cloud seen from the top and the side, coloured by manipulability.

:func:`plot_reachability_section` turns a 3-D map into the picture a line engineer reads: the
horizontal distance ``ρ`` from the base's vertical axis against the height ``z`` (mm), each
cell coloured by the *mean* reachability index of the voxels at that ``(ρ, z)`` over all
azimuths (0 → the colormap's low end, 1 → its high end, a fixed scale), cells without a
computed voxel left white. A *band* (a table region) can be drawn over it: the spherical
shell ``r_inner < |p − centre| < r_outer`` cut by ``z > z_min`` (seed 001's recommended
region), the shape the paper gives.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from numpy.typing import ArrayLike
from matplotlib.figure import Figure

from pinarms.errors import InvalidInput

from pinarms.viz.figure_files import checked_numbers, save_figure
from pinarms.viz.reach_scene import INDEX_COLORMAP

if TYPE_CHECKING:
    from pinarms.robots.reach.reach_map import ReachabilityMap

__all__ = ["plot_workspace", "plot_reachability_section", "section_index"]


def section_index(reach_map: ReachabilityMap, cell: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(rho_edges (a+1,), z_edges (b+1,), mean_index (a, b))`` [m] of the map over ``(ρ, z)`` cells of edge ``cell``.

    ``ρ`` is the horizontal distance of a voxel centre from the base's vertical axis; cells
    holding no computed voxel are NaN. ``cell`` defaults to the map's resolution.
    """
    cell = float(reach_map.resolution if cell is None else cell)
    if not (np.isfinite(cell) and cell > 0):
        raise InvalidInput(f"cell must be a positive length in m, got {cell!r}")
    c = reach_map.centres()
    rho = np.hypot(c[:, 0], c[:, 1])
    z = c[:, 2]
    a = max(1, int(np.ceil((rho.max() if rho.size else cell) / cell)) + 1)
    z0 = np.floor((z.min() if z.size else 0.0) / cell) * cell
    b = max(1, int(np.ceil(((z.max() if z.size else cell) - z0) / cell)) + 1)
    ia = np.minimum((rho / cell).astype(int), a - 1)
    ib = np.minimum(((z - z0) / cell).astype(int), b - 1)
    flat = ia * b + ib
    total = np.bincount(flat, weights=reach_map.index, minlength=a * b)
    count = np.bincount(flat, minlength=a * b)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0, total / count, np.nan).reshape(a, b)
    return np.arange(a + 1) * cell, z0 + np.arange(b + 1) * cell, mean


def plot_reachability_section(
    path: str | Path,
    reach_map: ReachabilityMap,
    *,
    band: dict | None = None,
    title: str = "",
    cell: float | None = None,
) -> Path:
    """Write the ``(ρ, z)`` section of ``reach_map`` (module doc) to ``path`` (.png or .svg); return the path.

    Args:
        band: optional table region to outline: ``{"centre": (3,) [m], "r_inner": m,
            "r_outer": m, "z_min": m, "label": str}``.
        cell: section cell edge [m] (default the map's resolution).
    """
    rho_e, z_e, mean = section_index(reach_map, cell)
    mm = 1000.0
    fig = Figure(figsize=(7.5, 6.0))
    ax = fig.add_subplot(1, 1, 1)
    cmap = matplotlib.colormaps[INDEX_COLORMAP].with_extremes(bad="white")
    mesh = ax.pcolormesh(rho_e * mm, z_e * mm, np.ma.masked_invalid(mean).T, cmap=cmap, vmin=0.0, vmax=1.0,
                         shading="flat")
    cb = fig.colorbar(mesh, ax=ax)
    cb.set_label("reachability index (mean over azimuth)")
    if band is not None:
        try:
            centre = np.asarray(band["centre"], dtype=float).reshape(3)
            r_in, r_out, z_min = float(band["r_inner"]), float(band["r_outer"]), float(band["z_min"])
        except (KeyError, TypeError, ValueError) as exc:
            raise InvalidInput("band needs centre (3,), r_inner, r_outer and z_min [m]") from exc
        rho_c = float(np.hypot(centre[0], centre[1]))
        t = np.linspace(-np.pi / 2, np.pi / 2, 400)
        for r in (r_in, r_out):
            x, y = rho_c + r * np.cos(t), centre[2] + r * np.sin(t)
            keep = (y > z_min) & (x >= 0)
            ax.plot(x[keep] * mm, y[keep] * mm, color="red", lw=2)
        zz = np.array([z_min, z_min])
        reach = np.sqrt(np.maximum(np.array([r_in, r_out]) ** 2 - (z_min - centre[2]) ** 2, 0.0))
        ax.plot((rho_c + reach) * mm, zz * mm, color="red", lw=2, label=band.get("label", "table band"))
        ax.legend(loc="lower right", fontsize=8)
    ax.set_xlabel("horizontal distance from the base axis ρ [mm]")
    ax.set_ylabel("height z [mm] (base frame)")
    ax.set_aspect("equal")
    import textwrap

    text = title or f"{reach_map.robot}, {reach_map.resolution * 1000:g} mm voxels: {reach_map.orientations.describe()}"
    ax.set_title("\n".join(textwrap.wrap(text, 80)), fontsize=9)
    return save_figure(fig, path)


def plot_workspace(path: str | Path, points: ArrayLike, manipulability: ArrayLike | None = None, *, title: str = "workspace",
                   colormap: str = "viridis", mm: bool = False) -> Path:
    """Top (x-y) and side (x-z) projections of a workspace cloud coloured by manipulability.

    ``points`` (n, 3) m (or a ``Workspace``/:class:`pinarms.viz.WorkspaceRecord` with ``points`` and
    ``manipulability``); ``mm=True`` labels the axes in millimetres.
    """
    if hasattr(points, "points"):
        points, manipulability = points.points, points.manipulability
    pts = checked_numbers(points, "points")
    if pts.ndim != 2 or pts.shape[1] != 3 or pts.shape[0] == 0:
        raise InvalidInput(f"points must have shape (n, 3) with n >= 1, got {pts.shape}")
    if colormap not in matplotlib.colormaps:
        raise InvalidInput(f"unknown matplotlib colormap {colormap!r}")
    w = None if manipulability is None else checked_numbers(manipulability, "manipulability")
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
    return save_figure(fig, path)
