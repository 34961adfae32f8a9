"""Neighbouring arms whose windows overlap: their picks proven clear by the cell's continuous check.

:class:`NeighbourGuard` is the ``guard`` of :func:`pinarms.optim.line.simulate.simulate`. For two picks
(one starting now, one under way at a neighbour) it plans both exactly
(:func:`pinarms.optim.line.tracking.plan_pick`, cached per arm and item), places each on the cell's
clock so that its rendezvous is at the simulated rendezvous time, and proves them over the time
both move at the clearance asked (arm–arm and arm–fixture pairs, continuously in time): the compiled
cover check (:func:`pinarms.optim.motion.fast_check`) where it proves, :meth:`pinarms.robots.cell.Cell.check_motion`
otherwise (:class:`~.fixtures.PairCheck`). The stations must be arms of the cell (same
names, same bases). A pick that exact planning cannot make (near the edge of the window, where
the map interpolates feasibility) is not proven clear: the guard says no.

A delta station (:class:`~.delta_tracking.DeltaArm`, a delta of the cell: docs/cells.md) has its pick on
the clock from :func:`~.delta_pick_path.delta_pick_plan` (its platform path along the time-optimal
profiles, a proven speed bound); in a cell with a delta every pair goes through the cell's exact check
alone (the compiled cover knows only the tree's geometry, not the delta's bodies).
"""

from __future__ import annotations

from typing import Any, Sequence, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.delta_pick_path import delta_pick_plan
from pinarms.optim.line.delta_tracking import DeltaArm
from pinarms.optim.line.items import ItemType
from pinarms.optim.line.sim_loop import Pick
from pinarms.optim.line.station import Station
from pinarms.optim.line.tracking import TrackingSpec, plan_pick
from pinarms.errors import InvalidInput, PinarmsError

if TYPE_CHECKING:
    from pinarms.robots.cell.cell import Cell

__all__ = ["NeighbourGuard"]


class NeighbourGuard:
    """Whether two neighbours' picks keep ``clearance`` [m] (module doc); ``margin`` [m] sets
    the check's time step. ``checks`` counts the continuous checks run; ``counts``: of those, proven
    by the fast route, sent to the exact one, found not clear."""

    def __init__(self, cell: Cell, stations: Sequence[Station], belt: Belt, tracking: TrackingSpec,
                 types: Sequence[ItemType], *, clearance: float = 0.01, margin: float = 0.01,
                 maps: dict | None = None, yaws: ArrayLike | None = None) -> None:
        self.cell, self.belt, self.tracking, self.types = cell, belt, tracking, tuple(types)
        self.stations = {s.name: s for s in stations}
        for s in stations:
            try:
                arm = cell.arm(s.name)
            except PinarmsError:
                raise InvalidInput(f"station {s.name!r} is not an arm of cell {cell.name!r}") from None
            if np.abs(arm.base_to_world - s.base_to_world).max() > 1e-9:
                raise InvalidInput(f"station {s.name!r} stands elsewhere than the cell's arm of that name")
            if isinstance(s.robot, DeltaArm) != (s.name in {d.name for d in cell.deltas}):
                raise InvalidInput(f"station {s.name!r} and the cell's arm of that name are not both deltas: place a "
                                   "delta station's delta in the cell description (delta = \"<name>\")")
        self.clearance, self.margin = float(clearance), float(margin)
        self._plans: dict = {}
        self.maps = maps or {}  # {station: task maps}: each pick on the IK branch its map chose
        self.yaws = None if yaws is None else np.asarray(yaws, float)  # per item [rad]: the hand turns to it
        self.checks = 0
        self._pairs: dict = {}
        self.fast = True  #: False: every check through the cell's exact continuous check alone

    @property
    def counts(self) -> dict[str, int]:
        out = {"fast": 0, "exact": 0, "blocked": 0}
        for p in self._pairs.values():
            for k in out:
                out[k] += p.counts[k]
        return out

    def _plan(self, pick: Pick | tuple) -> Any:
        pick = Pick(*pick)
        name, item, u, w, kind = pick.arm, pick.item, pick.u, pick.w, pick.kind
        key = (name, item)
        if key not in self._plans:
            t, st = self.types[kind], self.stations[name]
            branch = None
            if name in self.maps:
                u_base = float(self.belt.to_belt(st.base_to_world[:3, 3])[0])
                branch = self.maps[name][kind].branch_at(u - u_base, w, None if self.yaws is None else self.yaws[item])
            yaw = 0.0 if self.yaws is None else float(self.yaws[item])
            if isinstance(st.robot, DeltaArm):  # the tool's turn moves no body: the path alone
                self._plans[key] = delta_pick_plan(st, self.belt, self.tracking, u, w, item_height=t.size[2],
                                                   mass=t.mass)
                return self._plans[key]
            self._plans[key] = plan_pick(st, self.belt, self.tracking, u, w, item_height=t.size[2], mass=t.mass,
                                         branch=branch, yaw=yaw)
        return self._plans[key]

    def __call__(self, pick: Pick | tuple, other: Pick | tuple) -> bool:
        """Whether ``pick`` (starting now) keeps the clearance from ``other`` (under way): each a
        :class:`~.sim_loop.Pick` or a tuple of its seven fields in order."""
        from pinarms.robots.cell import ArmMotion

        try:
            a, b = self._plan(pick), self._plan(other)
        except PinarmsError:
            return False  # exact planning fails where the map interpolates: not proven clear

        # each pick on the cell's clock with its rendezvous at the simulated time
        pick, other = Pick(*pick), Pick(*other)
        off_a, off_b = pick.meet - a.times[0], other.meet - b.times[0]
        t0 = max(off_a, off_b)
        t1 = min(off_a + a.duration, off_b + b.duration)
        if t1 <= t0:
            return True
        motions = [ArmMotion(pick.arm, a.trajectory, off_a), ArmMotion(other.arm, b.trajectory, off_b)]
        self.checks += 1
        if not self.fast or self.cell.deltas:   # the compiled cover sees only the tree, not a delta's bodies
            res = self.cell.check_motion(motions, margin=self.margin, clearance=self.clearance, window=(t0, t1))
            return bool(res.clear if self.clearance > 0 else res.collision_free)
        key = (pick.arm, other.arm)
        if key not in self._pairs:
            from pinarms.optim.line.fixtures import PairCheck

            self._pairs[key] = PairCheck(self.cell, key, self.clearance)
        return self._pairs[key].clear(motions, (t0, t1), self.margin)
