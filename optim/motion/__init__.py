"""Collision-free motion in a cell (compiled RRT-Connect, else OMPL), proven continuously, timed optimally.

See docs/motion.md.

- :func:`plan_motion`: one :class:`MotionRequest` (the cell, one arm or two together, a start,
  a goal joint vector or tool pose, every IK branch a goal; :class:`MotionOptions`,
  :class:`MotionLimits`) in, one :class:`MotionPlan` out: its :class:`MotionStatus` (solved, or
  what planning found: start or goal in collision, no path in time, ...), and when solved the
  raw, shortcut and smooth paths, the time-optimal :class:`pinarms.planning.Trajectory`, the cell's
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

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "MotionChecker": "pinarms.optim.motion.checker",
    "TimedArm": "pinarms.optim.motion.checker",
    "Verdict": "pinarms.optim.motion.checker",
    "FastCheck": "pinarms.optim.motion.fast",
    "fast_check": "pinarms.optim.motion.fast",
    "fast_search": "pinarms.optim.motion.fast",
    "fast_shortcut": "pinarms.optim.motion.fast",
    "GoalCandidate": "pinarms.optim.motion.goals",
    "plan_motion": "pinarms.optim.motion.plan",
    "ClearanceProfile": "pinarms.optim.motion.report",
    "MotionLimits": "pinarms.optim.motion.request",
    "MotionOptions": "pinarms.optim.motion.request",
    "MotionRequest": "pinarms.optim.motion.request",
    "MotionPlan": "pinarms.optim.motion.result",
    "MotionStatus": "pinarms.optim.motion.result",
    "SCENES": "pinarms.optim.motion.scenes",
    "Query": "pinarms.optim.motion.scenes",
    "Region": "pinarms.optim.motion.scenes",
    "Scene": "pinarms.optim.motion.scenes",
    "load_scene": "pinarms.optim.motion.scenes",
    "scene_names": "pinarms.optim.motion.scenes",
    "scene_path": "pinarms.optim.motion.scenes",
    "scene_queries": "pinarms.optim.motion.scenes",
    "PLANNERS": "pinarms.optim.motion.search",
    "SearchSettings": "pinarms.optim.motion.search",
    "AroundRequest": "pinarms.optim.motion.two_arms",
    "AroundPlan": "pinarms.optim.motion.two_arms",
    "TwoArmRequest": "pinarms.optim.motion.two_arms",
    "TwoArmPlan": "pinarms.optim.motion.two_arms",
    "plan_around": "pinarms.optim.motion.two_arms",
    "plan_two_arms": "pinarms.optim.motion.two_arms",
    "PlannedMove": "pinarms.optim.motion.transfer",
    "planned_cycle": "pinarms.optim.motion.transfer",
}

__all__ = [
    "plan_motion", "MotionRequest", "MotionOptions", "MotionLimits", "MotionPlan", "MotionStatus",
    "ClearanceProfile", "GoalCandidate", "MotionChecker", "TimedArm", "Verdict", "FastCheck", "fast_check",
    "fast_search", "fast_shortcut", "PLANNERS", "SCENES", "Scene", "Region", "Query", "scene_names",
    "scene_path", "load_scene", "scene_queries", "plan_around", "plan_two_arms", "AroundPlan", "TwoArmPlan",
    "AroundRequest", "TwoArmRequest", "SearchSettings", "planned_cycle", "PlannedMove",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
