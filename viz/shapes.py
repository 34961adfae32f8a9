"""Shapes and views of a scene, as plain arrays (no MeshCat here): a tube along a tcp path,
a floor grid, and the camera view that frames the robots. World frame, metres.
"""

from __future__ import annotations

import numpy as np

__all__ = ["tube_mesh", "floor_grid", "downsample_polyline", "frame_view", "transform_points", "CAMERA_FOV_DEG"]

#: Vertical field of view of MeshCat's default camera [deg].
CAMERA_FOV_DEG = 75.0
#: Elevation of the camera above the framed target [deg], and its azimuth away from the side
#: where the tcp paths lie (seen from the robots' bases) [deg]: a three-quarter view with the
#: paths in front of the robots.
VIEW_ELEVATION_DEG = 25.0
VIEW_TURN_DEG = -35.0
DEFAULT_AZIMUTH_DEG = -40.0  # no path: from the front right (+x, -y)


def tube_mesh(points: np.ndarray, radius: float, sides: int = 10) -> tuple[np.ndarray, np.ndarray] | None:
    """Vertices ``(k·sides, 3)`` and triangles ``(·, 3)`` of a tube of ``radius`` [m] along a polyline.

    The rings follow rotation-minimising frames (double reflection, Wang et al. 2008), so
    the tube does not twist. ``None`` when the polyline has fewer than two distinct points.
    """
    keep = np.concatenate([[True], np.linalg.norm(np.diff(points, axis=0), axis=1) > 1e-9])
    p = points[keep]
    if p.shape[0] < 2:
        return None
    seg = np.diff(p, axis=0)
    seg /= np.linalg.norm(seg, axis=1, keepdims=True)
    tangent = np.vstack([seg[0], seg[:-1] + seg[1:], seg[-1]])
    norm = np.linalg.norm(tangent, axis=1, keepdims=True)
    tangent = np.where(norm > 1e-12, tangent / np.maximum(norm, 1e-12), np.vstack([seg, seg[-1]]))
    ref = np.eye(3)[int(np.argmin(np.abs(tangent[0])))]
    normals = np.empty_like(p)
    normals[0] = np.cross(tangent[0], ref)
    normals[0] /= np.linalg.norm(normals[0])
    for i in range(p.shape[0] - 1):  # one pass along the (downsampled) path: each frame follows the last
        v1 = p[i + 1] - p[i]
        c1 = v1 @ v1
        r_l = normals[i] - (2.0 / c1) * (v1 @ normals[i]) * v1
        t_l = tangent[i] - (2.0 / c1) * (v1 @ tangent[i]) * v1
        v2 = tangent[i + 1] - t_l
        c2 = v2 @ v2
        normals[i + 1] = r_l - (2.0 / c2) * (v2 @ r_l) * v2 if c2 > 1e-24 else r_l
    binormals = np.cross(tangent, normals)
    angle = 2.0 * np.pi * np.arange(sides) / sides
    ring = np.cos(angle)[None, :, None] * normals[:, None, :] + np.sin(angle)[None, :, None] * binormals[:, None, :]
    vertices = (p[:, None, :] + radius * ring).reshape(-1, 3)
    i, k = np.meshgrid(np.arange(p.shape[0] - 1), np.arange(sides), indexing="ij")
    a, b = i * sides + k, i * sides + (k + 1) % sides
    c, d = a + sides, b + sides
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([b, d, c], -1).reshape(-1, 3)])
    return vertices, faces


def floor_grid(lo: np.ndarray, hi: np.ndarray, z: float) -> tuple[np.ndarray, float]:
    """Segment end points ``(2k, 3)`` of a square grid on the plane ``z`` [m] under ``lo..hi``, and its spacing [m].

    The spacing is 0.1 m (0.5 m when the content spans more than 4 m), the grid reaches
    half a metre beyond the content. Lines are cut at every crossing so that no segment is
    longer than one square (long lines that pass behind the camera are dropped whole by
    some WebGL renderers).
    """
    step = 0.1 if float(np.max(hi[:2] - lo[:2])) <= 4.0 else 0.5
    x = np.arange(np.floor((lo[0] - 0.5) / step), np.ceil((hi[0] + 0.5) / step) + 1) * step
    y = np.arange(np.floor((lo[1] - 0.5) / step), np.ceil((hi[1] + 0.5) / step) + 1) * step
    ends = []
    gx, gy = np.meshgrid(x[:-1], y, indexing="ij")  # segments along x
    ends.append(np.stack([np.stack([gx, gy], -1), np.stack([gx + step, gy], -1)], -2).reshape(-1, 2))
    gx, gy = np.meshgrid(x, y[:-1], indexing="ij")  # segments along y
    ends.append(np.stack([np.stack([gx, gy], -1), np.stack([gx, gy + step], -1)], -2).reshape(-1, 2))
    xy = np.vstack(ends)
    return np.column_stack([xy, np.full(xy.shape[0], z)]), step


def downsample_polyline(points: np.ndarray, max_points: int = 1500) -> np.ndarray:
    """At most ``max_points`` rows of ``points``, evenly spaced, first and last kept."""
    if points.shape[0] <= max_points:
        return points
    return points[np.unique(np.linspace(0, points.shape[0] - 1, max_points).round().astype(int))]


def frame_view(points: np.ndarray, toward: np.ndarray | None = None,
             aspect: float = 4.0 / 3.0) -> tuple[np.ndarray, np.ndarray, float]:
    """``(target, camera, radius)``: a view of ``points (k, 3)`` [m] (world) that fits them.

    The target is the middle of their bounding box; the camera looks at it from
    :data:`VIEW_ELEVATION_DEG` above, from the side of ``toward`` (a horizontal direction,
    e.g. from the robots' bases to their tcp paths) turned by :data:`VIEW_TURN_DEG`, far
    enough for the bounding sphere to fill about 85 % of the narrower field of view of
    MeshCat's camera (75° vertical) on a page of ``aspect``.
    """
    lo, hi = points.min(axis=0), points.max(axis=0)
    target = 0.5 * (lo + hi)
    radius = max(float(np.max(np.linalg.norm(points - target, axis=1))), 0.15)
    if toward is not None and np.hypot(toward[0], toward[1]) > 1e-6:
        azimuth = np.arctan2(toward[1], toward[0]) + np.radians(VIEW_TURN_DEG)
    else:
        azimuth = np.radians(DEFAULT_AZIMUTH_DEG)
    elevation = np.radians(VIEW_ELEVATION_DEG)
    direction = np.array([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])
    half_v = np.radians(CAMERA_FOV_DEG) / 2.0
    half = min(half_v, np.arctan(np.tan(half_v) * aspect))
    distance = radius / np.sin(half) / 0.85
    return target, target + distance * direction, radius


def transform_points(T: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Points ``p (N, 3)`` moved by the homogeneous transform ``T (4, 4)``."""
    return p @ T[:3, :3].T + T[:3, 3]
