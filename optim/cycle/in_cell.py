"""Pick-and-place cycles that keep a clearance from the cell around the arm.

:func:`plan_cycle` with a cell (:class:`CellSettings` in the request) lands here. The cycle
is first planned as without a cell (:func:`pinarms.optim.cycle.straight.approach_cycle`), then
checked continuously in the cell
(:meth:`pinarms.robots.cell.Cell.check_motion`): every pair of the arm with a fixture or another
arm (held still at ``hold``) must keep ``clearance`` [m], and the arm's own links must
not touch (they are designed close, so no clearance is asked of them). When the check
fails, the cycle is re-planned, in this order, until it passes:

1. **raise the transfer**: the vertical lift at pick and place grows by ``lift_step``
   (the transfer then starts and ends higher), up to the highest lift the arm reaches or
   :data:`pinarms.optim.caps.MAX_LIFT_ATTEMPTS` rises;
2. **add a via point** above the middle of the transfer (between "above pick" and
   "above place", at the highest lifted height plus ``lift_step`` per attempt, three
   heights), then two via points at one and two thirds;
3. **plan the transfer** round what blocks (a crate under a guard, a shelf, the other
   arm's column): :func:`pinarms.optim.motion.transfer.planned_cycle` keeps the lift and lowering at
   the spec's height and plans the transfer between them with OMPL, every edge proven
   continuously (:mod:`pinarms.optim.motion`).

Each re-planned cycle is re-timed (time-optimal under the same limits) and re-checked.
With ``CellSettings.screen`` (default), an attempt is first screened by exact distances at a few
of its states, which can only reject it: every closed-form IK solution of its lifted and via
waypoints (:data:`SCREEN_BRANCHES`: its via points are among them), its joint via points before
it is timed (the timed cycle passes through them), its move to place at :data:`SCREEN_SAMPLES` / 2
instants before its move back is timed, then :data:`SCREEN_SAMPLES` instants of the timed cycle
before the continuous check. A state closer than the clearance (by more than :data:`SCREEN_TOL`) proves
the attempt cannot clear, so the screens change no verdict and no kept cycle; a cycle kept is
always the one the continuous check proved.
The result carries a :class:`CellCycleReport`: what was tried, the lift and via points
kept, the smallest clearance, and the extra time against the cycle planned without the
cell. If the pick or the place itself is closer than ``clearance`` to a fixture, or no
attempt clears, :class:`pinarms.errors.CollisionError` says which bodies block and where.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from pinarms.optim.caps import MAX_LIFT_ATTEMPTS
from pinarms.optim.cycle.cell_report import CellCycleReport
from pinarms.optim.cycle.joint import via_points, joint_cycle
from pinarms.optim.cycle.request import CycleRequest
from pinarms.optim.cycle.spec import CycleResult, CycleStatus, PickPlace
from pinarms.optim.cycle.straight import approach_cycle
from pinarms.optim.errors import PlanningError
from pinarms.optim.motion.transfer import planned_cycle
from pinarms.robots.cell import ArmMotion
from pinarms.robots.cell.idle import idle_contacts
from pinarms.errors import CollisionError, InvalidInput, PinarmsError, UnreachableTarget

__all__ = ["CellCycleReport", "plan_cycle_in_cell", "SCREEN_SAMPLES", "SCREEN_TOL", "SCREEN_BRANCHES", "SCREEN_MOVES"]

#: Instants of a timed attempt whose exact distances screen it before the continuous check.
SCREEN_SAMPLES = 48
#: A screened state rejects an attempt only when it is closer than the clearance by more than this [m].
SCREEN_TOL = 1e-6
#: With ``CellSettings.screen``, an attempt is first screened at every closed-form IK solution of its
#: lifted and via waypoints (a batched IK and one batch of distances, ~5 ms on the AUBO-i3, against
#: ~13 ms for its via points on one branch); ``False``: at its via points only (the route before).
SCREEN_BRANCHES = True
#: With ``CellSettings.screen``, an attempt's move to place is screened at ``SCREEN_SAMPLES / 2`` instants
#: before its move back is timed (an exact timing, ~0.1 s on the AUBO-i3); ``False``: the whole cycle
#: timed first (the route before).
SCREEN_MOVES = True
#: Rises of the lift whose branch screens are done in one batch.
AHEAD = 8

def _arm_of(cell: Any, robot: Any, arm: str | None):
    found = _find_arm(cell, robot, arm)
    if any(d.name == found.name for d in getattr(cell, "deltas", ())):
        raise InvalidInput(f"arm {found.name!r} of cell {cell.name!r} is a delta: a cycle in a cell plans a serial "
                           "arm's IK and moves; a delta's picks are planned on the line (optim.line.delta_tracking, "
                           "pinarms belt run --robot delta_flexpicker) and its standard cycle by optim.standard_cycle")
    return found


def _find_arm(cell: Any, robot: Any, arm: str | None):
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


def _describe(check) -> tuple[float, str, float]:
    """(min clearance, pair text, time) of a check, from its first contact or its closest sample."""
    if check.first_contact is not None:
        c = check.first_contact
        return -c.depth, str(c.pair), c.time
    pair = check.min_clearance_pair
    return check.min_clearance, (str(pair) if pair is not None else "none"), check.min_clearance_time


class _Trials:
    """The attempts of one in-cell cycle, in order: each cycle checked continuously in the cell.

    ``external`` holds the arm's pairs with fixtures and other arms (they must keep
    ``clearance``), ``own`` its own links' pairs (no contact), or None when it has none.
    """

    def __init__(self, request: CycleRequest, cell_arm: Any, hold_q: np.ndarray) -> None:
        cell = request.cell.cell
        self.request, self.cell_arm, self.hold_q = request, cell_arm, hold_q
        self.clearance, self.margin = request.cell.clearance, request.cell.margin
        self.external = cell.with_pairs("external")
        self.own = (cell.with_pairs("self") if any(p.kind == "self" and p.owner_a == cell_arm.name for p in cell.pairs)
                    else None)
        self.attempts: list[tuple[str, bool, float, str]] = []
        self.last: tuple[str, float, str, float] | None = None
        self.screen = bool(request.cell.screen)
        self.kept = None  # the continuous check of the last attempt checked
        self._ahead: dict[str, tuple[bytes, tuple[float, str] | None]] = {}  # branch screens done ahead

    def screened(self, description: str, q: np.ndarray, t: np.ndarray | None = None) -> bool:
        """Whether every state ``q (N, n)`` of the arm keeps the clearance (exact distances, module doc).

        A state that does not proves the attempt fails: it is recorded as the attempt, and False
        returned. ``t``: the states' instants in the cycle [s] (None: via points, not yet timed).
        """
        Q = np.repeat(self.hold_q[None], q.shape[0], axis=0)
        Q[:, self.cell_arm.q_slice] = q
        cl = self.external.clearance(Q)
        d = np.atleast_1d(np.asarray(cl.distance, dtype=float))
        k = int(np.argmin(d))
        if d[k] >= self.clearance - SCREEN_TOL:
            return True
        pair = str(cl.pair_of(k))
        self.attempts.append((description, False, float(d[k]), pair))
        self.last = (description, float(d[k]), pair, float("nan") if t is None else float(t[k]))
        return False

    def prescreen(self, items: list[tuple[str, PickPlace]]) -> None:
        """The branch screens (:meth:`branches_screened`) of the coming attempts ``(description, spec)`` in one
        batch (one IK, one batch of distances), kept until each attempt is planned."""
        robot = self.request.robot
        if not (self.screen and SCREEN_BRANCHES and self.request.approach.approach == "joint"):
            return
        poses = [spec.poses(robot)[1:-1] for _, spec in items]
        for (description, _), p, verdict in zip(items, poses, self._branch_rejections(poses)):
            self._ahead[description] = (p.tobytes(), verdict)

    def branches_screened(self, description: str, poses: np.ndarray) -> bool:
        """Whether each waypoint pose ``(K, 4, 4)`` has an IK solution keeping the clearance (module doc).

        The via points are solved on one branch among the closed form's solutions: when every
        solution of one pose is closer than the clearance, so is the attempt's via point, and the
        attempt is recorded as failing (with the best solution's distance) and False returned."""
        known = self._ahead.pop(description, None)
        verdict = known[1] if known is not None and known[0] == poses.tobytes() else \
            self._branch_rejections([poses])[0]
        if verdict is None:
            return True
        self.attempts.append((description, False, verdict[0], verdict[1]))
        self.last = (description, verdict[0], verdict[1], float("nan"))
        return False

    def _branch_rejections(self, pose_sets: list[np.ndarray]) -> list[tuple[float, str] | None]:
        """For each set of waypoint poses: (distance [m], pair) of the first pose every IK solution of which is
        closer than the clearance (the best solution's), or None. Only poses whose solutions do not depend on
        the reference configuration (two references, the same solutions: not at a singularity, where a free
        joint follows the reference) count; a set with a pose without solution, and an arm without a
        closed form, give None (the via points decide and name the pose)."""
        robot = self.request.robot
        out: list[tuple[float, str] | None] = [None] * len(pose_sets)
        sizes = [p.shape[0] for p in pose_sets]
        if not getattr(robot, "has_analytic_ik", False) or sum(sizes) == 0:
            return out
        flat = np.concatenate(pose_sets)
        other = np.clip(np.asarray(robot.neutral, dtype=float) + 1.0, robot.lower, robot.upper)
        try:
            sols = robot.ik_all(flat, equivalents=True)
            again = robot.ik_all(flat, q_ref=other, equivalents=True)
        except PinarmsError:
            return out
        bounds = np.cumsum([0] + sizes)
        keep = [[k for k in range(bounds[i], bounds[i + 1]) if sols[k].shape[0] and _same_rows(sols[k], again[k])]
                if all(sols[k].shape[0] for k in range(bounds[i], bounds[i + 1])) else []
                for i in range(len(pose_sets))]
        rows = [sols[k] for ks in keep for k in ks]
        if not rows:
            return out
        Q = np.repeat(self.hold_q[None], sum(r.shape[0] for r in rows), axis=0)
        Q[:, self.cell_arm.q_slice] = np.concatenate(rows)
        cl = self.external.clearance(Q)
        d = np.atleast_1d(np.asarray(cl.distance, dtype=float))
        start = 0
        for i, ks in enumerate(keep):
            for k in ks:
                n = sols[k].shape[0]
                best = start + int(np.argmax(d[start : start + n]))
                start += n
                if out[i] is None and d[best] < self.clearance - SCREEN_TOL:
                    out[i] = (float(d[best]), str(cl.pair_of(best)))
        return out

    def move_screened(self, description: str, move: Any, offset: float) -> bool:
        """:meth:`screened` at :data:`SCREEN_SAMPLES` / 2 instants of the timed move to place (``offset`` [s]:
        its start in the cycle, after the dwell at the pick)."""
        t = np.linspace(move.start_time, move.end_time, SCREEN_SAMPLES // 2)
        return self.screened(description, np.asarray(move.sample(t)[0], dtype=float), t - move.start_time + offset)

    def check(self, description: str, result: CycleResult) -> bool:
        """Check ``result`` in the cell and record the attempt: whether it keeps the clearance."""
        if self.screen:
            traj = result.trajectory
            t = np.linspace(traj.start_time, traj.end_time, SCREEN_SAMPLES)
            if not self.screened(description, np.asarray(traj.sample(t)[0], dtype=float), t - traj.start_time):
                return False
        motion = ArmMotion(self.cell_arm.name, result.trajectory)
        ext = self.external.check_motion([motion], margin=self.margin, clearance=self.clearance, hold=self.hold_q)
        # the arm's own links only when the fixtures and other arms are kept clear (else the attempt fails anyway)
        slf = self.own.check_motion([motion], margin=self.margin, hold=self.hold_q) \
            if self.own is not None and ext.clear else None
        ok = ext.clear and (slf is None or slf.collision_free)
        bad = ext if not ext.clear or slf is None else slf
        d, pair, t = _describe(bad if not ok else ext)
        self.attempts.append((description, bool(ok), float(d), pair))
        self.last = (description, d, pair, t)
        self.kept = ext
        return bool(ok)

    def plan(self, description: str, spec: PickPlace) -> tuple[bool, CycleResult | None]:
        """Plan ``spec`` as without the cell and check it (UnreachableTarget: the spec is out of reach).

        Screened first (joint approach): a via point closer than the clearance rejects it untimed (None)."""
        request = dataclasses.replace(self.request, spec=spec)
        if self.screen and request.approach.approach == "joint":
            robot = request.robot
            if SCREEN_BRANCHES and not self.branches_screened(description, spec.poses(robot)[1:-1]):
                return False, None
            via = via_points(robot, spec.poses(robot), spec.names, request.q_start)  # as the cycle will have them
            if not self.screened(description, via[0]):
                return False, None
            there_clear = (lambda move: self.move_screened(description, move, spec.dwell)) if SCREEN_MOVES else None
            result = joint_cycle(request, via=via, there_clear=there_clear)
            if result is None:  # the move to place is closer than the clearance: the move back untimed
                return False, None
            return self.check(description, result), result
        result = approach_cycle(request)
        return self.check(description, result), result

    def failure(self, cell: Any) -> CollisionError:
        """The error when no attempt cleared: what blocks, where, after how many attempts."""
        description, d, pair, t = self.last
        when = f"t = {t:.3f} s of the cycle" if np.isfinite(t) else "a via point"
        return CollisionError(
            f"arm {self.cell_arm.name!r} of cell {cell.name!r} cannot keep {self.clearance * 1e3:.1f} mm: {pair} "
            f"blocks (closest {d * 1e3:.1f} mm at {when}) after {len(self.attempts)} attempts, "
            f"the last with {description}; lower the clearance, move the pick/place, or move the fixture"
        )


def _same_rows(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two solution sets ``(k, n)`` hold the same rows (any order, within 1e-9)."""
    if a.shape != b.shape:
        return False
    return bool(np.allclose(a[np.lexsort(a.T[::-1])], b[np.lexsort(b.T[::-1])], rtol=0.0, atol=1e-9))


def _check_ends(trials: _Trials, base: CycleResult) -> None:
    """The pick and the place themselves must keep the clearance: no re-planning moves them."""
    cell_arm = trials.cell_arm
    for label, q in (("pick", base.q_via[0]), ("place", base.q_via[len(base.spec.names) - 1])):
        q_cell = trials.hold_q.copy()
        q_cell[cell_arm.q_slice] = q
        cl = trials.external.clearance(q_cell)
        if cl.distance < trials.clearance:
            raise CollisionError(
                f"the {label} pose of arm {cell_arm.name!r} is {cl.distance * 1e3:.1f} mm from {cl.pair_of().body_b} "
                f"({cl.pair_of()}), less than the clearance {trials.clearance * 1e3:.1f} mm: move the {label} point "
                "(re-planning the transfer cannot move it)"
            )


def _raise_lift(trials: _Trials, spec: PickPlace, lift_step: float) -> tuple[bool, CycleResult | None, float]:
    """Step 1: raise the lift by ``lift_step`` until the cycle clears, the arm's reach ends, or the cap."""
    lift, ok, result = spec.lift, False, None
    for i in range(MAX_LIFT_ATTEMPTS):  # bounded: the arm's reach usually ends the rise first
        if i % AHEAD == 0:  # the next few rises' branch screens in one batch
            ahead, lifts = lift, []
            for _ in range(min(AHEAD, MAX_LIFT_ATTEMPTS - i)):
                ahead += lift_step
                lifts.append(ahead)
            trials.prescreen([(f"lift {x:.3f} m", dataclasses.replace(spec, lift=x)) for x in lifts])
        lift += lift_step
        try:
            ok, result = trials.plan(f"lift {lift:.3f} m", dataclasses.replace(spec, lift=lift))
        except UnreachableTarget:
            lift -= lift_step
            break
        if ok:
            break
    return ok, result, lift


def _add_vias(trials: _Trials, spec: PickPlace, top: float,
              lift_step: float) -> tuple[bool, CycleResult | None, tuple]:
    """Step 2: at the highest lift ``top``, one via point mid-transfer, then two at thirds, three heights."""
    robot = trials.request.robot
    poses = dataclasses.replace(spec, lift=top).poses(robot)
    above_pick, above_place = poses[1][:3, 3], poses[-2][:3, 3]
    height = max(above_pick[2], above_place[2])
    tries = []
    for k in range(1, 4):
        for fractions in ((0.5,), (1.0 / 3.0, 2.0 / 3.0)):
            points = []
            for f in fractions:
                p = above_pick + f * (above_place - above_pick)
                p[2] = height + k * lift_step
                points.append(p)
            tries.append((f"lift {top:.3f} m, {len(points)} via point(s) at z = {height + k * lift_step:.3f} m",
                          dataclasses.replace(spec, lift=top, via=tuple(spec.via) + tuple(points)), points))
    trials.prescreen([(description, attempt) for description, attempt, _ in tries])
    for description, attempt, points in tries:
        try:
            ok, result = trials.plan(description, attempt)
        except UnreachableTarget:
            continue
        if ok:
            return True, result, tuple(tuple(float(x) for x in p) for p in points)
    return False, None, ()


def _plan_transfer(trials: _Trials, base: CycleResult) -> tuple[bool, CycleResult | None]:
    """Step 3: the transfer planned round what blocks (OMPL, :mod:`pinarms.optim.motion`), checked like the others."""
    request = trials.request
    try:
        result = planned_cycle(request, base, arm=trials.cell_arm, hold=trials.hold_q)
        move = result.moves[0]
        ok = trials.check(f"lift {request.spec.lift:.3f} m, transfer planned by {move.planner} ({move.states} states)",
                          result)
        return ok, result
    except (PlanningError, CollisionError) as exc:
        trials.attempts.append((f"transfer planned around the cell: {exc}", False, float("nan"), ""))
        return False, None


def plan_cycle_in_cell(request: CycleRequest) -> CycleResult:
    """Plan the cycle of ``request`` (its robot an arm of ``request.cell.cell``) keeping its clearance (module doc).

    Raises:
        InvalidInput: the robot is not an arm of the cell (or not arm ``request.cell.arm``).
        CollisionError: the pick or place pose is too close to a fixture, or no re-planned
            cycle keeps the clearance; the message names the blocking bodies. An arm that does
            not move touching something at its hold pose: the message names the idle arm.
    """
    settings, spec = request.cell, request.spec
    cell = settings.cell
    cell_arm = _arm_of(cell, request.robot, settings.arm)
    hold_q = cell.hold if settings.hold is None else cell.robot.check_q(settings.hold)[0][0]
    idle = idle_contacts(cell, hold_q, [cell_arm.name])
    if idle:  # every attempt would fail on the idle arm: name it now
        raise CollisionError(idle.message("hold in the cell description, or CellSettings(hold=...)"))
    trials = _Trials(request, cell_arm, hold_q)

    base = approach_cycle(request)  # the cycle as planned without the cell: the first attempt
    _check_ends(trials, base)
    ok, result = trials.check(f"lift {spec.lift:.3f} m", base), base
    lift, vias, status = spec.lift, (), CycleStatus.OK
    if not ok:
        ok, result, lift = _raise_lift(trials, spec, settings.lift_step)
        status = CycleStatus.REPLANNED
    if not ok:
        top = max(lift, spec.lift)
        ok, result, vias = _add_vias(trials, spec, top, settings.lift_step)
        lift = top if ok else lift
    if not ok and settings.plan_transfer:
        ok, result = _plan_transfer(trials, base)
        lift, vias, status = spec.lift, (), CycleStatus.TRANSFER_PLANNED
    if not ok:
        raise trials.failure(cell)
    report = _report(trials, result, base, lift, vias, planned_transfer=status is CycleStatus.TRANSFER_PLANNED)
    return dataclasses.replace(result, cell_report=report, status=status)


def _report(trials: _Trials, result: CycleResult, base: CycleResult, lift: float, vias: tuple,
            planned_transfer: bool) -> CellCycleReport:
    """The kept cycle once more with the exact distance at every sample (its true minimum), and what was tried.

    Without ``CellSettings.recheck``: the kept cycle's own continuous check (its samples' minimum)."""
    final = trials.kept
    if trials.request.cell.recheck or final is None:
        motion = ArmMotion(trials.cell_arm.name, result.trajectory)
        final = trials.external.check_motion([motion], margin=trials.margin, clearance=trials.clearance,
                                             hold=trials.hold_q, curve=True)
    d, pair, _ = _describe(final)
    return CellCycleReport(
        cell=trials.request.cell.cell.name,
        arm=trials.cell_arm.name,
        clearance=trials.clearance,
        margin=float(trials.margin),
        min_clearance=float(d),
        min_clearance_pair=pair,
        lower_bound=float(final.lower_bound),
        lift=float(lift),
        via=vias,
        cycle_time_without_cell=float(base.cycle_time),
        extra_time=float(result.cycle_time - base.cycle_time),
        attempts=tuple(trials.attempts),
        planned_transfer=planned_transfer,
    )
