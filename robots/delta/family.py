"""The loop closures every delta of the family has, by the frame names of its xacro macro."""

from __future__ import annotations

from pinarms.robots.delta.closures import ClosureSet, LoopClosure
from pinarms.robots.delta.geometry import LEG_COUNT, leg_frames

__all__ = ["family_closures"]


def family_closures(robot: str) -> ClosureSet:
    """One ball-joint closure per leg: the forearm's lower end (``leg{i}_ball``) on the platform
    (``platform_ball{i}``)."""
    return ClosureSet(robot, tuple(
        LoopClosure(f"leg{i}", leg_frames(i)["ball"], leg_frames(i)["platform_ball"], "point")
        for i in range(1, LEG_COUNT + 1)))
