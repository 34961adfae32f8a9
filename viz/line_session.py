"""A session of the line: the belt, the boxes, every arm replaying its picks, picks and misses marked.

Each arm's picks in the shown time are planned exactly again (:func:`optim.line.plan_pick` at
the simulated rendezvous point) and played on one clock: the arm holds at its box until a pick
starts, so that its rendezvous is at the simulated time (or right after its previous pick ends
when the exact plan runs a little longer than the map said). Grasp points are marked as
``target`` points of the arm that picked, missed items as ``contact`` points at the end of the
belt. Items themselves are not animated (the session format has no moving objects yet).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms.robots.errors import PinarmsError

from .session import Session

__all__ = ["line_session"]


def _arm_samples(plans: list[tuple[float, Any]], q_rest: np.ndarray, t_end: float, hz: float) -> tuple[np.ndarray, np.ndarray]:
    t_all, q_all = [np.array([0.0])], [q_rest[None]]
    clock = 0.0
    for start, plan in plans:
        start = max(start, clock + 1.0 / hz)
        tt = np.arange(0.0, plan.duration, 1.0 / hz)
        t_all.append(start + tt)
        q_all.append(plan.trajectory.sample(tt)[0])
        clock = start + tt[-1]
    if clock < t_end:
        t_all.append(np.array([t_end]))
        q_all.append(q_rest[None])
    return np.concatenate(t_all), np.concatenate(q_all)


def line_session(spec: Any, run: Any, *, t_max: float = 30.0, hz: float = 50.0, title: str = "") -> Session:
    """The line ``spec`` (:class:`optim.line.LineSpec`) replaying ``run`` (a :class:`SimResult`) over
    its first ``t_max`` s (module doc)."""
    from pinarms.optim.line.tracking import plan_pick, rest_configuration

    belt = spec.belt
    session = Session(title=title or f"line: {len(spec.stations)} arm(s), belt {belt.speed} m/s")
    T = belt.belt_to_world.copy()
    T[:3, 3] = belt.to_world(belt.length / 2.0, 0.0, -0.01)
    session.add_box("belt", (belt.length, belt.width, 0.02), T, (0.2, 0.2, 0.22, 1.0))
    kinds = spec.stream.types
    for k, st in enumerate(spec.stations):
        key = session.add_robot(st.robot, key=st.name.replace(" ", "_"), base_to_world=st.base_to_world)
        B = np.eye(4)
        B[:3, 3] = st.place.position - [0.0, 0.0, 0.06]
        session.add_box(f"{key} box", (0.2, 0.15, 0.06), B, (0.85, 0.6, 0.3, 1.0))
        sel = np.flatnonzero((run.picked_by == k) & (run.start < t_max))
        plans, grasps = [], []
        for i in sel[np.argsort(run.start[sel])]:
            kind = kinds[int(run.kind[i])]
            try:
                plan = plan_pick(st, belt, spec.tracking, float(run.u_meet[i]), float(run.w[i]),
                                 item_height=kind.size[2], mass=kind.mass)
            except PinarmsError:
                continue
            plans.append((float(run.meet[i]) - plan.times[0], plan))
            grasps.append(belt.to_world(run.u_meet[i] + belt.speed * spec.tracking.descend, run.w[i],
                                        kind.size[2]))
        q_rest = rest_configuration(st)
        t, q = _arm_samples(plans, q_rest, t_max, hz)
        session.add_trajectory(f"{key} picks", (t, q), robot=key)
        if grasps:
            session.add_points(f"{key} grasps", st.world_to_base(np.array(grasps)), kind="target", robot=key)
    missed = np.flatnonzero((run.picked_by < 0) & (run.t0 < t_max))
    if missed.size:
        last = spec.stations[-1]
        p = belt.to_world(np.full(missed.size, belt.length), run.w[missed], 0.02)
        session.add_points("missed items", last.world_to_base(p), kind="contact",
                           robot=last.name.replace(" ", "_"))
    return session
