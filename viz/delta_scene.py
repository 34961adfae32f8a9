"""A delta robot drawn and animated as its closed chain: upper arms, the six rods, the platform.

The URDF's forearm is the mid-line of each parallelogram (docs/delta.md), not a body: the page
draws the two rods of every leg from :func:`pinarms.robots.delta.rod_endpoints` (the ball centres
of the tree at the closed configuration :meth:`DeltaRobot.configuration`), each upper arm from its
motor axis to its elbow (:func:`~pinarms.robots.delta.elbow_positions`) and the platform at the
closed-form forward position (:func:`~pinarms.robots.delta.forward_position`).

Scene paths, under ``pinarms/deltas/<name>``: ``upper_arm_<i>``, ``rod_<i><a|b>`` (cylinders,
MeshCat's axis y along the part), ``platform`` (a disk), sized as the collision bodies
(:mod:`pinarms.robots.delta.collision`), and for a delta with the fourth axis ``tool`` (a flat
paddle from the platform centre to the tcp, turned by the tool angle, so that the turn shows).
:func:`delta_poses` gives their world transforms per frame (the scene data; no viewer needed);
:func:`draw_delta` and :func:`animate_delta` put them in a MeshCat scene; :func:`delta_page` writes
one standalone page. The deltas of a :class:`pinarms.viz.Session` (:mod:`pinarms.viz.delta_record`)
are drawn by :func:`draw_session_deltas` and animated by :func:`animate_session_deltas` in the
session's page (:mod:`pinarms.viz.scene`).
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.files import atomic_write
from pinarms.robots.delta import DeltaRobot, elbow_positions, forward_position, rod_endpoints
from pinarms.robots.delta.collision import PART_RADII, PLATFORM_THICKNESS
from pinarms.errors import InvalidInput

from pinarms.viz._meshcat import meshcat, mg
from pinarms.viz.names import SCENE_ROOT

if TYPE_CHECKING:
    from pinarms.viz.session import Session

__all__ = ["delta_poses", "delta_parts", "draw_delta", "animate_delta", "delta_page", "DELTA_ROOT", "TOOL_WIDTH",
           "draw_session_deltas", "animate_session_deltas", "session_delta_poses", "session_delta_tcp"]

#: Scene folder of the deltas.
DELTA_ROOT = f"{SCENE_ROOT}/deltas"
_COLORS = {"upper_arm": 0x4A6FA5, "rod": 0xC8C8C8, "platform": 0x8C8C8C, "tool": 0xE0A030}
#: Width of the drawn tool paddle [m] (its thickness is the tool capsule's diameter).
TOOL_WIDTH = 0.06


def _segment(p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """(F, 4, 4): a rigid frame at the segment's middle whose y axis runs p0 → p1."""
    d = p1 - p0
    y = d / np.linalg.norm(d, axis=-1, keepdims=True)
    helper = np.where(np.abs(y[..., 2:3]) < 0.9, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    x = np.cross(y, helper)
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    z = np.cross(x, y)
    T = np.zeros(p0.shape[:-1] + (4, 4))
    T[..., :3, 0], T[..., :3, 1], T[..., :3, 2], T[..., :3, 3], T[..., 3, 3] = x, y, z, 0.5 * (p0 + p1), 1.0
    return T


def delta_parts(delta: DeltaRobot) -> dict[str, tuple[str, float, float]]:
    """``{part: (kind, length [m], radius [m])}`` of every drawn part (kind: upper_arm, rod, platform)."""
    g = delta.geometry
    parts = {f"upper_arm_{i}": ("upper_arm", g.upper_arm, PART_RADII["upper_arm"]) for i in (1, 2, 3)}
    parts.update({f"rod_{i}{r}": ("rod", g.forearm, PART_RADII["rod"]) for i in (1, 2, 3) for r in "ab"})
    parts["platform"] = ("platform", PLATFORM_THICKNESS, g.platform_radius + 0.5 * g.rod_spacing)
    if delta.has_tool_axis:
        parts["tool"] = ("tool", float(np.linalg.norm(_tcp_offset(delta))), PART_RADII["tool"])
    return parts


def _tcp_offset(delta: DeltaRobot) -> np.ndarray:
    """(3,) the tcp from the platform centre at tool angle 0 [m] (Pinocchio's FK of the tree)."""
    home = delta.home()
    return delta.tcp_position(home) - forward_position(delta.geometry, home[delta.motor_q])


def _rz(a: np.ndarray) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(a.shape + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1], R[..., 2, 2] = c, -s, s, c, 1.0
    return R


def delta_poses(delta: DeltaRobot, theta: ArrayLike, base_to_world: ArrayLike | None = None,
                tool: ArrayLike | None = None) -> dict[str, np.ndarray]:
    """World transforms (F, 4, 4) of every part (module doc) at motor angles ``theta`` (F, 3) [rad] and,
    for a delta with the fourth axis, tool angles ``tool`` (F,) [rad] (default 0).

    Raises:
        InvalidInput: ``theta`` not (F, 3) finite, or a row the delta cannot assemble."""
    th = np.asarray(theta, dtype=float)
    if th.ndim != 2 or th.shape[1] != 3 or not np.all(np.isfinite(th)):
        raise InvalidInput(f"theta must be (F, 3) finite motor angles [rad], got shape {th.shape}")
    T = np.eye(4) if base_to_world is None else np.asarray(base_to_world, dtype=float)
    p = forward_position(delta.geometry, th)
    if not np.all(np.isfinite(p)):
        raise InvalidInput(f"{delta.name}: motor angles in row {int(np.flatnonzero(~np.isfinite(p[:, 0]))[0])} "
                           "do not assemble (the forearms' spheres do not meet)")
    rods = rod_endpoints(delta, delta.configuration(th))  # (F, 3 legs, 2 rods, 2 ends, 3), base frame
    elbows = elbow_positions(delta.geometry, th)          # (F, 3, 3)
    motors = delta.geometry.base_radius * delta.geometry.radial  # (3, 3)
    out: dict[str, np.ndarray] = {}
    for i in range(3):
        out[f"upper_arm_{i + 1}"] = _segment(np.broadcast_to(motors[i], elbows[:, i].shape), elbows[:, i])
        for r, tag in enumerate("ab"):
            out[f"rod_{i + 1}{tag}"] = _segment(rods[:, i, r, 0], rods[:, i, r, 1])
    plat = np.zeros((th.shape[0], 4, 4))
    plat[:, :3, :3] = [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]  # the disk's axis (y) vertical
    plat[:, :3, 3], plat[:, 3, 3] = p, 1.0
    out["platform"] = plat
    if delta.has_tool_axis:
        a = np.zeros(th.shape[0]) if tool is None else np.broadcast_to(np.asarray(tool, dtype=float), th.shape[:1])
        off = _tcp_offset(delta)
        T0 = _segment(np.zeros((1, 3)), off[None])[0]  # the paddle at tool angle 0, platform centre at the origin
        Rz = _rz(a)
        tl = np.zeros((th.shape[0], 4, 4))
        tl[:, :3, :3] = Rz @ T0[:3, :3]
        tl[:, :3, 3], tl[:, 3, 3] = p + Rz @ T0[:3, 3], 1.0
        out["tool"] = tl
    return {k: T[None] @ v for k, v in out.items()}


def draw_delta(vis: Any, name: str, delta: DeltaRobot, poses: dict[str, np.ndarray]) -> str:
    """Draw the parts of ``delta`` under ``DELTA_ROOT/name`` at the first frame of ``poses``; return the folder."""
    root = f"{DELTA_ROOT}/{name}"
    for part, (kind, length, radius) in delta_parts(delta).items():
        node = vis[f"{root}/{part}"]
        shape = mg.Box([TOOL_WIDTH, length, 2.0 * radius]) if kind == "tool" else mg.Cylinder(length, radius)
        node.set_object(shape, mg.MeshLambertMaterial(color=_COLORS[kind]))
        node.set_transform(poses[part][0])
    return root


def animate_delta(anim: Any, vis: Any, root: str, poses: dict[str, np.ndarray]) -> None:
    """One animation frame per row of ``poses`` (the animation's frame rate sets the time)."""
    frames = next(iter(poses.values())).shape[0]
    for k in range(frames):
        with anim.at_frame(vis, k) as frame:
            for part, T in poses.items():
                frame[f"{root}/{part}"].set_transform(T[k])


def delta_page(delta: DeltaRobot, theta: Any, path: str | Path, *, fps: float = 30.0, title: str | None = None,
               base_to_world: Any = None) -> Path:
    """A standalone page (HTML, written atomically) of ``delta`` moving through ``theta`` (F, 3) [rad],
    one row a frame at ``fps``; return the path."""
    from pinarms.viz.page import PAGE_PROPERTY, with_page
    from pinarms.viz.server import MeshcatServer

    poses = delta_poses(delta, theta, base_to_world)
    frames = next(iter(poses.values())).shape[0]
    centre = poses["platform"][:, :3, 3].mean(axis=0)
    page = {"title": title or f"{delta.name}: the closed chain", "lines": [f"{delta.name}: {frames} frames"],
            "target": centre.tolist(), "camera": (centre + [1.6, -1.6, 1.0]).tolist(),
            "animation": {"duration": (frames - 1) / fps, "playing": True}}
    with MeshcatServer() as server, contextlib.redirect_stdout(io.StringIO()):
        vis = server.visualizer
        root = draw_delta(vis, delta.name, delta, poses)
        anim = meshcat.animation.Animation(default_framerate=fps)
        animate_delta(anim, vis, root, poses)
        vis.set_animation(anim, play=True, repetitions=float("inf"))
        vis[SCENE_ROOT].set_property(PAGE_PROPERTY, json.dumps(page))
        text = with_page(server.static_html(), page["title"])
    data = text.encode("utf-8")
    return atomic_write(path, lambda f: f.write(data))


def session_delta_poses(session: Session, key: str, times: ArrayLike) -> dict[str, np.ndarray]:
    """World transforms (F, 4, 4) of the parts of the session's delta ``key`` at ``times`` (F,) [s] from its
    motion's start (held at the ends); the passive joints from the closed form."""
    rec = session.deltas[key]
    act = rec.sample(np.atleast_1d(np.asarray(times, dtype=float)))
    return delta_poses(session.delta(key), act[:, :3], rec.base_to_world, act[:, 3] if act.shape[1] == 4 else None)


def draw_session_deltas(vis: meshcat.Visualizer, session: Session, bounds: list, framed: list) -> list[str]:
    """Draw each delta of ``session`` at the start of its motion; its base and platform path join ``bounds``
    and ``framed`` (what the view centres on). Returns the page's summary lines."""
    lines = []
    for key, rec in getattr(session, "deltas", {}).items():
        delta = session.delta(key)
        draw_delta(vis, key, delta, session_delta_poses(session, key, [0.0]))
        # framed: both ends of every part at 9 instants of its motion (the whole chain, not only the platform)
        poses = session_delta_poses(session, key, np.linspace(0.0, rec.duration, 9))
        ends = [T[:, :3, 3] + sign * 0.5 * length * T[:, :3, 1] for part, (_, length, _) in delta_parts(delta).items()
                for T in (poses[part],) for sign in (-1.0, 1.0)]
        extent = np.vstack(ends)
        bounds.append(extent)
        framed.append(extent)
        label = key if key == rec.delta else f"{key} ({rec.delta})"
        lines.append(f"delta {label}: {rec.t.size} samples over {rec.duration:.3g} s" if rec.t.size > 1
                     else f"delta {label}: at rest")
    return lines


def animate_session_deltas(anim: meshcat.animation.Animation, vis: meshcat.Visualizer, session: Session,
                           times: np.ndarray) -> None:
    """Add each delta's motion at the animation's ``times`` (F,) [s] to ``anim`` (held after its end)."""
    for key in getattr(session, "deltas", {}):
        animate_delta(anim, vis, f"{DELTA_ROOT}/{key}", session_delta_poses(session, key, times))


def session_delta_tcp(session: Session, key: str, times: ArrayLike) -> np.ndarray:
    """(F, 3) world position [m] of the tcp of the session's delta ``key`` at ``times`` (F,) [s] from its motion's
    start: the closed-form platform plus the tcp's offset turned by the tool angle."""
    rec = session.deltas[key]
    delta = session.delta(key)
    act = rec.sample(np.atleast_1d(np.asarray(times, dtype=float)))
    p = forward_position(delta.geometry, act[:, :3])
    if act.shape[1] == 4:
        p = p + _rz(act[:, 3]) @ _tcp_offset(delta)
    else:
        p = p + _tcp_offset(delta)
    T = rec.base_to_world
    return p @ T[:3, :3].T + T[:3, 3]
