"""Belt lines in a MeshCat scene: the belt, the items riding it, picked, carried, boxed or missed.

Scene paths (under MeshCat's root ``/meshcat``):

- ``pinarms/lines/<name>/belt`` — the belt, a box of its length, width and thickness whose
  top face is the belt surface; ``pinarms/lines/<name>/miss`` — a thin red strip across the
  belt where an unpicked item counts as missed;
- ``pinarms/lines/<name>/items/<i>`` — item ``i`` (a box of its size): on the belt from its
  arrival, with the tool from its grasp to its release, then in its box; before it arrives
  and after it leaves the belt's end it is kept inside the belt (hidden);
- ``pinarms/lines/<name>/missed/<i>`` — the same item drawn red, which takes its place
  from the moment it passes the miss strip unpicked.

MeshCat animates transforms only (no colour or visibility tracks), hence the swap of two
objects for a missed item. Each item's track holds the frames where its motion is not
linear (on the belt it moves at constant speed: two key frames suffice), so that a page of a
few hundred items stays small.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pinarms.viz._meshcat import meshcat, mg
from pinarms.viz.errors import ViewerError
from pinarms.viz.line_record import BOX_DEPTH, MISSED, NOT_DRAWN, LineRecord

if TYPE_CHECKING:
    from pinarms.viz.session import Session

__all__ = ["draw_lines", "animate_lines", "item_positions", "ITEM_COLOR", "MISSED_COLOR"]

ITEM_COLOR = 0xE8DCB0
MISSED_COLOR = 0xD62728
_BELT_COLOR = 0x3C4450


def _to_world(T: np.ndarray, u: np.ndarray, w: np.ndarray, z: np.ndarray) -> np.ndarray:
    return T[:3, 3] + u[..., None] * T[:3, 0] + w[..., None] * T[:3, 1] + z[..., None] * T[:3, 2]


def draw_lines(vis: meshcat.Visualizer, session: Session, root: str, bounds: list) -> list[str]:
    """Draw each line's belt and miss strip (static); return the page's summary lines. ``bounds`` grows."""
    lines = []
    for name, rec in getattr(session, "lines", {}).items():
        base = f"{root}/lines/{name}"
        T = rec.belt_to_world.copy()
        centre = T @ np.array([rec.length / 2.0, 0.0, -rec.thickness / 2.0, 1.0])
        pose = T.copy()
        pose[:3, 3] = centre[:3]
        vis[f"{base}/belt"].set_object(mg.Box([rec.length, rec.width, rec.thickness]),
                                       mg.MeshLambertMaterial(color=_BELT_COLOR))
        vis[f"{base}/belt"].set_transform(pose)
        strip = T.copy()
        strip[:3, 3] = (T @ np.array([rec.u_miss, 0.0, 0.001, 1.0]))[:3]
        vis[f"{base}/miss"].set_object(mg.Box([0.01, rec.width, 0.002]), mg.MeshLambertMaterial(color=MISSED_COLOR))
        vis[f"{base}/miss"].set_transform(strip)
        corners = np.array(np.meshgrid([0, rec.length], [-rec.width / 2, rec.width / 2], [-rec.thickness, 0.0]))
        bounds.append(_to_world(T, *corners.reshape(3, -1)))
        lost = int(np.count_nonzero(rec.items[:, 6] == NOT_DRAWN))
        lines.append(f"{name}: belt {rec.length:.2f} m at {rec.speed:g} m/s, {rec.items.shape[0]} items in "
                     f"{rec.duration:g} s: {rec.n_picked} picked, {rec.n_missed} missed (red)"
                     + (f", {lost} picked but not replanned (left on the belt)" if lost else ""))
    return lines


def item_positions(rec: LineRecord, times: np.ndarray, tcp: dict[int, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """World centres (N, F, 3) of every item drawn normally and drawn red (missed) at ``times`` (F,) [s].

    ``tcp[k]`` (F, 3): arm ``k``'s tool point (world) at ``times``. Hidden items sit inside the belt.
    """
    T, it = rec.belt_to_world, rec.items
    t0, w, h = it[:, 0:1], it[:, 1:2], it[:, 5:6]
    half = it[:, 3:4] / 2.0
    t = times[None, :]
    u = rec.speed * (t - t0)
    on = (u >= 0.0) & (u <= rec.length)
    # hidden: inside the belt on its centre line, whatever the item's yaw (thickness >= 1.25 × its largest size)
    reach = np.hypot(half, it[:, 4:5] / 2.0)
    hid_u = np.clip(u, reach, np.maximum(reach, rec.length - reach))
    inside = np.where(on, u, hid_u)
    z_belt = np.where(on, h / 2.0, -rec.thickness / 2.0)
    ww = np.where(on, w, 0.0)
    normal = _to_world(T, inside, ww, z_belt)
    red = _to_world(T, hid_u, np.zeros(u.shape), np.full(u.shape, -rec.thickness / 2.0))
    arm = it[:, 6].astype(int)
    for i in np.flatnonzero(arm == MISSED):
        past = on[i] & (u[i] >= rec.u_miss)
        red[i, past] = normal[i, past]
        normal[i, past] = _to_world(T, hid_u[i, past], np.zeros(past.sum()), np.full(past.sum(), -rec.thickness / 2.0))
    for i in np.flatnonzero(arm >= 0):
        p = tcp.get(int(arm[i]))
        if p is None:
            continue
        tg, tr = it[i, 7], it[i, 8]
        carried = (times >= tg) & (times < tr)
        normal[i, carried] = p[carried] - [0.0, 0.0, h[i, 0] / 2.0]
        after = times >= tr
        if after.any():
            k = min(int(np.searchsorted(times, tr)), times.size - 1)
            drop = h[i, 0] / 2.0 + BOX_DEPTH + 0.01
            normal[i, after] = p[k] - [0.0, 0.0, drop]
    return normal, red


def _kept(p: np.ndarray) -> np.ndarray:
    """Frames of a uniformly timed track (F, 3) where it is not linear (its ends included)."""
    keep = np.ones(p.shape[0], dtype=bool)
    if p.shape[0] > 2:
        keep[1:-1] = np.abs(p[:-2] - 2.0 * p[1:-1] + p[2:]).max(axis=1) > 1e-7
    return np.flatnonzero(keep)


def animate_lines(vis: meshcat.Visualizer, anim: meshcat.animation.Animation, session: Session, root: str, times: np.ndarray, animated: tuple[str, ...],
                  drawings: dict) -> None:
    """Draw each line's items and add their tracks to ``anim`` (frames at ``times`` (F,) [s])."""
    for name, rec in getattr(session, "lines", {}).items():
        tcp: dict[int, np.ndarray] = {}
        for k, key in enumerate(rec.arms):
            if key in getattr(session, "deltas", {}):
                from pinarms.viz.delta_scene import session_delta_tcp  # robots.delta: imported when a delta is there

                tcp[k] = session_delta_tcp(session, key, times)
                continue
            if key not in session.robots:
                raise ViewerError(f"line {name!r} names arm {key!r}, which is not a robot or delta of this session")
            traj = [session.trajectories[n] for n in animated if session.trajectories[n].robot == key]
            if traj:
                tr = traj[0]
                for node in ("paths", "vias"):  # the items show the picks; tcp tubes would hide the belt
                    vis[f"{root}/{node}/{tr.name}"].set_property("visible", False)
                q = np.stack([np.interp(tr.t[0] + times, tr.t, tr.q[:, j]) for j in range(tr.q.shape[1])], axis=1)
                T = session.robots[key].base_to_world
                tcp[k] = drawings[key].robot.position(q) @ T[:3, :3].T + T[:3, 3]
        normal, red = item_positions(rec, times, tcp)
        base = f"{root}/lines/{name}"
        for i, row in enumerate(rec.items):
            R = rec.belt_to_world.copy()
            c, s = np.cos(row[2]), np.sin(row[2])
            R[:3, :3] = R[:3, :3] @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
            for sub, color, track in (("items", ITEM_COLOR, normal[i]), ("missed", MISSED_COLOR, red[i])):
                if sub == "missed" and int(row[6]) != MISSED:
                    continue
                path = f"{base}/{sub}/{i}"
                vis[path].set_object(mg.Box(row[3:6].tolist()), mg.MeshLambertMaterial(color=color))
                R[:3, 3] = track[0]
                vis[path].set_transform(R)
                for f in _kept(track):
                    R[:3, 3] = track[f]
                    with anim.at_frame(vis, int(f)) as frame:
                        frame[path].set_transform(R)


def line_duration(session: Session) -> float:
    """Longest window of the session's lines [s] (0 without lines)."""
    return max((rec.duration for rec in getattr(session, "lines", {}).values()), default=0.0)


__all__.append("line_duration")


#: A line of more arms than this opens framed on its first arms (where items arrive) and the belt under them.
FRAMED_ARMS = 3


def line_focus(session: Session, points: np.ndarray) -> np.ndarray:
    """What the view of a scene opens framed on: ``points`` (k, 3), or, for a line of more than
    :data:`FRAMED_ARMS` arms, those of them up to 0.6 m past the third arm's base along the belt
    and the belt from its start to there (the page's orbit and zoom reach the rest)."""
    lines = list(getattr(session, "lines", {}).values())
    if not lines or len(lines[0].arms) <= FRAMED_ARMS:
        return points
    rec = lines[0]
    T = rec.belt_to_world
    placed = {**session.robots, **getattr(session, "deltas", {})}  # robots and deltas: both have base_to_world
    bases = [placed[k].base_to_world[:3, 3] for k in rec.arms if k in placed]
    if len(bases) <= FRAMED_ARMS:
        return points
    u_bases = np.sort([(b - T[:3, 3]) @ T[:3, 0] for b in bases])
    u_hi = float(min(rec.length, u_bases[FRAMED_ARMS - 1] + 0.6))
    u = (points - T[:3, 3]) @ T[:3, 0]
    corners = np.array(np.meshgrid([0.0, u_hi], [-rec.width / 2, rec.width / 2], [-rec.thickness, 0.0]))
    return np.vstack([points[u <= u_hi], _to_world(T, *corners.reshape(3, -1))])


__all__.append("line_focus")
