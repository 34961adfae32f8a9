"""What a layout search is asked: :class:`LayoutRequest`, one frozen object checked when built,
and :class:`LayoutStatus`, what :func:`pinarms.optim.layout.search_layout` found.

Statuses and exceptions (:mod:`pinarms.optim.status`): a malformed request (points, candidates,
orientation, counts beyond :mod:`pinarms.optim.caps`, an unknown cycle kind, an arm or fixture the cell
does not have) raises when the request is built, before any work; a search that runs but finds
no placement able to run the cycle is a :class:`LayoutSearch` with status
:attr:`LayoutStatus.NO_PLACEMENT` and a ``status_reason`` counting the failures.
Units: m, rad, s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from pinarms.optim.caps import (MAX_CLEARANCE, MAX_PLACEMENTS, MAX_POINT_PAIRS, MAX_REFINE, MAX_REFINE_EVALUATIONS,
                               MAX_WORKSPACE_SAMPLES, count_setting, number_setting)
from pinarms.optim.cycle import CYCLE_KINDS, PickPlace
from pinarms.optim.errors import InvalidSettings, SettingOutOfRange
from pinarms.optim.status import Status
from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.robots.cell import Cell
    from pinarms.robots.robot import Robot

__all__ = ["LayoutRequest", "LayoutStatus", "is_cell"]


class LayoutStatus(Status):
    """What a layout search found (the value is the word printed)."""

    #: at least one placement runs the cycle: ``best_placement`` is set
    FOUND = "found"
    #: every candidate failed (``status_reason`` counts them by :data:`FAILURES`)
    NO_PLACEMENT = "no placement"


def is_cell(target: object) -> bool:
    """Whether ``target`` is a cell (its arm is moved among its fixtures) rather than a robot."""
    return hasattr(target, "arms") and hasattr(target, "with_arm_base")


def _points(value: object, what: str) -> np.ndarray:
    try:
        P = np.atleast_2d(np.asarray(value, dtype=float))
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be points (3,) or (N, 3) in m, got {value!r}") from exc
    if P.ndim != 2 or P.shape[1] != 3 or P.shape[0] == 0:
        raise InvalidInput(f"{what} must be points (3,) or (N, 3) in m, got shape {np.shape(value)}")
    if not np.all(np.isfinite(P)):
        raise InvalidInput(f"{what} holds NaN or inf")
    return P


@dataclass(frozen=True, eq=False)
class LayoutRequest:
    """A layout search: which arm, which points, which placements, which cycle.

    Attributes:
        robot: a :class:`pinarms.robots.Robot` (the arm to place), or a :class:`pinarms.robots.cell.Cell`:
            then the arm ``arm`` of the cell (its only arm by default) is moved among the
            cell's fixtures (the line frame is the cell's world; :meth:`Cell.with_arm_base`,
            the fixtures named in ``carry``, e.g. its stand, move with it) and every cycle
            must keep ``clearance`` [m] from the fixtures and the other arms
            (:func:`pinarms.optim.plan_cycle` with a cell: re-planned with a higher lift or via
            points when needed); a candidate whose cycle cannot clear fails as ``"collision"``.
            ``screen``: each re-planning attempt is first screened by exact distances at its
            via points and a few timed states (:class:`pinarms.optim.CellSettings`; proofs of failure
            only, so the same verdicts; ``False``: every attempt timed and checked in full).
        picks, places: points ``(3,)`` or ``(N, 3)`` in the line frame [m]; every pick is
            paired with every place (stored as ``(P, 3)``, ``(Q, 3)`` float arrays).
        candidates: placements ``(M, 4)`` ``(x, y, z, yaw)`` of the base in the line frame
            [m, rad] (:func:`grid_candidates`, :func:`random_candidates`).
        lift, dwell, kind, vmax, amax, jmax: the cycle (see :class:`pinarms.optim.PickPlace` and
            :func:`pinarms.optim.plan_cycle`); limits per joint (scalar or ``(nq,)``), None: the
            robot's (``vmax``) or none (``amax``, ``jmax``).
        orientation: tool orientation ``(3, 3)`` in the line frame at the points; default
            the robot's (tool down for six-axis arms), in its base frame.
        min_margin: smallest boundary margin [m] a pick or place may have; candidates below
            fail as ``"boundary"`` before any cycle is planned (0: no such rule). The fastest
            cycles are often near the edge of the workspace, where the arm is stretched.
        refine: how many of the best candidates start a continuous search (0: none).
        refine_evaluations: cycles each continuous search may plan.
        workspace_samples: samples of the workspace whose voxel map gives the boundary margins.
        seed: seed of the workspace samples and of the timing optimiser (results repeat).
        chunk_size: candidates per task (a task plans ``chunk_size × pairs`` cycles, ~0.5 s each
            for a six-axis arm).
        bound: branch and bound (:mod:`pinarms.optim.layout.bound`): the candidates are planned in
            increasing order of a proven lower bound of their cycle time, and those that cannot
            reach the first ``max(1, refine)`` places of the ranking are not planned (they fail
            as ``"outranked"``): the best placement, the refinement starts and every planned
            candidate's outcome are those of the exhaustive search (``False``, default).

    Raises (when built):
        InvalidInput: malformed points, candidates or orientation; ``arm``/``carry`` without a
            cell, or naming what the cell does not have.
        SettingOutOfRange: a count or a distance outside its cap (named, with the range).
        InvalidSettings: unknown ``kind``.
    """

    robot: Robot | Cell
    picks: np.ndarray
    places: np.ndarray
    candidates: np.ndarray
    lift: float = 0.05
    dwell: float = 0.2
    orientation: np.ndarray | None = None
    kind: str = "multi-quintic"
    vmax: float | np.ndarray | None = None
    amax: float | np.ndarray | None = None
    jmax: float | np.ndarray | None = None
    refine: int = 2
    refine_evaluations: int = 30
    workspace_samples: int = 200_000
    seed: int = 0
    chunk_size: int = 4
    arm: str | None = None
    clearance: float = 0.02
    carry: tuple[str, ...] = ()
    min_margin: float = 0.0
    screen: bool = True
    bound: bool = False

    def __post_init__(self) -> None:
        self._check_target()
        picks, places = _points(self.picks, "picks"), _points(self.places, "places")
        cand = np.asarray(self.candidates, dtype=float) if not isinstance(self.candidates, str) else np.zeros(0)
        if cand.ndim != 2 or cand.shape[1] != 4 or cand.shape[0] == 0 or not np.all(np.isfinite(cand)):
            raise InvalidInput(f"candidates must be finite placements (M, 4) = (x, y, z, yaw) [m, rad], "
                               f"got shape {cand.shape}")
        if self.kind not in CYCLE_KINDS:
            raise InvalidSettings(f"kind={self.kind!r}: use one of {CYCLE_KINDS}")
        if cand.shape[0] > MAX_PLACEMENTS:
            raise SettingOutOfRange(f"{cand.shape[0]:,} candidates, more than the {MAX_PLACEMENTS:,} a layout search takes")
        if len(picks) * len(places) > MAX_POINT_PAIRS:
            raise SettingOutOfRange(f"{len(picks)} picks × {len(places)} places = {len(picks) * len(places):,} "
                                    f"cycles per placement, more than the {MAX_POINT_PAIRS:,} allowed: give fewer points")
        for name, least, most in (("refine", 0, MAX_REFINE), ("refine_evaluations", 1, MAX_REFINE_EVALUATIONS),
                                  ("workspace_samples", 1000, MAX_WORKSPACE_SAMPLES),
                                  ("chunk_size", 1, MAX_PLACEMENTS), ("seed", 0, 2**64 - 1)):
            count_setting(getattr(self, name), name, least, most)
        R = None
        if self.orientation is not None:
            R = np.asarray(self.orientation, dtype=float)
            if R.shape != (3, 3) or not np.all(np.isfinite(R)) or np.abs(R @ R.T - np.eye(3)).max() > 1e-6 \
                    or np.linalg.det(R) < 0:
                raise InvalidInput(f"orientation must be a (3, 3) proper rotation matrix, got {self.orientation!r}")
        PickPlace(picks[0], places[0], lift=self.lift, dwell=self.dwell)  # checks lift and dwell (names them)
        number_setting(self.min_margin, "min_margin", 0.0, unit="m")
        for name, value in (("picks", picks), ("places", places), ("candidates", cand), ("orientation", R)):
            if value is not None:  # the request owns its arrays: a copy the caller cannot change
                value = np.array(value, dtype=float)
                value.setflags(write=False)
            object.__setattr__(self, name, value)
        object.__setattr__(self, "carry", tuple(self.carry))

    def _check_target(self) -> None:
        """The arm to place: a cell's named arm (its only one by default) and fixtures, or a robot alone."""
        if is_cell(self.robot):
            cell = self.robot
            if self.arm is None:
                if len(cell.arms) != 1:
                    raise InvalidInput(f"cell {cell.name!r} has arms {[a.name for a in cell.arms]}: "
                                       "name the one to place (arm=)")
                object.__setattr__(self, "arm", cell.arms[0].name)
            cell.arm(self.arm)
            number_setting(self.clearance, "clearance", 0.0, MAX_CLEARANCE, unit="m")
            for name in self.carry:
                cell.fixture(name)
        elif self.arm is not None or self.carry:
            raise InvalidInput("arm= and carry= name an arm and fixtures of a cell: pass the cell as robot")

    @property
    def arm_robot(self) -> Robot:
        """The arm placed: ``robot`` itself, or the cell's arm ``arm``."""
        return self.robot.arm(self.arm).robot if is_cell(self.robot) else self.robot
