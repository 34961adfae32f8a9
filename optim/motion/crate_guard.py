"""The planned move of the ``aubo_crate_guard`` scene, planned once per process: the one seed 001's study
reports (:mod:`pinarms.studies.seed001_motion`) and the shipped motions export
(:func:`pinarms.export.shipped.shipped_motions`).

From the middle of the food table to the middle of the crate's far half, under the guard plate:
:func:`pinarms.optim.motion.plan.plan_motion` with every clear IK branch of the goal pose searched
(``goals="best"``), 10 mm kept. RRT-Connect's paths vary a lot with the seed (a line is planned
once, offline): :data:`SEEDS` seeded searches, the fastest move kept (ties: the lowest seed).
Beside it the unobstructed move: the straight joint-space move between the same configurations,
timed under the same limits, and how deep it runs into the cell. Lengths in m, times in s.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from pinarms.optim.motion.result import MotionPlan
from pinarms.optim.topp.path_timing import PathTiming
from pinarms.robots.cell.collision import CollisionPair

__all__ = ["SEEDS", "CrateGuardMove", "crate_guard_move"]

#: Seeds of the planned move's searches (the fastest move is kept).
SEEDS = tuple(range(8))


@dataclass(frozen=True)
class CrateGuardMove:
    """The fastest of the seeded plans and the straight move it replaces.

    ``plan``: the fastest plan (of seed ``seed``); ``durations``: ``(len(SEEDS),)`` every plan's duration [s];
    ``straight``: the straight joint-space move from ``plan``'s start to its goal, timed under the same
    limits; ``straight_depth`` [m] (> 0) how far it goes into the cell, between the bodies ``straight_pair``.
    """

    plan: MotionPlan
    seed: int
    durations: np.ndarray = field(repr=False)
    straight: PathTiming = field(repr=False)
    straight_depth: float
    straight_pair: CollisionPair


@functools.cache  # planned once per process: the study and the shipped motions use the same plan
def crate_guard_move() -> CrateGuardMove:
    """Plan the crate-guard move (module doc; about 10 s the first time in a process)."""
    from pinarms.optim.motion.checker import MotionChecker
    from pinarms.optim.motion.goals import ik_candidates
    from pinarms.optim.motion.plan import plan_motion, time_path
    from pinarms.optim.motion.request import MotionLimits, MotionOptions, MotionRequest, motion_constraints
    from pinarms.optim.motion.scenes import SCENES, load_scene, region_pose
    from pinarms.optim.motion.smoothing import polyline_path

    cell = load_scene("aubo_crate_guard")
    arm = cell.arm("aubo")
    table, crate = SCENES["aubo_crate_guard"].regions
    checker = MotionChecker(cell, ["aubo"], margin=0.01)
    start_pose = region_pose(table, 0.5 * (np.array(table.lo) + np.array(table.hi)))
    goal_pose = region_pose(crate, 0.5 * (np.array(crate.lo) + np.array(crate.hi)))
    q0 = next(q for q in ik_candidates(arm.robot, arm.to_base(start_pose), cell.neutral)[0] if checker.state_valid(q))
    plans = [plan_motion(MotionRequest(cell, "aubo", q0, goal_pose,
                                       options=MotionOptions(margin=0.01, time_limit=60.0, seed=seed, goals="best")))
             for seed in SEEDS]
    durations = np.array([p.duration for p in plans])
    best = int(np.argmin(durations))  # the first of equal minima: the lowest seed
    plan = plans[best]
    constraints, _ = motion_constraints(cell, ("aubo",), MotionLimits())
    straight = time_path(polyline_path(np.stack([q0, plan.goal])), constraints)
    s = np.linspace(0.0, 1.0, 401)[:, None]
    hit = cell.clearance(cell.q_from_arms({"aubo": q0 + s * (plan.goal - q0)}))
    k = int(np.argmin(hit.distance))
    return CrateGuardMove(plan, SEEDS[best], durations, straight, float(-hit.distance[k]), hit.pair_of(k))
