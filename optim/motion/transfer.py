"""The planned transfer: what ``plan_cycle`` in a cell falls back to when raising it cannot clear.

:func:`pinarms.optim.plan_cycle` with a cell first re-plans its transfer by raising the lift and
adding via points (:mod:`pinarms.optim.cycle.in_cell`). A crate under a guard, a shelf or the other
arm's column defeat that: the way round is sideways or underneath. :func:`planned_cycle`
then keeps the vertical moves at pick and place (the cycle's lift and lowering, joint-space
lines or the straight Cartesian lines of ``approach="straight"``), proves them clear, and
plans the transfer between "above pick" and "above place" with :func:`pinarms.optim.plan_motion`'s
search, shortcut and smoothing (OMPL, every edge proven continuously); the move back runs
the same path in reverse. Each part is timed optimally from rest to rest under the cycle's
limits (joint velocity and acceleration; the URDF's torque limits when no acceleration
limit is given) and the parts are joined at rest. The cycle (dwells, move to place, move
back) is returned as a :class:`pinarms.optim.CycleResult` whose moves are :class:`PlannedMove` s.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from pinarms.optim.cycle.vertical import at_rest, line_deviation, vertical_segments
from pinarms.optim.motion.checker import MotionChecker
from pinarms.optim.motion.geometry import plan_geometry
from pinarms.optim.motion.plan import time_path
from pinarms.optim.motion.request import MotionLimits, MotionOptions, motion_constraints
from pinarms.optim.motion.smoothing import polyline_path, prove_path, smooth_path
from pinarms.planning import Trajectory
from pinarms.errors import CollisionError, InvalidInput

if TYPE_CHECKING:
    from pinarms.optim.cycle.request import CycleRequest
    from pinarms.optim.cycle.spec import CycleResult
    from pinarms.robots import Robot
    from pinarms.robots.cell import CellArm

__all__ = ["PlannedMove", "planned_cycle"]


@dataclass(frozen=True, eq=False)
class PlannedMove:
    """One move of a cycle with a planned transfer: the lift, the transfer, the lowering (at rest between).

    Attributes:
        parts: the three timings (:class:`pinarms.optim.PathTiming`).
        trajectory: the three concatenated.
        planner: the OMPL planner that found the transfer; ``states``: the states it explored.
    """

    parts: tuple = field(repr=False)
    trajectory: Trajectory = field(repr=False)
    planner: str = ""
    states: int = 0
    robot: Robot | None = field(default=None, repr=False)
    torque_limit: np.ndarray | None = field(default=None, repr=False)

    @property
    def durations(self) -> np.ndarray:
        """(3,) [s]: lift, transfer, lowering."""
        return np.array([p.duration for p in self.parts])

    @property
    def total(self) -> float:
        """Duration of the move [s]."""
        return float(self.durations.sum())

    @property
    def knot_times(self) -> np.ndarray:
        """Boundaries of the three parts [s] (the first and the last part are the vertical moves)."""
        return np.concatenate([[0.0], np.cumsum(self.durations)])

    @property
    def line_cost(self) -> float:
        """0: the lines are the cycle's own (their cost is reported by the cycle they come from)."""
        return 0.0

    @property
    def torque_ratios(self) -> np.ndarray | None:
        """Peak torque / limit per joint along the move (None without a torque limit)."""
        if self.torque_limit is None or self.robot is None:
            return None
        return self.trajectory.torque_peaks(self.robot).ratios(self.torque_limit)


def _lines(base: Any, k: int) -> tuple[list, list]:
    """(lift, lowering) paths of the move to place and of the move back, and their kind."""
    q = base.q_via
    if base.approach == "straight":
        there = [base.moves[0].lines[0].path, base.moves[0].lines[1].path]
        back = [base.moves[1].lines[0].path, base.moves[1].lines[1].path]
        return there, back
    pick, up_pick, up_place, place = q[0], q[1], q[k - 2], q[k - 1]
    return ([polyline_path(np.stack([pick, up_pick])), polyline_path(np.stack([up_place, place]))],
            [polyline_path(np.stack([place, up_place])), polyline_path(np.stack([up_pick, pick]))])


def _parts_of(piece: Trajectory) -> list:
    """The definitions of ``piece``'s parts (one copy of its definition; a concatenation gives its parts)."""
    d = piece.definition
    return d["parts"] if d.get("kind") == "concatenated" else [d]


def _joined(pieces: list, parts: list | None = None, atol: float = 1e-7) -> Trajectory:
    """The trajectories one after the other, as :meth:`Trajectory.concatenated` in turn gives them.

    ``parts``: each piece's part definitions (:func:`_parts_of`), when the caller has them: a
    timed path's definition is long, and a trajectory's definition is copied at each reading
    (copying the growing concatenation at every step took a third of a planned transfer; the
    cycle and its two moves share the copies, a trajectory never changes its definition)."""
    from pinarms.planning.errors import TrajectoryError
    from pinarms.planning.poly_pieces import pad_degree

    width = max(p.degree for p in pieces) + 1
    breaks, coefs = pieces[0].knot_times, [pad_degree(pieces[0].coefficients, width)]
    for prev, nxt in zip(pieces, pieces[1:]):
        gap = np.abs(prev.sample(prev.end_time)[0] - nxt.sample(nxt.start_time)[0])
        if np.any(gap > atol):
            raise TrajectoryError(f"position jump of {gap.max():.3g} at a junction of the planned cycle "
                                  f"(atol {atol:g})")
        k = nxt.knot_times
        breaks = np.concatenate([breaks, k[1:] - k[0] + breaks[-1]])
        coefs.append(pad_degree(nxt.coefficients, width))
    parts = [_parts_of(p) for p in pieces] if parts is None else parts
    return Trajectory(breaks, np.concatenate(coefs, axis=0),
                      {"kind": "concatenated", "parts": [d for piece in parts for d in piece]})


def planned_cycle(request: CycleRequest, base: CycleResult, *, arm: CellArm, hold: np.ndarray,
                  planner: str = "rrtconnect", time_limit: float = 5.0) -> CycleResult:
    """The cycle ``base`` (the request planned without its cell) with its transfer planned around the cell.

    Args:
        request: the cycle's :class:`pinarms.optim.CycleRequest`, with its :class:`pinarms.optim.CellSettings`:
            ``clearance`` kept from fixtures and other arms [m] (the arm's own links: no
            contact), ``margin`` the check's resolution when ``clearance`` is 0; the search is
            seeded with ``request.timing.seed``.
        base: the :class:`pinarms.optim.CycleResult` of the request without the cell (its via points
            fix the IK branch; its limits are used).
        arm: the :class:`pinarms.robots.cell.CellArm`; ``hold``: the cell configuration of the other arms.

    Raises:
        InvalidInput: a request without a cell.
        CollisionError: a vertical move itself is too close to something (no transfer can
            help), or :class:`pinarms.optim.NoPathFound` (a :class:`PlanningError`): no transfer found.
    """
    if request.cell is None:
        raise InvalidInput("planned_cycle plans a cycle in a cell: give the request a CellSettings")
    robot, spec, cell, seed = request.robot, request.spec, request.cell.cell, int(request.timing.seed)
    clearance, margin = request.cell.clearance, request.cell.margin
    k = len(spec.names)
    q = base.q_via
    checker = MotionChecker(cell, [arm.name], margin=clearance if clearance > 0.0 else margin, hold=hold)
    there, back = _lines(base, k)
    for label, path in (("lift at the pick", there[0]), ("lowering at the place", there[1])):
        verdict, _ = prove_path(checker, path)
        if not verdict.ok:
            raise CollisionError(f"the {label} of arm {arm.name!r} itself comes closer than "
                                 f"{checker.margin * 1e3:.1f} mm to something: no transfer can clear it; move the "
                                 "pick/place or lower the lift")
    options = MotionOptions(margin=checker.margin, planner=planner, time_limit=time_limit, seed=seed)
    # the transfer ends where the lowering at the place starts: its continuous joints as the cycle's IK gave them
    geo = plan_geometry(checker, (arm.name,), q[1], q[k - 2], options, nearest=False)
    transfer = geo["path"]
    reverse, _, _ = smooth_path(checker, geo["simplified"][::-1], arm.robot)
    amax = base.amax
    torque = True if amax is None and base.torque_limit is None else (base.torque_limit
                                                                       if base.torque_limit is not None else False)
    constraints, _ = motion_constraints(cell, (arm.name,), MotionLimits(vmax=base.vmax, amax=amax, torque=torque))

    def move(paths: list) -> tuple[PlannedMove, list]:
        parts = tuple(time_path(p, constraints) for p in paths)
        defs = [_parts_of(p.trajectory) for p in parts]
        traj = _joined([p.trajectory for p in parts], defs)
        return PlannedMove(parts, traj, geo["planner"], geo["states"], arm.robot, base.torque_limit), \
            [d for part in defs for d in part]

    (m1, d1), (m2, d2) = move([there[0], transfer, there[1]]), move([back[0], reverse, back[1]])
    pieces, defs = [m1.trajectory, m2.trajectory], [d1, d2]
    if spec.dwell > 0.0:
        holds = [at_rest(q[0], spec.dwell), at_rest(q[k - 1], spec.dwell)]
        pieces = [holds[0], pieces[0], holds[1], pieces[1]]
        defs = [_parts_of(holds[0]), d1, _parts_of(holds[1]), d2]
    trajectory = _joined(pieces, defs)
    ends = vertical_segments(spec.poses(robot))
    return dataclasses.replace(base, moves=(m1, m2), trajectory=trajectory, peaks=trajectory.peaks(),
                               line_deviation=line_deviation(robot, (m1, m2), ends))
