"""Collision-free motion in a cell (OMPL), timed optimally along the path."""

from pinarms.optim.motion.checker import MotionChecker, TimedArm, Verdict
from pinarms.optim.motion.goals import GoalCandidate
from pinarms.optim.motion.plan import ClearanceProfile, MotionPlan, plan_motion
from pinarms.optim.motion.scenes import SCENES, Query, Region, Scene, load_scene, scene_names, scene_path, scene_queries
from pinarms.optim.motion.search import PLANNERS

__all__ = ["plan_motion", "MotionPlan", "ClearanceProfile", "GoalCandidate", "MotionChecker", "TimedArm", "Verdict",
           "PLANNERS", "SCENES", "Scene", "Region", "Query", "scene_names", "scene_path", "load_scene", "scene_queries"]
