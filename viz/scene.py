"""A MeshCat scene built from a :class:`pinarms.viz.Session`.

Scene paths (under MeshCat's root ``/meshcat``), readable and stable:

- ``pinarms/robots/<key>`` — a robot, placed at its ``base_to_world``; its visual geometry
  (Pinocchio's visual model of the URDF) in ``pinarms/robots/<key>/visuals/<geometry>``
  (:mod:`pinarms.viz.robot_drawing`);
- ``pinarms/objects/<name>`` — static boxes (conveyor, crate);
- ``pinarms/workspace/<name>`` — a workspace cloud (``Points``, translucent) coloured by
  manipulability (:mod:`pinarms.viz.cloud_scene`);
- ``pinarms/paths/<name>`` — the TCP path of a trajectory, world frame: a thin tube
  (``Mesh``), since browsers draw WebGL lines one pixel wide whatever their width;
- ``pinarms/vias/<name>/<i>`` — the TCP at the trajectory's knots (small spheres);
- ``pinarms/points/<name>/<i>`` — via points / targets of the session (small spheres);
- ``pinarms/reachability/<name>/layers/z<mm>mm`` — reachability maps: the voxels of one
  horizontal layer each (:mod:`pinarms.viz.reach_scene`; the page's slice control shows/hides them);
- ``pinarms/deltas/<name>/<part>`` — a delta robot's upper arms, rods, platform and tool, its closed
  chain solved from its actuated angles (:mod:`pinarms.viz.delta_scene`).

One MeshCat animation per scene: the chosen trajectories (default: the first one of each
robot) and the deltas' motions play together from time 0, sampled at ``fps`` frames per second, looping
(:mod:`pinarms.viz.trajectory_scene`).

What the page around the scene shows (title, colour bar, framing, controls: see
:mod:`pinarms.viz.page`) is stored on the scene root as the property ``pinarms_page`` (JSON), so
that the standalone page and the live viewer read it the same way.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, TYPE_CHECKING

import numpy as np

from pinarms.errors import InvalidInput

from pinarms.viz._meshcat import meshcat, mg
from pinarms.viz.cloud_scene import draw_clouds, cloud_colorbar
from pinarms.viz.names import SCENE_ROOT
from pinarms.viz.page import PAGE_PROPERTY
from pinarms.viz.scene_options import SceneOptions
from pinarms.viz.robot_drawing import RobotDrawing
from pinarms.viz.shapes import downsample_polyline, floor_grid, frame_view, transform_points, tube_mesh
from pinarms.viz.trajectory_scene import animate_scene, animated_trajectories, show_start_poses, world_tcp_paths

if TYPE_CHECKING:
    from pinarms.viz.session import Session

__all__ = ["SceneInfo", "build_scene", "ROOT"]

ROOT = SCENE_ROOT
_BACKGROUND = ([0.96, 0.97, 0.99], [0.74, 0.78, 0.85])  # top, bottom (RGB in [0, 1])

_PATH_COLORS = (0xD62728, 0x1F77B4, 0x2CA02C, 0xFF7F0E, 0x9467BD, 0x8C564B)
_POINT_COLORS = {"via": 0xFF7F0E, "target": 0xD62728, "contact": 0xFF0000}


@dataclass(frozen=True)
class SceneInfo:
    """What :func:`build_scene` drew.

    Attributes:
        robots: robot key → scene paths of its visual geometries.
        objects: object name → scene path.
        clouds: workspace name → scene path.
        paths: trajectory name → scene path of its TCP line.
        points: point-set name → scene paths of its spheres.
        animated: names of the animated trajectories.
        duration: animation length (s); 0 when nothing is animated.
        n_frames: animation frames.
        fps: animation frame rate (1/s).
        bounds: world bounding box of the content, ((3,), (3,)) m.
        target: the point the view is centred on and orbits around (world, m): the middle
            of the robots and their tcp paths (not of the clouds or boxes).
        camera: where the camera opens (world, m).
        page: what the page around the scene shows (see :mod:`pinarms.viz.page`).
        reachability: reachability map name → scene paths of its voxel layers (lowest first).
    """

    robots: dict[str, list[str]]
    objects: dict[str, str]
    clouds: dict[str, str]
    paths: dict[str, str]
    points: dict[str, list[str]]
    animated: tuple[str, ...]
    duration: float
    n_frames: int
    fps: float
    bounds: tuple[np.ndarray, np.ndarray]
    target: np.ndarray
    camera: np.ndarray
    page: dict[str, Any]
    reachability: dict[str, list[str]] = field(default_factory=dict)


def _sphere_set(vis: meshcat.Visualizer, base: str, points: np.ndarray, radius: float, color: int) -> list[str]:
    paths = []
    for i, p in enumerate(points):
        path = f"{base}/{i}"
        vis[path].set_object(mg.Sphere(radius), mg.MeshLambertMaterial(color=color))
        vis[path].set_transform(meshcat.transformations.translation_matrix(p))
        paths.append(path)
    return paths


def build_scene(vis: meshcat.Visualizer, session: Session, options: SceneOptions | None = None) -> SceneInfo:
    """Draw ``session`` into the MeshCat visualizer ``vis``; return what was drawn.

    The view opens framed on the robots and their tcp paths (clouds and boxes may extend
    beyond it), clouds translucent, the animation looping.

    Args:
        vis: a ``meshcat.Visualizer`` (e.g. ``viz.MeshcatServer().visualizer``).
        session: a :class:`pinarms.viz.Session`.
        options: what to animate and how to draw (:class:`pinarms.viz.scene_options.SceneOptions`;
            default ``SceneOptions()``).
    """
    o = SceneOptions() if options is None else options
    if not isinstance(o, SceneOptions):
        raise InvalidInput(f"options must be a viz.SceneOptions, got {type(o).__name__}")
    vis[ROOT].delete()
    bounds: list[np.ndarray] = []
    framed: list[np.ndarray] = []  # what the view is centred on: robots and tcp paths
    drawings = _draw_robots(vis, session, bounds)
    _draw_boxes(vis, session, bounds)
    clouds = draw_clouds(vis, session, ROOT, bounds, colormap=o.colormap, point_pixels=o.point_pixels,
                          cloud_opacity=o.cloud_opacity, show_clouds=o.show_clouds, max_cloud_points=o.max_cloud_points)
    from pinarms.viz.reach_scene import draw_reachability  # voxel layers coloured by reachability index

    reach_paths, reach_page = draw_reachability(vis, session, ROOT, bounds)
    from pinarms.viz.line_scene import draw_lines  # belt lines: belt, items

    line_lines = draw_lines(vis, session, ROOT, bounds)
    delta_lines: list[str] = []
    if getattr(session, "deltas", None):  # deltas: the closed chain from the actuated angles (imported when needed)
        from pinarms.viz.delta_scene import draw_session_deltas

        delta_lines = draw_session_deltas(vis, session, bounds, framed)
    moving = any(rec.duration > 0 for rec in getattr(session, "deltas", {}).values())
    line_arms = {k for rec in getattr(session, "lines", {}).values() for k in rec.arms}  # summarised once
    tcp_paths, knots = world_tcp_paths(session, drawings, bounds, framed)
    animated = animated_trajectories(session, o.animate)
    show_start_poses(session, drawings, animated, framed)

    lo, hi, target, camera, radius = _frame(session, bounds, framed, tcp_paths)

    sphere_radius = max(0.012, 0.015 * radius) if o.sphere_radius is None else o.sphere_radius
    points = {name: _sphere_set(vis, f"{ROOT}/points/{name}", _point_set_world(session, name), sphere_radius,
                                _POINT_COLORS[ps.kind]) for name, ps in session.point_sets.items()}
    paths = _draw_tcp_paths(vis, tcp_paths, knots, sphere_radius)

    duration, n_frames = animate_scene(vis, session, ROOT, drawings, animated, bool(line_lines) or moving, o.fps,
                                       o.play)

    _place_camera(vis, camera)
    floor_note = _dress_stage(vis, np.vstack(framed) if framed else np.vstack([lo, hi]), o.hide_background)
    page = {
        "title": session.title or "pinarms session",
        "lines": (_summary_lines(session, animated, clouds.shown, line_arms) + line_lines
                  + [x for x, key in zip(delta_lines, session.deltas) if key not in line_arms] + [floor_note]),
        "target": target.tolist(), "camera": camera.tolist(),
        "clouds": list(clouds.paths.values()), "clouds_visible": bool(o.show_clouds),
        "animation": {"duration": duration, "playing": bool(o.play and (animated or line_lines or moving))},
        "colorbar": cloud_colorbar(session, clouds, o.colormap),
    }
    if reach_page:
        page["reachability"] = reach_page
    vis[ROOT].set_property(PAGE_PROPERTY, json.dumps(page, ensure_ascii=False))

    all_points = {**{f"vias:{k}": v for k, v in knots.items()}, **points}
    return SceneInfo(
        robots={k: d.geometry_paths for k, d in drawings.items()},
        objects={n: f"{ROOT}/objects/{n}" for n in session.objects},
        clouds=clouds.paths, paths=paths, points=all_points, animated=animated, duration=duration,
        n_frames=n_frames, fps=float(o.fps), bounds=(lo, hi), target=target, camera=camera, page=page,
        reachability=reach_paths,
    )


def _draw_robots(vis: meshcat.Visualizer, session: Any, bounds: list[np.ndarray]) -> dict[str, RobotDrawing]:
    """Each robot's visual geometry at its base placement (the bases join ``bounds``)."""
    drawings: dict[str, RobotDrawing] = {}
    for key, entry in session.robots.items():
        robot = session.robot(key)
        dirs = session.package_dirs_override if session.package_dirs_override is not None else robot.package_dirs
        drawings[key] = RobotDrawing(vis, robot, key, entry.base_to_world, dirs, ROOT)
        bounds.append(entry.base_to_world[None, :3, 3])
    return drawings


def _draw_boxes(vis: meshcat.Visualizer, session: Any, bounds: list[np.ndarray]) -> None:
    """The static boxes in their colours (their corners join ``bounds``)."""
    for name, box in session.objects.items():
        r, g, b, a = box.color
        mat = mg.MeshLambertMaterial(color=int(r * 255) << 16 | int(g * 255) << 8 | int(b * 255),
                                     opacity=a, transparent=a < 1.0)
        vis[f"{ROOT}/objects/{name}"].set_object(mg.Box(box.size.tolist()), mat)
        vis[f"{ROOT}/objects/{name}"].set_transform(box.pose)
        corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T * box.size / 2
        bounds.append(transform_points(box.pose, corners))


def _draw_tcp_paths(vis: meshcat.Visualizer, tcp_paths: dict[str, np.ndarray], knots: dict[str, Any],
                    sphere_radius: float) -> dict[str, str]:
    """Each tcp path as a tube (a dot when the tcp stands still), its knots as spheres (``knots`` → their paths)."""
    tube = sphere_radius / 2.5
    paths = {}
    for i, (name, tcp) in enumerate(tcp_paths.items()):
        path = f"{ROOT}/paths/{name}"
        color = _PATH_COLORS[i % len(_PATH_COLORS)]
        mesh = tube_mesh(downsample_polyline(tcp), tube)
        if mesh is None:  # the tcp stands still: a dot
            vis[path].set_object(mg.Sphere(2.0 * tube), mg.MeshLambertMaterial(color=color))
            vis[path].set_transform(meshcat.transformations.translation_matrix(tcp[0]))
        else:
            vis[path].set_object(mg.TriangularMeshGeometry(*mesh), mg.MeshLambertMaterial(color=color))
        paths[name] = path
        knots[name] = _sphere_set(vis, f"{ROOT}/vias/{name}", knots[name], sphere_radius, color)
    return paths


def _frame(session: Any, bounds: list[np.ndarray], framed: list[np.ndarray],
           tcp_paths: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """``(lo, hi)`` of everything drawn and the view ``(target, camera, radius)`` framed on the robots and paths."""
    from pinarms.viz.line_scene import line_focus  # a long belt line: its first arms

    parts = bounds + [_point_set_world(session, n) for n in session.point_sets]
    everything = np.vstack(parts) if parts else np.zeros((1, 3))
    lo, hi = everything.min(axis=0), everything.max(axis=0)
    bases = np.array([e.base_to_world[:3, 3] for e in session.robots.values()]).reshape(-1, 3)
    toward = np.vstack(list(tcp_paths.values())).mean(axis=0) - bases.mean(axis=0) if tcp_paths and bases.size else None
    target, camera, radius = frame_view(line_focus(session, np.vstack(framed) if framed else everything), toward)
    return lo, hi, target, camera, radius


def _dress_stage(vis: meshcat.Visualizer, content: np.ndarray, hide_background: bool) -> str:
    """Background colours and a floor grid sized to ``content`` (world, m); return the page's line about the floor.

    The floor is at z = 0, or under the lowest point of a suspended arm (most of it below
    its base) and its path.
    """
    vis["/Background"].set_property("top_color", _BACKGROUND[0])
    vis["/Background"].set_property("bottom_color", _BACKGROUND[1])
    suspended = np.median(content[:, 2]) < 0.0 and content[:, 2].min() < -0.05
    floor_z = float(np.floor(content[:, 2].min() / 0.1) * 0.1) if suspended else 0.0
    grid, grid_step = floor_grid(content.min(axis=0), content.max(axis=0), floor_z)
    vis["/Grid"].set_property("visible", False)  # MeshCat's 20 m grid: replaced by one sized to the content
    vis[f"{ROOT}/floor"].set_object(mg.LineSegments(mg.PointsGeometry(grid.T.astype(np.float32)),
                                                    mg.LineBasicMaterial(color=0xA0A8B4)))
    if hide_background:
        for node in ("/Background", "/Axes", f"{ROOT}/floor"):
            vis[node].set_property("visible", False)
    return f"floor grid: {grid_step * 100:.0f} cm squares at z = {floor_z:+.1f} m"


def _point_set_world(session: Any, name: str) -> np.ndarray:
    """Points of the session's point set ``name`` in the world frame, ``(n, 3)`` [m]."""
    ps = session.point_sets[name]
    T = np.eye(4) if ps.robot is None else session.robots[ps.robot].base_to_world
    return transform_points(T, ps.points)


def _summary_lines(session: Any, animated: tuple[str, ...], cloud_shown: dict[str, tuple[int, int]],
                   line_arms: set[str] = frozenset()) -> list[str]:
    """One line per robot (its name and DoF), trajectory (duration; ▶ when animated) and cloud;
    the arms of a belt line (``line_arms``) and their trajectories in one line."""
    lines = []
    if line_arms:
        names = sorted({session.robots[k].name for k in line_arms if k in session.robots}
                       | {session.deltas[k].delta for k in line_arms if k in getattr(session, "deltas", {})})
        lines.append(f"{len(line_arms)} arms along the belt ({', '.join(names)}), each through its picks")
    for key, entry in session.robots.items():
        if key in line_arms:
            continue
        robot = session.robot(key)
        label = entry.name if key == entry.name else f"{key} ({entry.name})"
        lines.append(f"robot {label}: {robot.nq} joints")
    for name, rec in session.trajectories.items():
        if rec.robot in line_arms:
            continue
        mark = "▶ " if name in animated else ""
        lines.append(f"{mark}{name}: {float(rec.t[-1] - rec.t[0]):.3g} s")
    for name, (shown, total) in cloud_shown.items():
        lines.append(f"cloud {name}: {total} samples" if shown == total else f"cloud {name}: {shown} of {total} samples shown")
    return lines


def _place_camera(vis: meshcat.Visualizer, camera: np.ndarray) -> None:
    """Put MeshCat's camera at ``camera`` (world, m).

    The camera object sits in a y-up frame (three.js), so the world point (x, y, z) is
    written (x, z, -y). MeshCat orbits around the world origin; the page script
    (:mod:`pinarms.viz.page`) moves the orbit's centre to the framed target.
    """
    x, y, z = (float(v) for v in camera)
    vis["/Cameras/default/rotated/<object>"].set_property("position", [x, z, -y])
