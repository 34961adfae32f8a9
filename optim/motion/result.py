"""What :func:`.plan.plan_motion` returns: a :class:`MotionPlan` whose :class:`MotionStatus` says how it ended.

**The status rule.** What is wrong with the *request* is an exception, raised when the
request is built or before any search (:class:`.request.MotionRequest`): an unknown arm, a
start or goal of the wrong size, a start outside the joint limits, a bad setting or limit
(``InvalidInput``, ``InvalidSettings``, ``InvalidLimits``). What *planning finds out* about a
valid request is a status of the returned plan, with the reason in words and the data to act
on: the start, the goal or an idle arm's hold pose too close to something (the pairs, their
distances, the joint values), a pose goal without any IK solution, no path within the time
limit (the planner, the states explored), a path that cannot be timed under the limits, a timed
motion the cell's independent check refuses. The search never proves that no path exists (a
sampling planner stops at its time limit), so "no path" always means "none within
``time_limit``". :meth:`MotionPlan.raise_for_status` raises the status as the project's error
(:class:`pinarms.optim.StartInCollision`, :class:`pinarms.optim.NoPathFound`, ...), and every property that
needs the motion (``duration``, ``tool_path``, ...) does so on a plan that was not solved.

Joint coordinates in rad or m, distances in m, times in s.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from pinarms.optim.errors import PlanningError
from pinarms.optim.motion.goals import GoalCandidate
from pinarms.optim.motion.report import SIMPLIFIER, ClearanceProfile, cell_trajectory
from pinarms.planning import JointPath, Trajectory

if TYPE_CHECKING:
    from pinarms.optim.topp.path_timing import PathTiming
    from pinarms.robots.cell import Cell
    from pinarms.robots.cell.motion_report import MotionCheck

__all__ = ["MotionStatus", "MotionPlan"]


class MotionStatus(enum.Enum):
    """How :func:`.plan.plan_motion` ended (module docstring: which failures are statuses)."""

    #: a collision-free motion, proven and timed
    SOLVED = "solved"
    #: the start is closer than the margin to a fixture, another arm or itself
    START_IN_COLLISION = "start in collision"
    #: every goal configuration (each IK branch of a pose goal) is too close to something
    GOAL_IN_COLLISION = "goal in collision"
    #: an arm that is not planned touches something at its hold pose
    HOLD_IN_COLLISION = "hold in collision"
    #: a pose goal without any IK solution within the joint limits
    GOAL_UNREACHABLE = "goal unreachable"
    #: no collision-free path found within the time limit
    NO_PATH = "no path"
    #: the path found cannot be timed under the limits (e.g. torques too small to hold the arm)
    LIMITS_NOT_MET = "limits not met"
    #: the cell's independent continuous check refused the timed motion
    RECHECK_FAILED = "recheck failed"


@dataclass(frozen=True, eq=False)
class MotionPlan:
    """A planned motion: its status, and when solved the proven, timed motion (module docstring).

    Attributes:
        arms: the planned arms; ``status``: the :class:`MotionStatus`; ``reason``: why it is not
            solved, in words (empty when solved).
        start: the planned arms' joint coordinates ``(n,)``; ``goal``: the goal reached ``(n,)``
            (continuous joints unwrapped: the goal asked plus a multiple of 2π, where the
            trajectory ends; not solved: the joint goal asked, or ``None`` for a pose goal).
        goals: every goal configuration tried (:class:`GoalCandidate`: valid or why not).
        which, pairs, distances, configurations: with a status ``*_IN_COLLISION``: which end
            (``"start"``, ``"goal"``, ``"hold"``), the pairs ``(body_a, body_b)`` nearest their
            margin, their distances [m] (negative: penetration), and the joint values in
            collision (``(k, n)`` planned joints: the start, each goal configuration; ``(1, nq)``
            the cell configuration for ``"hold"``).
        raw_path: ``(M, n)`` the planner's path; ``simplified``: ``(K, n)`` after shortcutting
            (:data:`.report.SIMPLIFIER`); ``path``: the smooth :class:`pinarms.planning.JointPath` that
            was timed, ``smoothing`` how it was made (``"cubic spline"``, ``"straight line"``
            or ``"polyline with stops"``).
        timing: the :class:`pinarms.optim.PathTiming`; ``trajectory``: the arms' joint trajectory
            (:class:`pinarms.planning.Trajectory`, the planned arms' joints in order).
        check: the cell's continuous check of the timed motion (:class:`pinarms.robots.cell.MotionCheck`;
            ``None`` when planned with ``recheck=False``).
        clearance: the distances along it (:class:`ClearanceProfile`; ``None`` likewise).
        hold: the cell configuration of the arms not planned.
        planner, seed, time_limit, margin, self_margin: what was asked (``planner`` the OMPL
            class that searched); ``states``: states the planner explored; ``seconds``: time per
            step (``"search"``, ``"shortcut"``, ``"smooth"``, ``"time"``, ``"check"``,
            ``"total"``); ``limits``: the limits timed under.
        simplifier: what shortcut the path; compiled: whether the compiled search on the sphere
            cover found it (:mod:`.fast`; else OMPL with the exact checker).
        error: the project's error for a status other than ``SOLVED`` (what
            :meth:`raise_for_status` raises), else ``None``.
    """

    cell: Cell = field(repr=False)
    arms: tuple[str, ...]
    status: MotionStatus
    start: np.ndarray = field(repr=False)
    reason: str = ""
    goal: np.ndarray | None = field(default=None, repr=False)
    goals: tuple[GoalCandidate, ...] = field(default=(), repr=False)
    which: str = ""
    pairs: tuple[tuple[str, str], ...] = field(default=(), repr=False)
    distances: tuple[float, ...] = field(default=(), repr=False)
    configurations: np.ndarray | None = field(default=None, repr=False)
    raw_path: np.ndarray | None = field(default=None, repr=False)
    simplified: np.ndarray | None = field(default=None, repr=False)
    path: JointPath | None = field(default=None, repr=False)
    smoothing: str = ""
    timing: PathTiming | None = field(default=None, repr=False)
    trajectory: Trajectory | None = field(default=None, repr=False)
    check: MotionCheck | None = field(default=None, repr=False)
    clearance: ClearanceProfile | None = field(default=None, repr=False)
    hold: np.ndarray | None = field(default=None, repr=False)
    planner: str = ""
    seed: int = 0
    time_limit: float = 0.0
    margin: float = 0.0
    self_margin: float = 0.0
    states: int = 0
    seconds: dict = field(default_factory=dict, repr=False)
    limits: dict = field(default_factory=dict, repr=False)
    simplifier: str = SIMPLIFIER
    compiled: bool = False
    error: PlanningError | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        """Whether the motion was solved (:attr:`MotionStatus.SOLVED`)."""
        return self.status is MotionStatus.SOLVED

    def raise_for_status(self) -> MotionPlan:
        """The plan itself when solved; else raise its error (:class:`pinarms.optim.StartInCollision`,
        :class:`pinarms.optim.GoalInCollision`, :class:`pinarms.optim.NoPathFound`, ...; the message is :attr:`reason`)."""
        if self.status is MotionStatus.SOLVED:
            return self
        if self.error is not None:
            raise self.error
        raise PlanningError(f"{self.status.value}: {self.reason}")

    @property
    def duration(self) -> float:
        """Time of the motion [s]."""
        return float(self.raise_for_status().trajectory.duration)

    @property
    def path_length(self) -> float:
        """Joint-space length of the shortcut path [rad or m, Euclidean]."""
        return float(np.linalg.norm(np.diff(self.raise_for_status().simplified, axis=0), axis=1).sum())

    @property
    def raw_length(self) -> float:
        """Joint-space length of the planner's path [rad or m]."""
        return float(np.linalg.norm(np.diff(self.raise_for_status().raw_path, axis=0), axis=1).sum())

    def cell_trajectory(self) -> Trajectory:
        """The motion as a trajectory of the whole cell joint vector (arms not planned held)."""
        return cell_trajectory(self.cell, self.arms, self.raise_for_status().trajectory, self.hold)

    def tool_path(self, arm: str | None = None, samples: int = 200) -> np.ndarray:
        """tcp positions ``(samples, 3)`` [m, world] of ``arm`` (default the first planned arm) along the motion."""
        name = self.arms[0] if arm is None else arm
        traj = self.raise_for_status().trajectory
        t = np.linspace(traj.start_time, traj.end_time, samples)
        q = self.cell_trajectory().sample(t)[0]
        return self.cell.world_pose(q, self.cell.arm(name).prefix + "tcp")[:, :3, 3]

    def clearance_summary(self) -> str:
        """One line in plain words: the smallest clearance (coal, exact) and where, whether the margin held, and
        what the cell's independent re-check proved.

        E.g. ``smallest clearance 32.2 mm (forearm ↔ table at t = 0.410 s); the 10 mm margin holds along the whole
        motion (proven on the path by the planner; re-checked by the cell: no contact, no two shapes closer than
        5.0 mm at its 10 mm resolution)``. ``None`` parts (planned with ``recheck=False``) are left out.
        """
        self.raise_for_status()
        held = f"the {self.margin * 1e3:g} mm margin holds along the whole motion (proven on the path by the planner"
        c, check = self.clearance, self.check
        if check is not None:
            held += (f"; re-checked by the cell: no contact, no two shapes closer than {check.lower_bound * 1e3:.1f} mm"
                     f" at its {check.margin * 1e3:g} mm resolution")
        held += ")"
        if c is None:
            return held
        where = "" if c.min_pair is None else f" ({c.min_pair[0]} ↔ {c.min_pair[1]} at t = {c.min_time:.3f} s)"
        own = "" if not np.isfinite(c.min_own) else f"; own links closest {c.min_own * 1e3:.1f} mm"
        return f"smallest clearance {c.min_environment * 1e3:.1f} mm{where}; {held}{own}"

    def as_dict(self) -> dict[str, Any]:
        """JSON-able summary (SI units); a plan not solved gives its status, reason and collision data."""
        head = {
            "status": self.status.value,
            "arms": list(self.arms),
            "planner": self.planner,
            "seed": self.seed,
            "time_limit_s": self.time_limit,
            "margin_m": self.margin,
            "self_margin_m": self.self_margin,
            "start": self.start.tolist(),
            "goal": None if self.goal is None else self.goal.tolist(),
            "goal_candidates": [{"q": g.q.tolist(), "valid": g.valid, "reason": g.reason, "branch": g.branch}
                                for g in self.goals],
            "states_explored": self.states,
        }
        if not self.ok:
            return {**head, "reason": self.reason, "which": self.which, "pairs": [list(p) for p in self.pairs],
                    "distances_m": list(self.distances),
                    "configurations": None if self.configurations is None else self.configurations.tolist(),
                    "seconds": {k: round(v, 6) for k, v in self.seconds.items()}}
        c = self.clearance
        return {
            **head,
            "raw_path": self.raw_path.tolist(),
            "simplified_path": self.simplified.tolist(),
            "raw_length": self.raw_length,
            "path_length": self.path_length,
            "simplifier": self.simplifier,
            "compiled_search": self.compiled,
            "smoothing": self.smoothing,
            "duration_s": self.duration,
            "timing": self.timing.as_dict(),
            "limits": {k: (None if v is None else np.asarray(v).tolist()) for k, v in self.limits.items()},
            "collision_free": None if self.check is None else bool(self.check.collision_free),
            "min_clearance_environment_m": None if c is None else c.min_environment,
            "min_clearance_time_s": None if c is None else c.min_time,
            "min_clearance_pair": None if c is None or c.min_pair is None else list(c.min_pair),
            "min_clearance_own_links_m": None if c is None else c.min_own,
            "seconds": {k: round(v, 6) for k, v in self.seconds.items()},
        }
