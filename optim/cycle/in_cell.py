"""Pick-and-place cycles that keep a clearance from the cell around the arm.

:func:`plan_cycle` with ``cell=`` lands here. The cycle is first planned as without a cell
(:mod:`optim.cycle`), then checked continuously in the cell
(:meth:`robots.cell.Cell.check_motion`): every pair of the arm with a fixture or another
arm (held still at ``hold``) must keep ``clearance`` [m], and the arm's own links must
not touch (they are designed close, so no clearance is asked of them). When the check
fails, the cycle is re-planned, in this order, until it passes:

1. **raise the transfer**: the vertical lift at pick and place grows by ``lift_step``
   (the transfer then starts and ends higher), up to the highest lift the arm reaches or
   :data:`optim.caps.MAX_LIFT_ATTEMPTS` rises;
2. **add a via point** above the middle of the transfer (between "above pick" and
   "above place", at the highest lifted height plus ``lift_step`` per attempt, three
   heights), then two via points at one and two thirds;
3. **plan the transfer** round what blocks (a crate under a guard, a shelf, the other
   arm's column): :func:`optim.motion.cycle.planned_cycle` keeps the lift and lowering at
   the spec's height and plans the transfer between them with OMPL, every edge proven
   continuously (:mod:`optim.motion`).

Each re-planned cycle is re-timed (time-optimal under the same limits) and re-checked.
The result carries a :class:`CellCycleReport`: what was tried, the lift and via points
kept, the smallest clearance, and the extra time against the cycle planned without the
cell. If the pick or the place itself is closer than ``clearance`` to a fixture, or no
attempt clears, :class:`robots.errors.CollisionError` says which bodies block and where.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pinarms.optim.caps import LIFT_STEP_RANGE, MAX_CLEARANCE, MAX_LIFT_ATTEMPTS, MIN_MARGIN, number_setting
from pinarms.robots.errors import CollisionError, InvalidInput, UnreachableTarget

__all__ = ["CellCycleReport", "plan_cycle_in_cell"]

_UP = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True, eq=False)
class CellCycleReport:
    """How a cycle was made to keep its clearance in a cell.

    Attributes:
        cell: the cell's name; ``arm``: the arm's name in it.
        clearance: the distance required from fixtures and other arms [m]; ``margin``: the
            resolution of the continuous check [m].
        min_clearance: the smallest distance of the kept cycle at the check's samples [m]
            and the pair (``min_clearance_pair``, ``"body_a – body_b"``); ``lower_bound``:
            the proven bound between samples [m].
        lift: the lift kept [m]; ``via``: the via points added (base frame, m).
        cycle_time_without_cell: the cycle planned ignoring the cell [s];
            ``extra_time``: the kept cycle's time minus it [s].
        attempts: each attempt in order: ``(description, clear, min clearance [m], pair)``.
        planned_transfer: the transfer was planned around the cell (:mod:`optim.motion.cycle`)
            after raising the lift and via points could not clear.
    """

    cell: str
    arm: str
    clearance: float
    margin: float
    min_clearance: float
    min_clearance_pair: str
    lower_bound: float
    lift: float
    via: tuple[tuple[float, float, float], ...]
    cycle_time_without_cell: float
    extra_time: float
    attempts: tuple[tuple[str, bool, float, str], ...] = field(default=())
    planned_transfer: bool = False

    def as_dict(self) -> dict[str, Any]:
        return {
            "cell": self.cell,
            "arm": self.arm,
            "clearance_m": self.clearance,
            "margin_m": self.margin,
            "min_clearance_m": self.min_clearance,
            "min_clearance_pair": self.min_clearance_pair,
            "lower_bound_m": self.lower_bound,
            "lift_m": self.lift,
            "via_m": [list(v) for v in self.via],
            "cycle_time_without_cell_s": self.cycle_time_without_cell,
            "extra_time_s": self.extra_time,
            "attempts": [{"what": a, "clear": c, "min_clearance_m": d, "pair": p} for a, c, d, p in self.attempts],
            "planned_transfer": self.planned_transfer,
        }


def _arm_of(cell: Any, robot: Any, arm: str | None):
    if arm is not None:
        found = cell.arm(arm)
        if robot is not found.robot and tuple(robot.joint_names) != tuple(found.robot.joint_names):
            raise InvalidInput(f"robot {robot.name!r} is not arm {arm!r} of cell {cell.name!r}")
        return found
    for a in cell.arms:
        if a.robot is robot:
            return a
    if len(cell.arms) == 1 and tuple(robot.joint_names) == tuple(cell.arms[0].robot.joint_names):
        return cell.arms[0]
    raise InvalidInput(
        f"robot {robot.name!r} is not an arm of cell {cell.name!r}: pass cell.arm(name).robot, or arm=name "
        f"(arms: {', '.join(a.name for a in cell.arms)})"
    )


def _verdict(external, own, motion, clearance: float, margin: float, hold: Any):
    ext = external.check_motion([motion], margin=margin, clearance=clearance, hold=hold)
    slf = own.check_motion([motion], margin=margin, hold=hold) if own is not None else None
    ok = ext.clear and (slf is None or slf.collision_free)
    return ok, ext, slf


def _describe(check) -> tuple[float, str, float]:
    """(min clearance, pair text, time) of a check, from its first contact or its closest sample."""
    if check.first_contact is not None:
        c = check.first_contact
        return -c.depth, str(c.pair), c.time
    pair = check.min_clearance_pair
    return check.min_clearance, (str(pair) if pair is not None else "none"), check.min_clearance_time


def plan_cycle_in_cell(robot: Any, spec: Any, *, cell: Any, clearance: float, arm: str | None, hold: Any,
                       margin: float, lift_step: float, plan: Any, plan_transfer: bool = True, **plan_kwargs: Any):
    """Plan ``spec`` for ``robot`` (an arm of ``cell``) keeping ``clearance`` (module doc).

    ``plan`` is :func:`optim.cycle.plan_cycle` (called without a cell for each attempt).
    """
    from pinarms.robots.cell import ArmMotion

    clearance = number_setting(clearance, "clearance", 0.0, MAX_CLEARANCE, unit="m")
    lift_step = number_setting(lift_step, "lift_step (rise per re-planning attempt)", *LIFT_STEP_RANGE, unit="m")
    margin = number_setting(margin, "margin (resolution of the continuous check)", MIN_MARGIN, unit="m")
    cell_arm = _arm_of(cell, robot, arm)
    external = cell.with_pairs("external")
    own = cell.with_pairs("self") if any(p.kind == "self" and p.owner_a == cell_arm.name for p in cell.pairs) else None
    hold_q = cell.neutral if hold is None else cell.robot.check_q(hold)[0][0]

    base = plan(robot, spec, **plan_kwargs)
    # the pick and the place themselves must keep the clearance: no re-planning moves them
    for label, q in (("pick", base.q_via[0]), ("place", base.q_via[len(spec.names) - 1])):
        q_cell = hold_q.copy()
        q_cell[cell_arm.q_slice] = q
        cl = external.clearance(q_cell)
        if cl.distance < clearance:
            raise CollisionError(
                f"the {label} pose of arm {cell_arm.name!r} is {cl.distance * 1e3:.1f} mm from {cl.pair_of().body_b} "
                f"({cl.pair_of()}), less than the clearance {clearance * 1e3:.1f} mm: move the {label} point "
                "(re-planning the transfer cannot move it)"
            )

    attempts: list[tuple[str, bool, float, str]] = []
    last = None

    def attempt(description: str, candidate_spec: Any):
        nonlocal last
        result = plan(robot, candidate_spec, **plan_kwargs)
        ok, ext, slf = _verdict(external, own, ArmMotion(cell_arm.name, result.trajectory), clearance, margin, hold_q)
        bad = ext if not ext.clear or slf is None else slf
        d, pair, t = _describe(bad if not ok else ext)
        attempts.append((description, bool(ok), float(d), pair))
        last = (description, d, pair, t, ok, result, ext)
        return ok, result, ext

    ok, result, ext = attempt(f"lift {spec.lift:.3f} m", spec)
    lift = spec.lift
    for _ in range(MAX_LIFT_ATTEMPTS):  # bounded: the arm's reach usually ends the rise first
        if ok:
            break
        lift += lift_step
        try:
            ok, result, ext = attempt(f"lift {lift:.3f} m", dataclasses.replace(spec, lift=lift))
        except UnreachableTarget:
            lift -= lift_step
            break
    vias: tuple = ()
    if not ok:
        top = max(lift, spec.lift)
        poses = dataclasses.replace(spec, lift=top).poses(robot)
        above_pick, above_place = poses[1][:3, 3], poses[-2][:3, 3]
        height = max(above_pick[2], above_place[2])
        for k in range(1, 4):
            for fractions in ((0.5,), (1.0 / 3.0, 2.0 / 3.0)):
                points = []
                for f in fractions:
                    p = above_pick + f * (above_place - above_pick)
                    p[2] = height + k * lift_step
                    points.append(p)
                try:
                    ok, result, ext = attempt(
                        f"lift {top:.3f} m, {len(points)} via point(s) at z = {height + k * lift_step:.3f} m",
                        dataclasses.replace(spec, lift=top, via=tuple(spec.via) + tuple(points)),
                    )
                except UnreachableTarget:
                    continue
                if ok:
                    lift, vias = top, tuple(tuple(float(x) for x in p) for p in points)
                    break
            if ok:
                break
    planned_transfer = False
    if not ok and plan_transfer:
        # raising the transfer cannot clear: plan it round what blocks (OMPL, optim.motion)
        from pinarms.optim.errors import PlanningError
        from pinarms.optim.motion.cycle import planned_cycle

        try:
            result = planned_cycle(robot, spec, base, cell=cell, arm=cell_arm, clearance=clearance, hold=hold_q,
                                   margin=margin, seed=int(plan_kwargs.get("seed", 0)))
            ok, ext, slf = _verdict(external, own, ArmMotion(cell_arm.name, result.trajectory), clearance, margin,
                                    hold_q)
            d, pair, t = _describe(ext if ok else (ext if not ext.clear or slf is None else slf))
            move = result.moves[0]
            description = f"lift {spec.lift:.3f} m, transfer planned by {move.planner} ({move.states} states)"
            attempts.append((description, bool(ok), float(d), pair))
            last = (description, d, pair, t, ok, result, ext)
            lift, vias, planned_transfer = spec.lift, (), bool(ok)
        except (PlanningError, CollisionError) as exc:
            attempts.append((f"transfer planned around the cell: {exc}", False, float("nan"), ""))
    if not ok:
        description, d, pair, t, _, _, _ = last
        raise CollisionError(
            f"arm {cell_arm.name!r} of cell {cell.name!r} cannot keep {clearance * 1e3:.1f} mm: {pair} blocks "
            f"(closest {d * 1e3:.1f} mm at t = {t:.3f} s of the cycle) after {len(attempts)} attempts, the last with "
            f"{description}; lower the clearance, move the pick/place, or move the fixture"
        )
    # the kept cycle once more with the exact distance at every sample: its true minimum
    final = external.check_motion([ArmMotion(cell_arm.name, result.trajectory)], margin=margin, clearance=clearance,
                                  hold=hold_q, curve=True)
    d, pair, _ = _describe(final)
    ext = final
    report = CellCycleReport(
        cell=cell.name,
        arm=cell_arm.name,
        clearance=clearance,
        margin=float(margin),
        min_clearance=float(d),
        min_clearance_pair=pair,
        lower_bound=float(ext.lower_bound),
        lift=float(lift),
        via=vias,
        cycle_time_without_cell=float(base.cycle_time),
        extra_time=float(result.cycle_time - base.cycle_time),
        attempts=tuple(attempts),
        planned_transfer=planned_transfer,
    )
    return dataclasses.replace(result, cell_report=report)
