"""A simulated belt line into a session: its arms, their picks as joint trajectories, the belt, the items.

:func:`add_line` takes a line (:class:`pinarms.optim.line.LineSpec`) and its result
(:class:`pinarms.optim.line.LineResult`, one :class:`SimResult` per seed) and adds to a
:class:`pinarms.viz.Session`, for a window of one run (default the first 20 s of the first seed):

- each station's arm as a robot (key: the station's name) at its base pose, and its box as
  a translucent static box under the release point; a delta (:class:`pinarms.optim.line.delta_tracking.DeltaArm`)
  as a session delta (:meth:`pinarms.viz.Session.add_delta`) whose motion is its actuated angles;
- each arm's joint trajectory through its picks of the window, ``"<station> picks"`` (a delta's:
  its motion, :func:`pinarms.optim.line.delta_motion.delta_pick_motion`): the
  simulator keeps only pick times, so every pick of the window is planned again exactly
  (:func:`pinarms.optim.line.tracking.plan_pick` at the simulated rendezvous point, rest at the box
  between picks). The exact plan's times differ from the task map's by its error (≤ 1 %); a
  pick that would start before the previous one ends waits for it (the item is then met a
  little downstream of the simulated point: the picture, not the figures);
- a :class:`pinarms.viz.line_record.LineRecord` with the belt and every item on it during the window.

Units: m, s, rad.
"""

from __future__ import annotations

from typing import Any, TYPE_CHECKING

import numpy as np

from pinarms.errors import InvalidInput, PinarmsError

from pinarms.viz.line_record import BOX_DEPTH, ITEM_COLUMNS, MISSED, NOT_DRAWN, LineRecord, make_line

if TYPE_CHECKING:
    from pinarms.optim.line.api import LineResult, LineSpec
    from pinarms.optim.line.belt import Belt
    from pinarms.optim.line.delta_motion import DeltaPickMotion
    from pinarms.optim.line.items import ItemType
    from pinarms.optim.line.station import Station
    from pinarms.optim.line.tracking import TrackingSpec

__all__ = ["add_line", "BOX_DEPTH", "BOX_GAP", "DEFAULT_WINDOW_S"]

#: The gap between an item's bottom and the drawn place box's rim at release [m] (the box's
#: depth, :data:`BOX_DEPTH`, lives in :mod:`pinarms.viz.line_record`, shared with the scene).
BOX_GAP = 0.01
DEFAULT_WINDOW_S = 20.0


def _window(start: Any, duration: Any) -> tuple[float, float]:
    ok = all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in (start, duration))
    if not ok or start < 0.0 or not 0.0 < duration <= 3600.0:
        raise InvalidInput(f"the window shown must be start >= 0 s and 0 < duration <= 3600 s, got {start!r}, "
                           f"{duration!r}")
    return float(start), float(duration)


def _delta_pick(st: Station, belt: Belt, tr: TrackingSpec, u: float, w: float, kind: ItemType, yaw: float
                ) -> DeltaPickMotion:
    from pinarms.optim.line.delta_motion import delta_pick_motion

    return delta_pick_motion(st, belt, tr, u, w, mass=kind.mass, item_height=kind.size[2], yaw=yaw)


def _plan_arm(spec: Any, k: int, picks: np.ndarray, run: Any, items: Any, t_end: float,
              maps: tuple = ()) -> tuple[list, dict]:
    """Exact plans of arm ``k``'s picks (item indices, by start) up to ``t_end``: [(start, plan)], {item: (tg, tr)}.
    A delta's picks are motions of its actuated coordinates (:mod:`pinarms.optim.line.delta_motion`)."""
    from pinarms.optim.line.delta_tracking import DeltaArm
    from pinarms.optim.line.tracking import plan_pick

    st = spec.stations[k]
    is_delta = isinstance(st.robot, DeltaArm)
    q_rest = None if is_delta else _rest(st)
    u_base = float(spec.belt.to_belt(st.base_to_world[:3, 3])[0])
    tr = spec.tracking
    out, times = [], {}
    free_at = -np.inf
    for i in picks:
        if run.start[i] >= t_end:
            break
        kind = items.types[int(items.kind[i])]
        u, w = float(run.u_meet[i]), float(items.w[i])
        branch = maps[int(items.kind[i])].branch_at(u - u_base, w) if maps and not is_delta else None  # as timed
        try:
            plan = _delta_pick(st, spec.belt, tr, u, w, kind, float(items.yaw[i])) if is_delta else \
                plan_pick(st, spec.belt, tr, u, w, item_height=kind.size[2], mass=kind.mass, q_rest=q_rest,
                          branch=branch, yaw=float(items.yaw[i]))
        except PinarmsError:
            continue  # drawn on the belt, not marked (NOT_DRAWN)
        s = max(float(run.meet[i]) - plan.times[0], free_at)
        out.append((s, plan))
        times[int(i)] = (s + plan.times[0] + tr.descend + tr.grasp, s + plan.times[0] + plan.times[1] + plan.times[2])
        free_at = s + plan.duration
    return out, times


def _rest(st: Station) -> np.ndarray:
    """The arm at rest at its box: joint values, or a delta's actuated coordinates."""
    from pinarms.optim.line.delta_motion import delta_rest
    from pinarms.optim.line.delta_tracking import DeltaArm
    from pinarms.optim.line.tracking import rest_configuration

    return delta_rest(st) if isinstance(st.robot, DeltaArm) else rest_configuration(st)


def _arm_samples(q_rest: np.ndarray, plans: list, t: np.ndarray) -> np.ndarray:
    q = np.tile(q_rest, (t.size, 1))
    for s, plan in plans:
        sel = (t >= s) & (t <= s + plan.duration)
        if sel.any():
            tau = np.clip(t[sel] - s, 0.0, plan.duration)
            q[sel] = plan.sample(tau) if hasattr(plan, "actuated") else plan.trajectory.sample(
                np.minimum(tau, plan.trajectory.duration))[0]
    return q


def add_line(session: Any, spec: LineSpec, result: LineResult, *, run: int = 0, start: float = 0.0,
             duration: float = DEFAULT_WINDOW_S, name: str = "line", hz: float = 30.0) -> LineRecord:
    """Add the window [``start``, ``start + duration``] s of run ``run`` of ``result`` (module doc).

    Args:
        session: a :class:`pinarms.viz.Session` (its robot keys must not clash with the stations' names).
        spec: the :class:`pinarms.optim.line.LineSpec` simulated; ``result``: its :class:`pinarms.optim.line.LineResult`.
        run: index of the seed's run in ``result.runs``.
        hz: sampling rate of the arms' trajectories [1/s].

    Raises:
        InvalidInput: a bad window, run index or rate; a station name already used as a robot key.
    """
    from pinarms.optim.line.delta_tracking import DeltaArm

    t_a, dur = _window(start, duration)
    runs = getattr(result, "runs", None)
    if not runs or not (isinstance(run, int) and 0 <= run < len(runs)):
        raise InvalidInput(f"run must index result.runs (0..{len(runs or ()) - 1}), got {run!r}")
    if not (isinstance(hz, (int, float)) and np.isfinite(hz) and 1.0 <= hz <= 1000.0):
        raise InvalidInput(f"hz must be a sampling rate in [1, 1000] 1/s, got {hz!r}")
    r = runs[run]
    items = spec.stream.items(spec.belt, spec.seeds[run])
    if len(items) != r.picked_by.size or not np.array_equal(items.t0, r.t0):
        raise InvalidInput("result does not belong to spec: its run's items differ from the stream's")
    belt, t_b = spec.belt, t_a + dur
    h_max = max(t.size[2] for t in items.types)
    t = np.append(np.arange(0.0, dur, 1.0 / hz), dur)
    grasp: dict[int, tuple[float, float]] = {}
    arms = []
    for k, st in enumerate(spec.stations):
        delta = isinstance(st.robot, DeltaArm)
        if delta and st.name in session.robots or not delta and st.name in session.deltas:
            raise InvalidInput(f"station {st.name!r}: its name is already a key of this session")
        key = st.name if delta else session.add_robot(st.robot, key=st.name, base_to_world=st.base_to_world)
        arms.append(key)
        picks = np.flatnonzero(r.picked_by == k)
        picks = picks[np.argsort(r.start[picks], kind="stable")]
        arm_maps = tuple((getattr(result, "maps", None) or {}).get(st.name, ()))
        plans, times = _plan_arm(spec, k, picks, r, items, t_b, arm_maps)
        grasp.update(times)
        samples = _arm_samples(_rest(st), plans, t_a + t)
        if delta:  # a delta and its actuated angles (viz.delta_record); its passive joints are never stored
            session.add_delta(st.robot.delta, key=key, base_to_world=st.base_to_world, motion=(t, samples))
        else:
            session.add_trajectory(f"{st.name} picks", (t, samples), robot=key)
        box = np.eye(4)
        box[:3, 3] = st.place.position - [0.0, 0.0, h_max + BOX_GAP + BOX_DEPTH / 2.0]
        session.add_box(f"{st.name}: {st.place.name}", [0.2, 0.16, BOX_DEPTH], pose=box, color=(0.75, 0.55, 0.3, 0.45))
    on_belt = np.flatnonzero((items.t0 <= t_b) & (items.t0 + belt.length / belt.speed >= t_a))
    rows = np.zeros((on_belt.size, len(ITEM_COLUMNS)))
    for row, i in enumerate(on_belt):
        size = items.types[int(items.kind[i])].size
        k = int(r.picked_by[i])
        if k < 0:
            arm, tg, tr = MISSED, 0.0, 0.0
        elif int(i) in grasp:
            arm, (tg, tr) = k, grasp[int(i)]
            tg, tr = tg - t_a, tr - t_a
        elif r.start[i] >= t_b:  # picked after the window: on the belt all along
            arm, tg = k, max(float(r.meet[i]) - t_a, float(items.t0[i]) - t_a)
            tr = tg
        else:
            arm, tg, tr = NOT_DRAWN, 0.0, 0.0
        rows[row] = (items.t0[i] - t_a, items.w[i], items.yaw[i], *size, arm, tg, tr)
    ends = [w.u_max for w in getattr(result, "windows", ())] or [belt.length]
    u_miss = float(min(belt.length, max(ends) + belt.speed * spec.tracking.track_time))
    thickness = max(0.05, 1.25 * max(max(tp.size) for tp in items.types))
    rec = make_line(LineRecord(session.free_name(session.lines, name, "line"), tuple(arms), belt.belt_to_world,
                               length=belt.length, width=belt.width, thickness=thickness, speed=belt.speed,
                               u_miss=u_miss, duration=dur, items=rows))
    session.lines[rec.name] = rec
    return rec
