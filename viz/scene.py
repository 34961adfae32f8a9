"""A MeshCat scene built from a :class:`viz.Session`.

Scene paths (under MeshCat's root ``/meshcat``), readable and stable:

- ``pinarms/robots/<key>`` — a robot, placed at its ``base_to_world``; its visual geometry
  (Pinocchio's visual model of the URDF) in ``pinarms/robots/<key>/visuals/<geometry>``;
- ``pinarms/objects/<name>`` — static boxes (conveyor, crate);
- ``pinarms/workspace/<name>`` — a workspace cloud (``Points``) coloured by manipulability;
- ``pinarms/paths/<name>`` — the TCP path of a trajectory (``Line``), world frame;
- ``pinarms/vias/<name>/<i>`` — the TCP at the trajectory's knots (small spheres);
- ``pinarms/points/<name>/<i>`` — via points / targets of the session (small spheres).
- ``pinarms/reachability/<name>/...`` — reachability maps: voxel layers and a colour bar
  (:mod:`viz.reach_scene`).

One MeshCat animation per scene: the chosen trajectories (default: the first one of each
robot) play together from time 0, sampled at ``fps`` frames per second.
"""

from __future__ import annotations

import contextlib
import io
import warnings
from dataclasses import dataclass, field
from typing import Any, Sequence

import matplotlib
import numpy as np
import pinocchio as pin

from pinarms.robots.errors import InvalidInput

from ._meshcat import MeshcatVisualizer, meshcat, mg
from .errors import ViewerError

__all__ = ["SceneInfo", "build_scene", "ROOT", "colors_by_value"]

ROOT = "pinarms"

_PATH_COLORS = (0xD62728, 0x1F77B4, 0x2CA02C, 0xFF7F0E, 0x9467BD, 0x8C564B)
_POINT_COLORS = {"via": 0xFF7F0E, "target": 0xD62728}


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
        reachability: reachability map name → scene paths of its voxel layers and colour bar.
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
    reachability: dict[str, list[str]] = field(default_factory=dict)


def colors_by_value(values: np.ndarray, colormap: str = "viridis") -> np.ndarray:
    """RGB colours (N, 3) in [0, 1] of ``values`` scaled by their maximum (0 → low end of the colormap)."""
    v = np.asarray(values, dtype=float)
    top = v.max() if v.size else 0.0
    x = v / top if top > 0 else np.zeros_like(v)
    return np.asarray(matplotlib.colormaps[colormap](x))[:, :3]


def _transform_points(T: np.ndarray, p: np.ndarray) -> np.ndarray:
    return p @ T[:3, :3].T + T[:3, 3]


def _interp_rows(t_new: np.ndarray, t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Linear interpolation of each column of ``q (N, n)`` at ``t_new`` (held at the ends)."""
    return np.stack([np.interp(t_new, t, q[:, j]) for j in range(q.shape[1])], axis=1)


class _RobotDrawing:
    """One robot's visual geometry in the scene, driven by Pinocchio's MeshcatVisualizer."""

    def __init__(self, vis: meshcat.Visualizer, robot: Any, key: str, base_to_world: np.ndarray,
                 package_dirs: Sequence[str]) -> None:
        self.robot = robot
        self.root = f"{ROOT}/robots/{key}"
        try:
            visual_model = pin.buildGeomFromUrdfString(
                robot.model, robot.urdf_text, pin.GeometryType.VISUAL, package_dirs=list(package_dirs)
            )
        except Exception as exc:  # Pinocchio raises ValueError/RuntimeError for missing meshes
            raise ViewerError(
                f"cannot build the visual geometry of robot {key!r}: {exc}; if its meshes moved, "
                "pass package_dirs=... to viz.load_session"
            ) from exc
        self.pv = MeshcatVisualizer(robot.model, None, visual_model)
        self.pv.initViewer(viewer=vis)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # unsupported geometry is skipped, not fatal
            self.pv.loadViewerModel(rootNodeName=self.root)
        vis[self.root].set_transform(base_to_world)
        self.geometry_paths = [self.pv.getViewerNodeName(g, pin.GeometryType.VISUAL)
                               for g in visual_model.geometryObjects]

    def display(self, q: np.ndarray) -> None:
        """Show configuration ``q (nq,)``."""
        self.pv.display(self.robot.q_to_pinocchio(q))

    def record(self, anim: meshcat.animation.Animation, vis: meshcat.Visualizer, qs: np.ndarray) -> None:
        """Add one key frame per row of ``qs (F, nq)`` to ``anim`` (rigid poses: tracks hold position + rotation)."""
        model, data = self.pv.model, self.pv.data
        gmodel, gdata = self.pv.visual_model, self.pv.visual_data
        qp = self.robot.q_to_pinocchio(qs)
        ids = [gmodel.getGeometryId(g.name) for g in gmodel.geometryObjects]
        for i in range(qp.shape[0]):
            pin.forwardKinematics(model, data, qp[i])
            pin.updateGeometryPlacements(model, data, gmodel, gdata)
            with anim.at_frame(vis, i) as frame:
                for path, gid in zip(self.geometry_paths, ids):
                    frame[path].set_transform(gdata.oMg[gid].homogeneous)


def _sphere_set(vis: meshcat.Visualizer, base: str, points: np.ndarray, radius: float, color: int) -> list[str]:
    paths = []
    for i, p in enumerate(points):
        path = f"{base}/{i}"
        vis[path].set_object(mg.Sphere(radius), mg.MeshLambertMaterial(color=color))
        vis[path].set_transform(meshcat.transformations.translation_matrix(p))
        paths.append(path)
    return paths


def build_scene(
    vis: meshcat.Visualizer,
    session: Any,
    *,
    animate: Sequence[str] | None = None,
    fps: float = 30.0,
    play: bool = True,
    point_size: float = 0.012,
    sphere_radius: float = 0.012,
    colormap: str = "viridis",
    hide_background: bool = False,
) -> SceneInfo:
    """Draw ``session`` into the MeshCat visualizer ``vis``; return what was drawn.

    Args:
        vis: a ``meshcat.Visualizer`` (e.g. ``viz.viewer.MeshcatServer().visualizer``).
        session: a :class:`viz.Session`.
        animate: trajectory names to animate (at most one per robot); default: the first
            trajectory of each robot; ``()`` for no animation.
        fps: animation frame rate (1/s).
        play: start playing when a browser opens the page.
        point_size: workspace point size (m); sphere_radius: via-point sphere radius (m).
        colormap: matplotlib colormap for manipulability (low → high).
        hide_background: hide MeshCat's background, grid and axes (plain white page).
    """
    if not (np.isfinite(fps) and fps > 0):
        raise InvalidInput(f"fps must be a positive frame rate in 1/s, got {fps!r}")
    if colormap not in matplotlib.colormaps:
        raise InvalidInput(f"unknown matplotlib colormap {colormap!r}")
    vis[ROOT].delete()
    bounds: list[np.ndarray] = []

    # robots and their TCP paths
    drawings: dict[str, _RobotDrawing] = {}
    for key, entry in session.robots.items():
        robot = session.robot(key)
        dirs = session.package_dirs_override if session.package_dirs_override is not None else robot.package_dirs
        drawings[key] = _RobotDrawing(vis, robot, key, entry.base_to_world, dirs)
        bounds.append(entry.base_to_world[None, :3, 3])

    for name, box in session.objects.items():
        r, g, b, a = box.color
        mat = mg.MeshLambertMaterial(color=int(r * 255) << 16 | int(g * 255) << 8 | int(b * 255),
                                     opacity=a, transparent=a < 1.0)
        vis[f"{ROOT}/objects/{name}"].set_object(mg.Box(box.size.tolist()), mat)
        vis[f"{ROOT}/objects/{name}"].set_transform(box.pose)
        corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T * box.size / 2
        bounds.append(_transform_points(box.pose, corners))

    clouds = {}
    for name, ws in session.workspaces.items():
        world = _transform_points(session.robots[ws.robot].base_to_world, ws.points)
        path = f"{ROOT}/workspace/{name}"
        vis[path].set_object(mg.PointCloud(world.T.astype(np.float32),
                                           colors_by_value(ws.manipulability, colormap).T.astype(np.float32),
                                           size=point_size))
        clouds[name] = path
        bounds.append(world)

    from .reach_scene import draw_reachability  # coloured voxel layers and a colour bar per map

    reach_paths = draw_reachability(vis, session, ROOT, bounds)

    paths, knots_drawn = {}, {}
    for i, (name, rec) in enumerate(session.trajectories.items()):
        robot = drawings[rec.robot].robot
        T_base = session.robots[rec.robot].base_to_world
        tcp = _transform_points(T_base, robot.position(rec.q))
        path = f"{ROOT}/paths/{name}"
        color = _PATH_COLORS[i % len(_PATH_COLORS)]
        vis[path].set_object(mg.Line(mg.PointsGeometry(tcp.T.astype(np.float32)),
                                     mg.LineBasicMaterial(color=color, linewidth=2)))
        paths[name] = path
        q_knots = _interp_rows(rec.knot_times, rec.t, rec.q)
        knots = _transform_points(T_base, robot.position(q_knots))
        knots_drawn[name] = _sphere_set(vis, f"{ROOT}/vias/{name}", knots, sphere_radius, color)
        bounds.append(tcp)

    points = {}
    for name, ps in session.point_sets.items():
        T = np.eye(4) if ps.robot is None else session.robots[ps.robot].base_to_world
        world = _transform_points(T, ps.points)
        points[name] = _sphere_set(vis, f"{ROOT}/points/{name}", world, sphere_radius, _POINT_COLORS[ps.kind])
        bounds.append(world)

    # which trajectories play
    if animate is None:
        chosen: dict[str, str] = {}
        for name, rec in session.trajectories.items():
            chosen.setdefault(rec.robot, name)
        animated = tuple(chosen.values())
    else:
        animated = tuple(animate)
        unknown = [n for n in animated if n not in session.trajectories]
        if unknown:
            raise InvalidInput(f"cannot animate {unknown}: trajectories are {list(session.trajectories)}")
        owners = [session.trajectories[n].robot for n in animated]
        if len(set(owners)) != len(owners):
            raise InvalidInput(f"animate at most one trajectory per robot; got {list(animated)} (robots {owners})")

    # static pose: start of the animated (else first) trajectory, else the neutral pose
    for key, drawing in drawings.items():
        recs = [session.trajectories[n] for n in animated if session.trajectories[n].robot == key]
        recs = recs or [r for r in session.trajectories.values() if r.robot == key]
        drawing.display(recs[0].q[0] if recs else drawing.robot.neutral)

    duration, n_frames = 0.0, 0
    if animated:
        duration = max(float(session.trajectories[n].t[-1] - session.trajectories[n].t[0]) for n in animated)
        n_frames = int(np.floor(duration * fps + 1e-9)) + 1
        times = np.minimum(np.arange(n_frames) / fps, duration)
        if times[-1] < duration:  # end exactly on the last pose
            times = np.append(times, duration)
            n_frames += 1
        anim = meshcat.animation.Animation(default_framerate=fps)
        for name in animated:
            rec = session.trajectories[name]
            qs = _interp_rows(rec.t[0] + times, rec.t, rec.q)
            drawings[rec.robot].record(anim, vis, qs)
        vis.set_animation(anim, play=play, repetitions=1)

    lo = np.min(np.vstack(bounds), axis=0) if bounds else np.zeros(3)
    hi = np.max(np.vstack(bounds), axis=0) if bounds else np.zeros(3)
    _place_camera(vis, lo, hi)
    if hide_background:
        for node in ("/Background", "/Grid", "/Axes"):
            vis[node].set_property("visible", False)
    all_points = {**{f"vias:{k}": v for k, v in knots_drawn.items()}, **points}
    return SceneInfo(
        robots={k: d.geometry_paths for k, d in drawings.items()},
        objects={n: f"{ROOT}/objects/{n}" for n in session.objects},
        clouds=clouds, paths=paths, points=all_points, animated=animated, duration=duration,
        n_frames=n_frames, fps=float(fps), bounds=(lo, hi), reachability=reach_paths,
    )


def _place_camera(vis: meshcat.Visualizer, lo: np.ndarray, hi: np.ndarray) -> None:
    """Look at the world origin from the front-right, far enough to see the content's bounding box.

    MeshCat 0.3.2 orbits around the world origin; the camera object sits in a y-up frame
    (three.js), so the world point (x, y, z) is written (x, z, -y).
    """
    reach = float(np.max(np.abs(np.vstack([lo, hi])))) if np.any(hi > lo) else 1.0
    d = 2.6 * max(reach, 0.3)
    x, y, z = 0.75 * d, -0.55 * d, 0.45 * d
    vis["/Cameras/default/rotated/<object>"].set_property("position", [x, z, -y])


def scene_html(session: Any, **options: Any) -> tuple[str, SceneInfo]:
    """The session's scene as MeshCat's self-contained static HTML (a server runs for a moment)."""
    from .viewer import MeshcatServer

    with MeshcatServer() as server, contextlib.redirect_stdout(io.StringIO()):
        info = build_scene(server.visualizer, session, **options)
        html = server.static_html()
    return html, info
