"""Collision-free motion in a cell (compiled RRT-Connect, else OMPL), proven continuously, timed optimally.

See docs/motion.md.

- :func:`plan_motion`: one :class:`MotionRequest` (the cell, one arm or two together, a start,
  a goal joint vector or tool pose, every IK branch a goal; :class:`MotionOptions`,
  :class:`MotionLimits`) in, one :class:`MotionPlan` out: its :class:`MotionStatus` (solved, or
  what planning found: start or goal in collision, no path in time, ...), and when solved the
  raw, shortcut and smooth paths, the time-optimal :class:`planning.Trajectory`, the cell's
  re-check, the clearance profile.
- :class:`MotionChecker`: state, edge and timed-motion validity (:mod:`.checker`), exact (coal
  where the sphere cover is inconclusive); :func:`fast_check` its compiled side on the cover
  alone (:class:`FastCheck`: states, edges, polylines proven or not, in µs), which
  :func:`fast_search` (RRT-Connect) and :func:`fast_shortcut` run on (:mod:`.fast`).
- :func:`plan_around` / :func:`plan_two_arms`: one arm around the other's timed
  trajectory, or both together (:mod:`.two_arms`).
- :func:`planned_cycle`: the transfer ``plan_cycle`` in a cell falls back to (:mod:`.transfer`).
- The planning scenes and their seeded queries (:mod:`.scenes`), example-robot-data arms
  as xacro macros (:mod:`.arm_macros`).
"""

from pinarms.optim.motion.checker import MotionChecker, TimedArm, Verdict
from pinarms.optim.motion.fast import FastCheck, fast_check, fast_search, fast_shortcut
from pinarms.optim.motion.goals import GoalCandidate
from pinarms.optim.motion.plan import plan_motion
from pinarms.optim.motion.report import ClearanceProfile
from pinarms.optim.motion.request import MotionLimits, MotionOptions, MotionRequest
from pinarms.optim.motion.result import MotionPlan, MotionStatus
from pinarms.optim.motion.scenes import SCENES, Query, Region, Scene, load_scene, scene_names, scene_path, scene_queries
from pinarms.optim.motion.search import PLANNERS
from pinarms.optim.motion.two_arms import AroundPlan, TwoArmPlan, plan_around, plan_two_arms
from pinarms.optim.motion.transfer import PlannedMove, planned_cycle

__all__ = ["plan_motion", "MotionRequest", "MotionOptions", "MotionLimits", "MotionPlan", "MotionStatus",
           "ClearanceProfile", "GoalCandidate", "MotionChecker", "TimedArm", "Verdict",
           "FastCheck", "fast_check", "fast_search", "fast_shortcut",
           "PLANNERS", "SCENES", "Scene", "Region", "Query", "scene_names", "scene_path", "load_scene", "scene_queries",
           "plan_around", "plan_two_arms", "AroundPlan", "TwoArmPlan", "planned_cycle", "PlannedMove"]
