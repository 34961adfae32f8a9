"""The trajectories of a scene: their world tcp paths, which of them play, and the one looping animation.

:func:`pinarms.viz.scene.build_scene` draws what these compute: the tcp path of each trajectory in
the world frame (one per arm for a cell) with the tcp at its knots, the trajectories that
play (default: the first of each robot; at most one per robot), each robot posed at the
start of its motion, and one MeshCat animation of them all (and of the belt lines) from
time 0 at ``fps`` frames per second, looping. Times in s, positions in m.
"""

from __future__ import annotations

from typing import Sequence, TYPE_CHECKING

import numpy as np

from pinarms.errors import InvalidInput

from pinarms.viz._meshcat import meshcat
from pinarms.viz.robot_drawing import RobotDrawing
from pinarms.viz.shapes import transform_points

if TYPE_CHECKING:
    from pinarms.viz.session import Session

__all__ = ["interp_rows", "world_tcp_paths", "animated_trajectories", "show_start_poses", "animate_scene",
           "frame_times"]


def interp_rows(t_new: np.ndarray, t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Linear interpolation of each column of ``q (N, n)`` at ``t_new`` (held at the ends)."""
    return np.stack([np.interp(t_new, t, q[:, j]) for j in range(q.shape[1])], axis=1)


def world_tcp_paths(session: Session, drawings: dict[str, RobotDrawing], bounds: list[np.ndarray],
               framed: list[np.ndarray]) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """World tcp paths of the trajectories and the tcp at their knots, by label (a cell: one per arm)."""
    tcp_paths, knots = {}, {}
    for name, rec in session.trajectories.items():
        robot = drawings[rec.robot].robot
        T_base = session.robots[rec.robot].base_to_world
        q_knots = interp_rows(rec.knot_times, rec.t, rec.q)
        # a cell: one tcp path per arm; a robot: its tcp
        frames = {arm: f for arm, f in session.cell_tcp_frames(rec.robot).items() if f in robot.frame_names}
        for arm, frame in (frames.items() if frames else [(None, "tcp")]):
            label = name if arm is None else f"{name}: {arm}"
            tcp_paths[label] = transform_points(T_base, robot.position(rec.q, frame))
            knots[label] = transform_points(T_base, robot.position(q_knots, frame))
            bounds.append(tcp_paths[label])
            framed.append(tcp_paths[label])
    return tcp_paths, knots


def animated_trajectories(session: Session, animate: Sequence[str] | None) -> tuple[str, ...]:
    """The trajectories that play: ``animate`` checked (at most one per robot), default the first of each robot."""
    if animate is None:
        chosen: dict[str, str] = {}
        for name, rec in session.trajectories.items():
            chosen.setdefault(rec.robot, name)
        return tuple(chosen.values())
    animated = tuple(animate)
    unknown = [n for n in animated if n not in session.trajectories]
    if unknown:
        raise InvalidInput(f"cannot animate {unknown}: trajectories are {list(session.trajectories)}")
    owners = [session.trajectories[n].robot for n in animated]
    if len(set(owners)) != len(owners):
        raise InvalidInput(f"animate at most one trajectory per robot; got {list(animated)} (robots {owners})")
    return animated


def show_start_poses(session: Session, drawings: dict[str, RobotDrawing], animated: tuple[str, ...],
                      framed: list[np.ndarray]) -> None:
    """Pose each robot at the start of its animated (else first) trajectory, else its rest pose (a cell's
    hold, :meth:`Session.cell_hold`; else neutral); frame its motion."""
    for key, drawing in drawings.items():
        recs = [session.trajectories[n] for n in animated if session.trajectories[n].robot == key]
        recs = recs or [r for r in session.trajectories.values() if r.robot == key]
        hold = session.cell_hold(key)
        rest = drawing.robot.neutral if hold is None else hold
        drawing.display(recs[0].q[0] if recs else rest)
        # framed over the whole motion: the pose at 9 instants of its (first) trajectory
        poses = recs[0].q[np.linspace(0, recs[0].q.shape[0] - 1, 9).round().astype(int)] if recs else rest
        framed.append(transform_points(session.robots[key].base_to_world, drawing.extent(poses)))


def animate_scene(vis: meshcat.Visualizer, session: Session, root: str, drawings: dict[str, RobotDrawing],
                  animated: tuple[str, ...], lines: bool, fps: float, play: bool) -> tuple[float, int]:
    """One looping animation of the ``animated`` trajectories, the belt ``lines`` and the session's deltas
    (``lines`` true when a line or a delta moves); return (duration, frames)."""
    from pinarms.viz.line_scene import animate_lines, line_duration

    if not (animated or lines):
        return 0.0, 0
    duration = max([float(session.trajectories[n].t[-1] - session.trajectories[n].t[0]) for n in animated]
                   + [line_duration(session)] + [rec.duration for rec in getattr(session, "deltas", {}).values()])
    times = frame_times(duration, fps)
    anim = meshcat.animation.Animation(default_framerate=fps)
    for name in animated:
        rec = session.trajectories[name]
        drawings[rec.robot].record(anim, vis, interp_rows(rec.t[0] + times, rec.t, rec.q))
    animate_lines(vis, anim, session, root, times, animated, drawings)
    if getattr(session, "deltas", None):
        from pinarms.viz.delta_scene import animate_session_deltas

        animate_session_deltas(anim, vis, session, times)
    vis.set_animation(anim, play=play, repetitions=float("inf"))
    return duration, times.size


def frame_times(duration: float, fps: float) -> np.ndarray:
    """Animation instants from 0 at ``fps``, ending exactly on ``duration``."""
    n_frames = int(np.floor(duration * fps + 1e-9)) + 1
    times = np.minimum(np.arange(n_frames) / fps, duration)
    if times[-1] < duration:  # end exactly on the last pose
        times = np.append(times, duration)
    return times
