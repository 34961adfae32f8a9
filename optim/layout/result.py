"""What a layout search returns: :class:`LayoutSearch` (every candidate's figures, ranked)
and :class:`Refinement` (the gain of the refined starts).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pinarms.optim.cycle import CycleResult

from pinarms.optim.layout.candidates import FAILURES, CandidateFailure
from pinarms.optim.layout.request import LayoutStatus

__all__ = ["LayoutSearch", "Refinement"]


# ----------------------------------------------------------------------- results
@dataclass(frozen=True)
class Refinement:
    """The continuous improvement of the best grid candidates.

    Attributes:
        starts: ``(k,)`` indices of the candidates started from.
        start_picks_per_minute: ``(k,)`` their picks/min.
        placements: ``(k, 4)`` placement reached from each.
        picks_per_minute: ``(k,)`` picks/min there.
        evaluations: ``(k,)`` cycles planned by each search.
        free: names of the coordinates searched (those the candidates vary).
        margin: ``(k,)`` boundary margin [m] of each refined placement; one below the
            search's ``min_margin`` is reported but never taken as the best placement.
    """

    starts: np.ndarray
    start_picks_per_minute: np.ndarray
    placements: np.ndarray
    picks_per_minute: np.ndarray
    evaluations: np.ndarray
    free: tuple[str, ...]
    margin: np.ndarray | None = None

    @property
    def gain(self) -> float:
        """Best refined picks/min minus the best grid candidate's (≥ 0: a start is kept if nothing better)."""
        return float(np.max(self.picks_per_minute) - np.max(self.start_picks_per_minute))


@dataclass(frozen=True, eq=False)
class LayoutSearch:
    """Result of :func:`search_layout` (per-candidate columns are ``(M,)`` arrays).

    Attributes:
        robot: name of the arm.
        picks, places: ``(P, 3)``, ``(Q, 3)`` points in the line frame [m].
        candidates: ``(M, 4)`` placements ``(x, y, z, yaw)`` of the base in the line frame [m, rad].
        failure: per candidate None (planned) or its :class:`CandidateFailure`.
        reason: per candidate, why it failed (names the point) or ``""``.
        cycle_time: mean cycle time over the (pick, place) pairs [s] (NaN when failed).
        picks_per_minute: ``60 / cycle_time`` (0 when failed).
        branch: closed-form IK branch label at the first pick (-1: failed or numerical IK).
        manipulability: smallest position manipulability at the picks and places (NaN when failed).
        margin: smallest distance of the picks and places to the workspace boundary [m] (0 outside).
        order: ``(M,)`` ranking (see the module docstring).
        refinement: the continuous improvement, or ``None``.
        best_placement: ``(4,)`` the best placement found (refined when that gained), or None.
        best_picks_per_minute: its picks/min (0 if no candidate succeeded).
        best_cycle: its first pair's cycle (:class:`pinarms.optim.CycleResult`, in the base frame), or None.
        seed: seed of the search (optimiser starts; random candidates are drawn by the caller).
        lower_bound: ``(M,)`` each candidate's proven lower bound of its cycle time [s] with
            ``bound=True`` (:mod:`pinarms.optim.layout.bound`; 0 where none), else None.
        seconds: the search's phases (``"screen"``, ``"cycles"``, ``"refine"``, ``"best"``: the
            best placement's cycle planned again with its report) as ``(wall, CPU)`` seconds; the
            CPU is this process's (a cluster's workers are not counted).
        status: :attr:`LayoutStatus.FOUND` (a best placement) or :attr:`LayoutStatus.NO_PLACEMENT`.
        status_reason: why not found (the failures counted by kind), ``""`` when found.
    """

    robot: str
    picks: np.ndarray = field(repr=False)
    places: np.ndarray = field(repr=False)
    candidates: np.ndarray = field(repr=False)
    failure: tuple[CandidateFailure | None, ...] = field(repr=False)
    reason: tuple[str, ...] = field(repr=False)
    cycle_time: np.ndarray = field(repr=False)
    picks_per_minute: np.ndarray = field(repr=False)
    branch: np.ndarray = field(repr=False)
    manipulability: np.ndarray = field(repr=False)
    margin: np.ndarray = field(repr=False)
    order: np.ndarray = field(repr=False)
    refinement: Refinement | None
    best_placement: np.ndarray | None
    best_picks_per_minute: float
    best_cycle: CycleResult | None = field(repr=False)
    seed: int = 0
    lower_bound: np.ndarray | None = field(default=None, repr=False)
    seconds: dict = field(default_factory=dict, repr=False)
    status: LayoutStatus = LayoutStatus.FOUND
    status_reason: str = ""

    @property
    def ok(self) -> np.ndarray:
        """``(M,)`` bool: the cycle was planned."""
        return np.array([f is None for f in self.failure], dtype=bool)

    @property
    def best_index(self) -> int:
        """Index of the best grid candidate (-1 if none succeeded)."""
        return int(self.order[0]) if self.ok[self.order[0]] else -1

    def failures(self) -> dict[str, int]:
        """Number of candidates per failure kind (only kinds that occur)."""
        counts = Counter(f for f in self.failure if f)
        return {k.value: counts[k] for k in FAILURES if counts[k]}

    def table(self, top: int = 10, *, failed: int = 3) -> str:
        """The ranked table (mm, degrees): the ``top`` candidates and the first ``failed`` failures."""
        mm = 1000.0
        ok = self.ok
        head = (f"layout search of {self.robot}: {len(self.candidates)} placements, {int(ok.sum())} planned"
                + "".join(f", {n} {k}" for k, n in self.failures().items()))
        lines = [head, "rank   x [mm]   y [mm]   z [mm]  yaw [°]  picks/min  cycle [s]  branch  manip.   margin [mm]"]
        for rank, i in enumerate(self.order[: int(top)]):
            if not ok[i]:
                break
            x, y, z, yaw = self.candidates[i]
            lines.append(f"{rank + 1:4d} {x * mm:8.0f} {y * mm:8.0f} {z * mm:8.0f} {np.degrees(yaw):8.1f} "
                         f"{self.picks_per_minute[i]:10.2f} {self.cycle_time[i]:10.3f} {self.branch[i]:7d} "
                         f"{self.manipulability[i]:7.4f} {self.margin[i] * mm:12.0f}")
        bad = [i for i in range(len(self.failure)) if self.failure[i]][: int(failed)]
        for i in bad:
            x, y, z, yaw = self.candidates[i]
            lines.append(f"  failed ({x * mm:.0f}, {y * mm:.0f}, {z * mm:.0f}) mm, yaw {np.degrees(yaw):.1f}°: "
                         f"{self.failure[i]}: {self.reason[i]}")
        if self.refinement is not None:
            r = self.refinement
            k = int(np.argmax(r.picks_per_minute))
            x, y, z, yaw = r.placements[k]
            lines.append(f"refined over {', '.join(r.free)} from the best {len(r.starts)}: "
                         f"{np.max(r.start_picks_per_minute):.2f} → {r.picks_per_minute[k]:.2f} picks/min "
                         f"(+{r.gain:.2f}, {int(r.evaluations.sum())} cycles planned) at "
                         f"({x * mm:.0f}, {y * mm:.0f}, {z * mm:.0f}) mm, yaw {np.degrees(yaw):.1f}°")
        if self.best_placement is not None:
            x, y, z, yaw = self.best_placement
            lines.append(f"best placement: base at ({x * mm:.0f}, {y * mm:.0f}, {z * mm:.0f}) mm, yaw "
                         f"{np.degrees(yaw):.1f}°: {self.best_picks_per_minute:.2f} picks/min")
        else:
            lines.append("no placement can run the cycle: see the failures above")
        return "\n".join(lines)

    def as_dict(self) -> dict[str, Any]:
        """JSON-able result (SI units), candidates in ranking order."""
        rows = []
        for i in self.order:
            rows.append({
                "index": int(i),
                "placement": dict(zip(("x_m", "y_m", "z_m", "yaw_rad"), self.candidates[i].tolist())),
                "ok": self.failure[i] is None,
                "failure": None if self.failure[i] is None else self.failure[i].value,
                "reason": self.reason[i] or None,
                "cycle_time_s": None if self.failure[i] else float(self.cycle_time[i]),
                "picks_per_minute": float(self.picks_per_minute[i]),
                "branch": int(self.branch[i]),
                "manipulability": None if self.failure[i] else float(self.manipulability[i]),
                "boundary_margin_m": float(self.margin[i]),
            })
        out: dict[str, Any] = {
            "robot": self.robot,
            "status": self.status.value,
            "status_reason": self.status_reason or None,
            "picks_m": self.picks.tolist(),
            "places_m": self.places.tolist(),
            "seed": self.seed,
            "failures": self.failures(),
            "candidates": rows,
            "best": None if self.best_placement is None else {
                "placement": dict(zip(("x_m", "y_m", "z_m", "yaw_rad"), self.best_placement.tolist())),
                "picks_per_minute": self.best_picks_per_minute,
                "cycle": None if self.best_cycle is None else self.best_cycle.as_dict(),
            },
            "refinement": None,
        }
        if self.refinement is not None:
            r = self.refinement
            out["refinement"] = {
                "free": list(r.free),
                "starts": r.starts.tolist(),
                "start_picks_per_minute": r.start_picks_per_minute.tolist(),
                "placements": r.placements.tolist(),
                "picks_per_minute": r.picks_per_minute.tolist(),
                "evaluations": r.evaluations.tolist(),
                "boundary_margin_m": None if r.margin is None else r.margin.tolist(),
                "gain_picks_per_minute": r.gain,
            }
        return out
