"""Step 4 of inverse reach: candidate bases checked by exact IK at the exact task poses.

:func:`verify_bases` solves every task pose (every roll about the tool axis for roll-free
tasks) seen from each candidate base: every closed-form branch within the limits when the arm
and the map have a closed form, else the numerical solver (seeded per pose); the collision
checks of :func:`pinarms.robots.reach.reachability.reachability_map` drop solutions. Used by
:func:`pinarms.robots.reach.inverse_reach.base_placements`. Units: m, rad.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from pinarms.robots.so3 import about as rotations_about
from pinarms.robots.reach.reach_chunk import ChunkTask, collision_free, manipulability_of
from pinarms.robots.reach.reach_map import ReachabilityMap
from pinarms.robots.reach.robot_spec import spec_of

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.robot import Robot

__all__ = ["verify_bases"]


def verify_bases(robot: "Robot", reach_map: ReachabilityMap, candidates: np.ndarray, T_tasks: np.ndarray, roll_free: bool,
                 roll_steps: int, self_collision: bool, collision: Any) -> tuple[np.ndarray, np.ndarray]:
    """Exact IK at every task from each candidate: ``(verified (n,), min over tasks of best w (n,))``.

    ``candidates (n, 4)`` are ``x, y, z, yaw`` [m, rad]; ``T_tasks (N, 4, 4)`` tool frame → world.
    A task counts as solved when any of its ``roll_steps`` rolls about the map's tool axis is
    (``roll_free``); its best ``w`` is the largest over its solutions (NaN when unverified).
    """
    tool_axis = reach_map.orientations.tool_axis
    n, N = candidates.shape[0], T_tasks.shape[0]
    rolls = rotations_about(tool_axis, 2 * np.pi * np.arange(roll_steps) / roll_steps) if roll_free else np.eye(3)[None]
    R = rolls.shape[0]
    B = np.tile(np.eye(4), (n, 1, 1))
    cz, sz = np.cos(candidates[:, 3]), np.sin(candidates[:, 3])
    B[:, 0, 0], B[:, 0, 1], B[:, 1, 0], B[:, 1, 1] = cz, -sz, sz, cz
    B[:, :3, 3] = candidates[:, :3]
    tasks_to_base = np.linalg.inv(B)[:, None] @ T_tasks[None]  # (n, N, 4, 4)
    T = np.repeat(tasks_to_base[:, :, None], R, axis=2)
    T[..., :3, :3] = T[..., :3, :3] @ rolls[None, None]
    T = T.reshape(-1, 4, 4)
    task = ChunkTask(robot=spec_of(robot), origin=np.zeros(3), resolution=1.0, shape=(1, 1, 1), voxels=np.zeros(0, np.int64),
                     rotations=np.eye(3)[None], group=np.zeros(1, np.int64), n_groups=1, roll_free=False,
                     solver="analytic", manipulability=reach_map.manipulability_kind, restarts=0, tol=1e-9,
                     self_collision=bool(self_collision), collision=collision, keep_solutions=False, seed=0)
    best = np.full(T.shape[0], np.nan)
    if robot.has_analytic_ik and reach_map.solver == "analytic":
        idx, q = robot.analytic_ik.candidates(T)
        keep = collision_free(task, robot, q)
        idx, q = idx[keep], q[keep]
        w = manipulability_of(robot, q, reach_map.manipulability_kind)
        top = np.full(T.shape[0], -np.inf)
        np.maximum.at(top, idx, w)
        best = np.where(np.isfinite(top), top, np.nan)
    else:
        from pinarms.errors import UnreachableTarget

        for k in range(T.shape[0]):
            try:
                q = robot.ik(T[k], max_restarts=max(4, int(reach_map.parameters.get("restarts", 2)) * 2), seed=k)
            except UnreachableTarget:
                continue
            if collision_free(task, robot, q[None])[0]:
                best[k] = manipulability_of(robot, q[None], reach_map.manipulability_kind)[0]
    per = best.reshape(n, N, R)
    task_best = np.where(np.isnan(per).all(axis=2), np.nan, np.nanmax(np.where(np.isnan(per), -np.inf, per), axis=2))
    verified = ~np.isnan(task_best).any(axis=1)
    wmin = np.where(verified, np.nanmin(np.where(np.isnan(task_best), np.inf, task_best), axis=1), np.nan)
    return verified, wmin
