"""One chunk of a reachability map: :class:`ChunkTask` and its task function :func:`solve_chunk`.

A chunk is a fixed run of voxels; for each voxel and each rotation of the orientation set, the
pose is solved by every closed-form branch at once (batched) or by the seeded numerical solver,
solutions are dropped by the optional collision checks, and the most dexterous one is kept
(ties within :data:`TIE_RTOL` go to the solver's first). Step 3 and 4 of the method in
:mod:`pinarms.robots.reach.reachability`. Units: m, rad.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from pinarms.errors import InvalidInput
from pinarms.robots.reach.reach_map import cell_centres
from pinarms.robots.reach.robot_spec import RobotSpec, robot_of, spec_key

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.robot import Robot

__all__ = ["ChunkTask", "solve_chunk", "manipulability_of", "collision_free", "TIE_RTOL"]

#: Relative tolerance under which two solutions' manipulabilities count as tied.
TIE_RTOL = 1e-9
_TIE_ATOL = 1e-15


@dataclass(frozen=True)
class ChunkTask:
    """One chunk of voxels: everything :func:`solve_chunk` needs (picklable, a few kB).

    ``voxels`` are flat indices (C order) into the grid ``origin``/``resolution``/``shape``.
    """

    robot: RobotSpec
    origin: np.ndarray
    resolution: float
    shape: tuple[int, int, int]
    voxels: np.ndarray
    rotations: np.ndarray
    group: np.ndarray
    n_groups: int
    roll_free: bool
    solver: str
    manipulability: str
    restarts: int
    tol: float
    self_collision: bool
    collision: Any
    keep_solutions: bool
    seed: int


def manipulability_of(robot: "Robot", q: np.ndarray, part: str) -> np.ndarray:
    """Manipulability ``(N,)`` of ``q (N, nq)``: ``|det J|``, or ``sqrt(det(J Jᵀ))`` / ``sqrt(det(Jᵀ J))`` when not square.

    ``part="position"`` uses the 3 linear rows of the Jacobian, ``"full"`` all 6.
    """
    if q.shape[0] == 0:
        return np.zeros(0)
    J = robot.jacobian(q)
    if part == "position":
        J = J[:, :3, :]
    m, n = J.shape[1:]
    if m == n:
        return np.abs(np.linalg.det(J))
    G = J @ np.swapaxes(J, 1, 2) if m < n else np.swapaxes(J, 1, 2) @ J
    return np.sqrt(np.clip(np.linalg.det(G), 0.0, None))


_COLLISION_CACHE: dict[tuple, Any] = {}


def _self_collision(spec: RobotSpec, robot: "Robot"):
    """The robot's self-collision checker, built once per process."""
    key = spec_key(spec)
    checker = _COLLISION_CACHE.get(key)
    if checker is None:
        from pinarms.robots.self_collision import SelfCollision

        checker = _COLLISION_CACHE[key] = SelfCollision(robot, seed=0)
    return checker


def collision_free(task: ChunkTask, robot: "Robot", q: np.ndarray) -> np.ndarray:
    """``(N,)`` bool: ``q (N, nq)`` passes the task's self-collision and ``collision`` checks."""
    ok = np.ones(q.shape[0], dtype=bool)
    if q.shape[0] == 0:
        return ok
    if task.self_collision:
        ok &= ~np.asarray(_self_collision(task.robot, robot).in_collision(q), dtype=bool)
    if task.collision is not None:
        idx = np.flatnonzero(ok)
        if idx.size:
            hit = np.asarray(task.collision.in_collision(q[idx]), dtype=bool).reshape(-1)
            if hit.shape != idx.shape:
                raise InvalidInput(
                    f"collision.in_collision returned shape {hit.shape} for {idx.size} configurations; it must return (N,) bool"
                )
            ok[idx[hit]] = False
    return ok


def _best_per_target(idx: np.ndarray, w: np.ndarray, n_targets: int) -> tuple[np.ndarray, np.ndarray]:
    """For solutions sorted by target ``idx (K,)``: the chosen row per target (−1 if none) and its ``w``.

    Chosen: the first (solver order) among those within ``TIE_RTOL`` of the target's largest ``w``.
    """
    choice = np.full(n_targets, -1, dtype=np.int64)
    best = np.full(n_targets, np.nan)
    if idx.size == 0:
        return choice, best
    starts = np.flatnonzero(np.concatenate(([True], idx[1:] != idx[:-1])))
    counts = np.diff(np.append(starts, idx.size))
    wmax = np.repeat(np.maximum.reduceat(w, starts), counts)
    tied = w >= wmax - (_TIE_ATOL + TIE_RTOL * np.abs(wmax))
    rows = np.flatnonzero(tied)
    first = rows[np.concatenate(([True], idx[rows][1:] != idx[rows][:-1]))]
    choice[idx[first]] = first
    best[idx[first]] = w[first]
    return choice, best


def _poses(task: ChunkTask) -> np.ndarray:
    """Targets ``(n·M, 4, 4)``: voxel-major, orientation-minor."""
    P = cell_centres(task.origin, task.resolution, task.shape, task.voxels)
    n, M = P.shape[0], task.rotations.shape[0]
    T = np.zeros((n, M, 4, 4))
    T[:, :, :3, :3] = task.rotations[None]
    T[:, :, :3, 3] = P[:, None, :]
    T[:, :, 3, 3] = 1.0
    return T.reshape(n * M, 4, 4)


def _solve_analytic(task: ChunkTask, robot: "Robot") -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """``(pose index (K,), q (K, nq), w (K,), n_solutions)``: the chosen solution of each reached pose."""
    T = _poses(task)
    idx, q = robot.analytic_ik.candidates(T)
    n_all = int(idx.size)
    keep = collision_free(task, robot, q)
    idx, q = idx[keep], q[keep]
    w = manipulability_of(robot, q, task.manipulability)
    choice, best = _best_per_target(idx, w, T.shape[0])
    reached = np.flatnonzero(choice >= 0)
    return reached, q[choice[reached]], best[reached], n_all


def _solve_numerical(task: ChunkTask, robot: "Robot") -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """As :func:`_solve_analytic`, one seeded numerical solve per pose (one solution per pose).

    Warm start of pose ``k`` of a voxel: the solution of pose ``k`` in a face neighbour already
    solved in this chunk (the voxel below, then behind in y, then in x: voxels come in grid
    order), else the previous roll of the same direction in this voxel; then ``restarts``
    random starts drawn by the generator seeded with ``(seed, voxel flat index)``.
    """
    solver = robot.numerical_ik()
    T = _poses(task)
    n, M = task.voxels.size, task.rotations.shape[0]
    nq = robot.nq
    ny, nz = task.shape[1], task.shape[2]
    solved: dict[int, np.ndarray] = {}
    poses, qs = [], []
    for r in range(n):
        v = int(task.voxels[r])
        rng = np.random.default_rng([task.seed, v])
        k_idx = v % nz
        j_idx = (v // nz) % ny
        neighbours = [solved.get(u) for u, ok in ((v - 1, k_idx > 0), (v - nz, j_idx > 0), (v - ny * nz, True)) if ok]
        neighbours = [a for a in neighbours if a is not None]
        here = np.full((M, nq), np.nan)
        for k in range(M):
            start = next((a[k] for a in neighbours if np.isfinite(a[k, 0])), None)
            if start is None and k > 0 and task.group[k] == task.group[k - 1] and np.isfinite(here[k - 1, 0]):
                start = here[k - 1]  # previous roll of the same direction
            res = solver.solve_checked(T[r * M + k], start, position_only=False, tol=task.tol,
                                max_restarts=task.restarts, seed=rng, limits=True)
            if res.success and collision_free(task, robot, res.q[None])[0]:
                here[k] = res.q
                poses.append(r * M + k)
                qs.append(res.q)
        solved[v] = here
    pose = np.asarray(poses, dtype=np.int64)
    q = np.asarray(qs, dtype=float).reshape(-1, nq)
    return pose, q, manipulability_of(robot, q, task.manipulability), int(pose.size)


def solve_chunk(task: ChunkTask) -> dict:
    """Reachability of one chunk of voxels (the task function of :func:`reachability_map`).

    Returns a dict of arrays: ``voxels (n,)`` (the task's), ``reached (n, M)`` bool, ``index (n,)``, ``best (n,)`` (NaN where
    nothing is reached), ``n_solutions`` (every in-limit solution found, before collisions), and
    with ``keep_solutions`` the reached poses' ``pose_voxel (K,)`` (grid flat index),
    ``pose_orientation (K,)``, ``q (K, nq)`` and ``w (K,)``.
    """
    robot = robot_of(task.robot)
    n, M = task.voxels.size, task.rotations.shape[0]
    if task.solver == "analytic":
        pose, q, w, n_all = _solve_analytic(task, robot)
    else:
        pose, q, w, n_all = _solve_numerical(task, robot)
    reached = np.zeros(n * M, dtype=bool)
    reached[pose] = True
    reached = reached.reshape(n, M)
    if task.roll_free:  # a direction counts when any of its rolls is reached
        per_group = np.zeros((n, task.n_groups), dtype=bool)
        for k in range(M):
            per_group[:, task.group[k]] |= reached[:, k]
        index = per_group.sum(axis=1) / task.n_groups
    else:
        index = reached.sum(axis=1) / M
    best = np.full(n, np.nan)
    if pose.size:  # pose is sorted: the best manipulability per voxel by one reduceat
        rows = pose // M
        starts = np.flatnonzero(np.concatenate(([True], rows[1:] != rows[:-1])))
        best[rows[starts]] = np.maximum.reduceat(w, starts)
    out = {"voxels": task.voxels, "reached": reached, "index": index, "best": best, "n_solutions": n_all}
    if task.keep_solutions:
        out.update(pose_voxel=task.voxels[pose // M], pose_orientation=(pose % M).astype(np.int32), q=q, w=w)
    return out
