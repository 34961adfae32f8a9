"""A MeshCat scene built from a :class:`viz.Session`.

Scene paths (under MeshCat's root ``/meshcat``), readable and stable:

- ``pinarms/robots/<key>`` — a robot, placed at its ``base_to_world``; its visual geometry
  (Pinocchio's visual model of the URDF) in ``pinarms/robots/<key>/visuals/<geometry>``;
- ``pinarms/objects/<name>`` — static boxes (conveyor, crate);
- ``pinarms/workspace/<name>`` — a workspace cloud (``Points``, translucent) coloured by
  manipulability;
- ``pinarms/paths/<name>`` — the TCP path of a trajectory, world frame: a thin tube
  (``Mesh``), since browsers draw WebGL lines one pixel wide whatever their width;
- ``pinarms/vias/<name>/<i>`` — the TCP at the trajectory's knots (small spheres);
- ``pinarms/points/<name>/<i>`` — via points / targets of the session (small spheres);
- ``pinarms/reachability/<name>/layers/z<mm>mm`` — reachability maps: the voxels of one
  horizontal layer each (:mod:`viz.reach_scene`; the page's slice control shows/hides them).

One MeshCat animation per scene: the chosen trajectories (default: the first one of each
robot) play together from time 0, sampled at ``fps`` frames per second, looping.

What the page around the scene shows (title, colour bar, framing, controls: see
:mod:`viz.page`) is stored on the scene root as the property ``pinarms_page`` (JSON), so
that the standalone page and the live viewer read it the same way.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass, field
from typing import Any, Sequence

import matplotlib
import numpy as np
import pinocchio as pin

from pinarms.robots.errors import InvalidInput

from ._meshcat import MeshcatVisualizer, meshcat, mg
from .errors import ViewerError
from .page import PAGE_PROPERTY, colorbar_stops, manipulability_unit
from .shapes import downsample_polyline, floor_grid, frame_view, tube_mesh

__all__ = ["SceneInfo", "build_scene", "ROOT", "colors_by_value"]

ROOT = "pinarms"
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
        page: what the page around the scene shows (see :mod:`viz.page`).
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

    def extent(self, qs: np.ndarray) -> np.ndarray:
        """Corners of the visual geometries' boxes at each row of ``qs (F, nq)``, ``(8kF, 3)`` in the base frame [m].

        A geometry whose box is unknown contributes its origin. The displayed pose is untouched.
        """
        model, gmodel = self.pv.model, self.pv.visual_model
        data, gdata = model.createData(), gmodel.createData()
        signs = np.array(np.meshgrid([0, 1], [0, 1], [0, 1])).reshape(3, -1).T
        local = []
        for g in gmodel.geometryObjects:
            try:
                g.geometry.computeLocalAABB()
                lo, hi = np.asarray(g.geometry.aabb_local.min_), np.asarray(g.geometry.aabb_local.max_)
                local.append((lo + signs * (hi - lo)) * np.asarray(g.meshScale))
            except Exception:  # noqa: BLE001 - a geometry coal cannot bound: its origin only
                local.append(np.zeros((1, 3)))
        corners = [np.zeros((1, 3))]
        for qp in np.atleast_2d(self.robot.q_to_pinocchio(qs)):
            pin.forwardKinematics(model, data, qp)
            pin.updateGeometryPlacements(model, data, gmodel, gdata)
            corners += [box @ M.rotation.T + M.translation for box, M in zip(local, gdata.oMg)]
        return np.vstack(corners)

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


def build_scene(
    vis: meshcat.Visualizer,
    session: Any,
    *,
    animate: Sequence[str] | None = None,
    fps: float = 30.0,
    play: bool = True,
    point_pixels: float = 3.0,
    cloud_opacity: float = 0.3,
    show_clouds: bool = True,
    max_cloud_points: int = 20_000,
    sphere_radius: float | None = None,
    colormap: str = "viridis",
    hide_background: bool = False,
) -> SceneInfo:
    """Draw ``session`` into the MeshCat visualizer ``vis``; return what was drawn.

    The view opens framed on the robots and their tcp paths (clouds and boxes may extend
    beyond it), clouds translucent, the animation looping.

    Args:
        vis: a ``meshcat.Visualizer`` (e.g. ``viz.MeshcatServer().visualizer``).
        session: a :class:`viz.Session`.
        animate: trajectory names to animate (at most one per robot); default: the first
            trajectory of each robot; ``()`` for no animation.
        fps: animation frame rate (1/s).
        play: start playing (looping) when a browser opens the page.
        point_pixels: size of the workspace points on screen [px]; cloud_opacity: their
            opacity in (0, 1];
            show_clouds: whether the clouds are shown when the page opens (the page has a
            switch either way); max_cloud_points: a larger cloud is drawn as a seeded
            uniform subsample of that many points (the page says so; the session keeps all).
        sphere_radius: via-point sphere radius (m); default 1.5 % of the framed radius, at
            least 12 mm; the tcp path tube's radius is 40 % of it.
        colormap: matplotlib colormap for manipulability (low → high).
        hide_background: hide MeshCat's background, grid and axes (plain white page).
    """
    if not (np.isfinite(fps) and fps > 0):
        raise InvalidInput(f"fps must be a positive frame rate in 1/s, got {fps!r}")
    if colormap not in matplotlib.colormaps:
        raise InvalidInput(f"unknown matplotlib colormap {colormap!r}")
    if not (isinstance(cloud_opacity, (int, float)) and 0.0 < cloud_opacity <= 1.0):
        raise InvalidInput(f"cloud_opacity must be in (0, 1], got {cloud_opacity!r}")
    for name, value, unit in (("point_pixels", point_pixels, "px"), ("sphere_radius", sphere_radius, "m")):
        if value is None and name == "sphere_radius":
            continue
        if isinstance(value, bool) or not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
            raise InvalidInput(f"{name} must be a positive size in {unit}, got {value!r}")
    if isinstance(max_cloud_points, bool) or not isinstance(max_cloud_points, (int, np.integer)) or max_cloud_points < 1:
        raise InvalidInput(f"max_cloud_points must be a positive integer, got {max_cloud_points!r}")
    vis[ROOT].delete()
    bounds: list[np.ndarray] = []
    framed: list[np.ndarray] = []  # what the view is centred on: robots and tcp paths

    # robots
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

    clouds, cloud_robots, cloud_shown, w_max = {}, [], {}, 0.0
    for name, ws in session.workspaces.items():
        world = _transform_points(session.robots[ws.robot].base_to_world, ws.points)
        colors = colors_by_value(ws.manipulability, colormap)  # scaled by the whole cloud's maximum
        shown = np.arange(world.shape[0])
        if world.shape[0] > max_cloud_points:
            shown = np.sort(np.random.default_rng(0).choice(world.shape[0], size=int(max_cloud_points), replace=False))
        cloud_shown[name] = (shown.size, world.shape[0])
        path = f"{ROOT}/workspace/{name}"
        vis[path].set_object(mg.Points(
            mg.PointsGeometry(world[shown].T.astype(np.float32), colors[shown].T.astype(np.float32)),
            _CloudMaterial(point_pixels, cloud_opacity)))
        if not show_clouds:
            vis[path].set_property("visible", False)
        clouds[name] = path
        cloud_robots.append(ws.robot)
        w_max = max(w_max, float(np.max(ws.manipulability)))
        bounds.append(world)

    from .reach_scene import draw_reachability  # voxel layers coloured by reachability index

    reach_paths, reach_page = draw_reachability(vis, session, ROOT, bounds)
    from .line_scene import animate_lines, draw_lines, line_duration  # belt lines: belt, items

    line_lines = draw_lines(vis, session, ROOT, bounds)
    line_arms = {k for rec in getattr(session, "lines", {}).values() for k in rec.arms}  # summarised once

    paths, knots_drawn, tcp_paths = {}, {}, {}
    for i, (name, rec) in enumerate(session.trajectories.items()):
        robot = drawings[rec.robot].robot
        T_base = session.robots[rec.robot].base_to_world
        q_knots = _interp_rows(rec.knot_times, rec.t, rec.q)
        # a cell: one tcp path per arm; a robot: its tcp
        frames = {arm: f for arm, f in session.cell_tcp_frames(rec.robot).items() if f in robot.frame_names}
        for arm, frame in (frames.items() if frames else [(None, "tcp")]):
            label = name if arm is None else f"{name}: {arm}"
            tcp_paths[label] = _transform_points(T_base, robot.position(rec.q, frame))
            knots_drawn[label] = _transform_points(T_base, robot.position(q_knots, frame))
            bounds.append(tcp_paths[label])
            framed.append(tcp_paths[label])

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
        # framed over the whole motion: the pose at 9 instants of its (first) trajectory
        poses = recs[0].q[np.linspace(0, recs[0].q.shape[0] - 1, 9).round().astype(int)] if recs else drawing.robot.neutral
        framed.append(_transform_points(session.robots[key].base_to_world, drawing.extent(poses)))

    parts = bounds + [_point_set_world(session, n) for n in session.point_sets]
    everything = np.vstack(parts) if parts else np.zeros((1, 3))
    lo, hi = everything.min(axis=0), everything.max(axis=0)
    bases = np.array([e.base_to_world[:3, 3] for e in session.robots.values()]).reshape(-1, 3)
    toward = np.vstack(list(tcp_paths.values())).mean(axis=0) - bases.mean(axis=0) if tcp_paths and bases.size else None
    from .line_scene import line_focus  # a long belt line: its first arms

    target, camera, radius = frame_view(line_focus(session, np.vstack(framed) if framed else everything), toward)

    if sphere_radius is None:
        sphere_radius = max(0.012, 0.015 * radius)
    tube = sphere_radius / 2.5
    points = {}
    for name, ps in session.point_sets.items():
        points[name] = _sphere_set(vis, f"{ROOT}/points/{name}", _point_set_world(session, name), sphere_radius,
                                   _POINT_COLORS[ps.kind])
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
        knots_drawn[name] = _sphere_set(vis, f"{ROOT}/vias/{name}", knots_drawn[name], sphere_radius, color)

    duration, n_frames = 0.0, 0
    if animated or line_lines:
        duration = max([float(session.trajectories[n].t[-1] - session.trajectories[n].t[0]) for n in animated]
                       + [line_duration(session)])
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
        animate_lines(vis, anim, session, ROOT, times, animated, drawings)
        vis.set_animation(anim, play=play, repetitions=float("inf"))

    _place_camera(vis, camera)
    vis["/Background"].set_property("top_color", _BACKGROUND[0])
    vis["/Background"].set_property("bottom_color", _BACKGROUND[1])
    # the floor: at z = 0, or under the lowest point of a suspended arm (most of it below its base) and its path
    content = np.vstack(framed) if framed else np.vstack([lo, hi])
    suspended = np.median(content[:, 2]) < 0.0 and content[:, 2].min() < -0.05
    floor_z = float(np.floor(content[:, 2].min() / 0.1) * 0.1) if suspended else 0.0
    grid, grid_step = floor_grid(content.min(axis=0), content.max(axis=0), floor_z)
    vis["/Grid"].set_property("visible", False)  # MeshCat's 20 m grid: replaced by one sized to the content
    vis[f"{ROOT}/floor"].set_object(mg.LineSegments(mg.PointsGeometry(grid.T.astype(np.float32)),
                                                    mg.LineBasicMaterial(color=0xA0A8B4)))
    if hide_background:
        for node in ("/Background", "/Axes", f"{ROOT}/floor"):
            vis[node].set_property("visible", False)

    page = {
        "title": session.title or "pinarms session",
        "lines": _summary_lines(session, animated, cloud_shown, line_arms) + line_lines + [f"floor grid: {grid_step * 100:.0f} cm squares at z = {floor_z:+.1f} m"],
        "target": target.tolist(),
        "camera": camera.tolist(),
        "clouds": list(clouds.values()),
        "clouds_visible": bool(show_clouds),
        "animation": {"duration": duration, "playing": bool(play and (animated or line_lines))},
        "colorbar": None,
    }
    if clouds:
        units = {manipulability_unit(session.robot(k).joint_units) for k in cloud_robots}
        page["colorbar"] = {
            "label": "position manipulability √det(J_v J_vᵀ)",
            "unit": units.pop() if len(units) == 1 else "",
            "min": 0.0,
            "max": w_max,
            "colors": colorbar_stops(colormap),
        }
    if reach_page:
        page["reachability"] = reach_page
    vis[ROOT].set_property(PAGE_PROPERTY, json.dumps(page, ensure_ascii=False))

    all_points = {**{f"vias:{k}": v for k, v in knots_drawn.items()}, **points}
    return SceneInfo(
        robots={k: d.geometry_paths for k, d in drawings.items()},
        objects={n: f"{ROOT}/objects/{n}" for n in session.objects},
        clouds=clouds, paths=paths, points=all_points, animated=animated, duration=duration,
        n_frames=n_frames, fps=float(fps), bounds=(lo, hi), target=target, camera=camera, page=page,
        reachability=reach_paths,
    )


def _point_set_world(session: Any, name: str) -> np.ndarray:
    """Points of the session's point set ``name`` in the world frame, ``(n, 3)`` [m]."""
    ps = session.point_sets[name]
    T = np.eye(4) if ps.robot is None else session.robots[ps.robot].base_to_world
    return _transform_points(T, ps.points)


def _summary_lines(session: Any, animated: tuple[str, ...], cloud_shown: dict[str, tuple[int, int]],
                   line_arms: set[str] = frozenset()) -> list[str]:
    """One line per robot (its name and DoF), trajectory (duration; ▶ when animated) and cloud;
    the arms of a belt line (``line_arms``) and their trajectories in one line."""
    lines = []
    if line_arms:
        names = sorted({session.robots[k].name for k in line_arms if k in session.robots})
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
    (:mod:`viz.page`) moves the orbit's centre to the framed target.
    """
    x, y, z = (float(v) for v in camera)
    vis["/Cameras/default/rotated/<object>"].set_property("position", [x, z, -y])
