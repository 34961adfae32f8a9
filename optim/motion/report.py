"""What :func:`.plan.plan_motion` reports: the :class:`MotionPlan` and the :class:`ClearanceProfile` along it.

Distances in m (the world frame), joint coordinates in rad or m, times in s.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from pinarms.optim.motion.goals import GoalCandidate
from pinarms.planning import JointPath, Trajectory

__all__ = ["MotionPlan", "ClearanceProfile", "SIMPLIFIER", "FAST_SIMPLIFIER", "clearance_profile", "cell_trajectory"]

#: What shortcuts a path found by OMPL (said in every result).
SIMPLIFIER = "OMPL PathSimplifier (reduceVertices, partialShortcutPath, ropeShortcutPath), edges proven by pinarms"
#: What shortcuts a path found by the compiled search (:mod:`.fast`).
FAST_SIMPLIFIER = "random shortcuts then vertex removal, edges proven on the sphere cover (compiled)"


@dataclass(frozen=True, eq=False)
class ClearanceProfile:
    """Distances along a timed motion, sampled every ``margin`` of travel of the fastest point.

    Attributes:
        times: ``(M,)`` [s]; ``environment``: ``(M,)`` smallest distance [m] between a planned
            arm and a fixture or another arm; ``environment_pair``: its pair index into
            ``pairs`` (−1 when there is none); ``own``: ``(M,)`` smallest distance between
            two links of one planned arm [m].
        pairs: the pairs checked (those involving a planned arm); ``required``: the margin [m].

    ``viz.plot_clearance(path, profile)`` draws it over time.
    """

    times: np.ndarray
    environment: np.ndarray
    environment_pair: np.ndarray
    own: np.ndarray
    pairs: tuple
    required: float = 0.0

    # what viz.plot_clearance reads: viz.plot_clearance("clearance.png", plan.clearance)
    @property
    def clearance(self) -> np.ndarray:
        """``environment`` (the name the clearance plot reads)."""
        return self.environment

    @property
    def exact(self) -> np.ndarray:
        """Every sample is an exact distance (coal)."""
        return np.ones(self.times.size, dtype=bool)

    @property
    def min_clearance_pair(self) -> str | None:
        """``"body_a – body_b"`` of the closest pair to the environment."""
        pair = self.min_pair
        return None if pair is None else f"{pair[0]} – {pair[1]}"

    @property
    def min_environment(self) -> float:
        """Smallest distance to a fixture or another arm over the motion [m]."""
        return float(np.min(self.environment)) if self.environment.size else float("inf")

    @property
    def min_time(self) -> float:
        """When it occurs [s]."""
        return float(self.times[int(np.argmin(self.environment))]) if self.environment.size else 0.0

    @property
    def min_pair(self) -> tuple[str, str] | None:
        """``(body_a, body_b)`` of that pair."""
        if not self.environment.size:
            return None
        k = int(self.environment_pair[int(np.argmin(self.environment))])
        return None if k < 0 else self.pairs[k].bodies

    @property
    def min_own(self) -> float:
        """Smallest distance between two links of one planned arm [m]."""
        return float(np.min(self.own)) if self.own.size else float("inf")



@dataclass(frozen=True, eq=False)
class MotionPlan:
    """A planned, proven and timed motion (see the module docstring).

    Attributes:
        arms: the planned arms; ``start``/``goal``: their joint coordinates ``(n,)``.
        goals: every goal configuration tried (:class:`GoalCandidate`: valid or why not).
        raw_path: ``(M, n)`` the planner's path; ``simplified``: ``(K, n)`` after shortcutting
            (:data:`SIMPLIFIER`); ``path``: the smooth :class:`planning.JointPath` that was
            timed, ``smoothing`` how it was made (``"cubic spline"``, ``"straight line"`` or
            ``"polyline with stops"``).
        timing: the :class:`optim.PathTiming`; ``trajectory``: the arms' joint trajectory
            (:class:`planning.Trajectory`, the planned arms' joints in order).
        check: the cell's continuous check of the timed motion (:class:`robots.cell.MotionCheck`;
            ``None`` when planned with ``recheck=False``).
        clearance: the distances along it (:class:`ClearanceProfile`; ``None`` likewise).
        hold: the cell configuration of the arms not planned.
        planner, seed, time_limit, margin, self_margin: what was asked; ``states``: states the
            planner explored; ``seconds``: time per step (``"search"``, ``"shortcut"``,
            ``"smooth"``, ``"time"``, ``"check"``, ``"total"``); ``limits``: the limits timed under.
        simplifier: what shortcut the path; compiled: whether the compiled search on the sphere
            cover found it (:mod:`.fast`; else OMPL with the exact checker).
    """

    cell: Any = field(repr=False)
    arms: tuple[str, ...]
    start: np.ndarray = field(repr=False)
    goal: np.ndarray = field(repr=False)
    goals: tuple[GoalCandidate, ...] = field(repr=False)
    raw_path: np.ndarray = field(repr=False)
    simplified: np.ndarray = field(repr=False)
    path: JointPath = field(repr=False)
    smoothing: str
    timing: Any = field(repr=False)
    trajectory: Trajectory = field(repr=False)
    check: Any = field(repr=False)
    clearance: ClearanceProfile | None = field(repr=False)
    hold: np.ndarray = field(repr=False)
    planner: str
    seed: int
    time_limit: float
    margin: float
    self_margin: float
    states: int
    seconds: dict = field(repr=False)
    limits: dict = field(repr=False)
    simplifier: str = SIMPLIFIER
    compiled: bool = False

    @property
    def duration(self) -> float:
        """Time of the motion [s]."""
        return float(self.trajectory.duration)

    @property
    def path_length(self) -> float:
        """Joint-space length of the shortcut path [rad or m, Euclidean]."""
        return float(np.linalg.norm(np.diff(self.simplified, axis=0), axis=1).sum())

    @property
    def raw_length(self) -> float:
        """Joint-space length of the planner's path [rad or m]."""
        return float(np.linalg.norm(np.diff(self.raw_path, axis=0), axis=1).sum())

    def cell_trajectory(self) -> Trajectory:
        """The motion as a trajectory of the whole cell joint vector (arms not planned held)."""
        return cell_trajectory(self.cell, self.arms, self.trajectory, self.hold)

    def tool_path(self, arm: str | None = None, samples: int = 200) -> np.ndarray:
        """tcp positions ``(samples, 3)`` [m, world] of ``arm`` (default the first planned arm) along the motion."""
        name = self.arms[0] if arm is None else arm
        t = np.linspace(self.trajectory.start_time, self.trajectory.end_time, samples)
        q = self.cell_trajectory().sample(t)[0]
        return self.cell.world_pose(q, self.cell.arm(name).prefix + "tcp")[:, :3, 3]

    def as_dict(self) -> dict[str, Any]:
        """JSON-able summary (SI units)."""
        c = self.clearance
        return {
            "arms": list(self.arms),
            "planner": self.planner,
            "seed": self.seed,
            "time_limit_s": self.time_limit,
            "margin_m": self.margin,
            "self_margin_m": self.self_margin,
            "start": self.start.tolist(),
            "goal": self.goal.tolist(),
            "goal_candidates": [{"q": g.q.tolist(), "valid": g.valid, "reason": g.reason, "branch": g.branch}
                                for g in self.goals],
            "states_explored": self.states,
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



def cell_trajectory(cell: Any, arms: Sequence[str], trajectory: Trajectory, hold: np.ndarray) -> Trajectory:
    """A trajectory of the planned arms' joints as one of the whole cell (the other arms held at ``hold``)."""
    C = trajectory.coefficients
    out = np.zeros((C.shape[0], C.shape[1], cell.nq))
    out[:, 0, :] = hold
    cols = np.concatenate([np.arange(cell.nq)[cell.arm(a).q_slice] for a in arms])
    out[:, :, cols] = C
    return Trajectory(trajectory.knot_times, out)


def clearance_profile(checker: Any, trajectory: Trajectory, *, samples: int | None = None) -> ClearanceProfile:
    """Distances along ``trajectory`` (planned arms' joints; time last for none): one sample per
    ``margin`` of travel of the fastest point (at least 20, at most 4000)."""
    t0, t1 = trajectory.start_time, trajectory.end_time
    peaks = np.asarray(trajectory.peaks().velocity, dtype=float)
    travel = float(peaks @ checker.levers) * (t1 - t0)
    n = samples or int(np.clip(np.ceil(travel / checker.margin), 20, 4000))
    t = np.linspace(t0, t1, n + 1)
    X = np.asarray(trajectory.sample(t)[0], dtype=float).reshape(t.size, -1)
    if checker.timed:
        X = np.column_stack([X, t])
    Q = checker.full(X)
    own = np.array([p.kind == "self" for p in checker.pairs])
    env_e, env_k, env_d = checker.excess(Q, mask=~own)
    own_e, own_k, own_d = checker.excess(Q, mask=own) if own.any() else (None, None, np.full(t.size, np.inf))
    return ClearanceProfile(t, env_d, env_k, own_d, checker.pairs, checker.margin)

