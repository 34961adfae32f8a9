"""Inverse reachability: where the base may stand so that every task pose is reachable.

The arm's base stands on a plane at height ``z`` [m] (world frame), at ``(x, y)`` with a yaw
``ψ`` about the vertical: ``T_base_to_world = Trans(x, y, z) · Rz(ψ)``. A task pose
``task_to_world`` (tool frame → world) is, seen from that base, ``task_to_base = T_base_to_world⁻¹ · task_to_world``.

:func:`base_placements` answers with the inverse of a :class:`~pinarms.robots.reach.reachability.ReachabilityMap`
restricted to bases on the plane:

1. **Candidates.** A grid of ``(x, y) = (i, j)·xy_step`` (default step: the map's resolution)
   over the tasks' bounding box grown by the map's horizontal reach, times yaws ``k·yaw_step``.
   A base farther (horizontally) from a task than the farthest reachable voxel of the map is
   dropped at once.
2. **Map lookups.** For each candidate and task: the voxel of ``task_to_base``'s position and the set's
   orientation nearest ``task_to_base``'s (for *roll-free* tasks, such as a gripper closing on a
   mushroom with the tool pointing down, only the tool axis matters: a roll-free map's
   direction group, or for an SO(3) map any of ``roll_steps`` rolls about the tool axis).
   A candidate is *feasible on the map* when every task is reached there.
3. **Score and rank.** ``index_sum`` = the sum over tasks of the reached directions (or
   rotations) of the task's voxel, an integer, i.e. the mean reachability index times the
   count: how much orientation freedom is left around the tasks; then the smallest best
   manipulability of the tasks' voxels; then the candidate's grid order (x, then y, then
   yaw). Manipulabilities within 1e-9 relative count as tied.
4. **Check** (:mod:`pinarms.robots.reach.base_verify`). The ``verify`` best candidates are solved exactly by IK (every closed-form branch
   within the limits, or the numerical solver) at the exact task poses (rolls tried for
   roll-free tasks) with the collision checks given; ``verified`` says whether every task has
   a solution, ``ik_manipulability`` the smallest (over tasks) best manipulability. The final
   order puts verified candidates first (then the map's order).

The map is a discretisation (voxel centres, a finite orientation set): a candidate feasible on
the map can fail the exact check near the workspace boundary, which is why the check exists.
The candidates are what ``optim.search_layout`` can start from (:meth:`BasePlacements.poses`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput, ModelError
from pinarms.robots.reach.orientations import align_rotations
from pinarms.robots.so3 import about as rotations_about
from pinarms.robots.reach.base_verify import verify_bases
from pinarms.robots.reach.reach_map import ReachabilityMap
from pinarms.robots.reach.robot_spec import urdf_sha256

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.robot import Robot

__all__ = ["BasePlacements", "IKCheck", "base_placements", "tool_down_poses", "MAX_CANDIDATES"]

#: Most (x, y, yaw) candidates one call evaluates on the map.
MAX_CANDIDATES = 20_000_000
_BLOCK = 250_000
_DOWN = np.array([0.0, 0.0, -1.0])


def tool_down_poses(points: ArrayLike, tool_axis: ArrayLike = (0.0, 0.0, 1.0)) -> np.ndarray:
    """Task poses ``(N, 4, 4)`` at ``points (N, 3)`` [m] with ``tool_axis`` (tool frame) pointing straight down.

    Roll zero as in :func:`pinarms.robots.reach.orientations.tool_axis_orientations` (a fixed rotation taking
    the tool axis to ``(0, 0, −1)``); a roll-free task ignores it.
    """
    P = _as_points(points)
    axis = np.asarray(tool_axis, dtype=float)
    if axis.shape != (3,) or not np.all(np.isfinite(axis)) or np.linalg.norm(axis) < 1e-12:
        raise InvalidInput(f"tool_axis must be a finite non-zero 3-vector, got {tool_axis!r}")
    R = align_rotations(axis / np.linalg.norm(axis), _DOWN[None])[0]
    T = np.tile(np.eye(4), (P.shape[0], 1, 1))
    T[:, :3, :3] = R
    T[:, :3, 3] = P
    return T


def _as_points(points: Any) -> np.ndarray:
    try:
        P = np.asarray(points, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"points must be numbers with shape (N, 3) [m], got {points!r}") from exc
    P = P.reshape(1, 3) if P.shape == (3,) else P
    if P.ndim != 2 or P.shape[1] != 3 or P.shape[0] == 0 or not np.all(np.isfinite(P)):
        raise InvalidInput(f"points must be a non-empty finite (N, 3) array [m], got shape {np.shape(points)}")
    return P


def _as_tasks(tasks: Any) -> np.ndarray:
    try:
        T = np.asarray(tasks, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"tasks must be poses (N, 4, 4) [m], got {tasks!r}") from exc
    T = T[None] if T.shape == (4, 4) else T
    if T.ndim != 3 or T.shape[1:] != (4, 4) or T.shape[0] == 0 or not np.all(np.isfinite(T)):
        raise InvalidInput(f"tasks must be a non-empty finite array of poses (N, 4, 4), got shape {np.shape(tasks)}")
    R = T[:, :3, :3]
    if np.abs(R @ np.swapaxes(R, 1, 2) - np.eye(3)).max() > 1e-6 or np.any(np.linalg.det(R) < 0):
        raise InvalidInput("tasks: every rotation block must be a proper rotation (orthonormal, det +1)")
    return T


@dataclass(frozen=True, eq=False)
class BasePlacements:
    """Base poses from which every task is reachable, best first (see the module doc).

    Attributes:
        tasks: ``(N, 4, 4)`` task poses, tool frame → world.
        roll_free: tasks ignore the roll about the tool axis.
        z: height of the base plane [m]; ``xy_step`` [m], ``yaw_step`` [rad] of the grid.
        candidates: ``(C, 4)`` ``x, y, z, yaw`` [m, rad] of the bases feasible on the map, best first.
        index_sum: ``(C,)`` int, reached directions (or rotations) summed over the tasks' voxels.
        index_mean: ``(C,)`` mean reachability index over the tasks.
        manipulability: ``(C,)`` smallest best manipulability of the tasks' voxels (map).
        checked: ``(C,)`` bool, solved exactly by IK; ``verified`` ``(C,)`` every task solved;
        ik_manipulability: ``(C,)`` smallest over tasks of the best exact manipulability (NaN unchecked).
        n_grid: candidates in the grid; ``n_lookups`` map lookups made.
    """

    tasks: np.ndarray = field(repr=False)
    roll_free: bool
    z: float
    xy_step: float
    yaw_step: float
    candidates: np.ndarray = field(repr=False)
    index_sum: np.ndarray = field(repr=False)
    index_mean: np.ndarray = field(repr=False)
    manipulability: np.ndarray = field(repr=False)
    checked: np.ndarray = field(repr=False)
    verified: np.ndarray = field(repr=False)
    ik_manipulability: np.ndarray = field(repr=False)
    n_grid: int = 0
    n_lookups: int = 0

    def __len__(self) -> int:
        return int(self.candidates.shape[0])

    @property
    def best(self) -> np.ndarray | None:
        """``(x, y, z, yaw)`` of the best verified candidate, or ``None``."""
        ok = np.flatnonzero(self.verified)
        return None if ok.size == 0 else self.candidates[ok[0]].copy()

    def poses(self, n: int | None = None) -> np.ndarray:
        """``(n, 4, 4)`` base → world poses of the first ``n`` candidates (default all)."""
        c = self.candidates if n is None else self.candidates[: int(n)]
        T = np.tile(np.eye(4), (c.shape[0], 1, 1))
        cz, sz = np.cos(c[:, 3]), np.sin(c[:, 3])
        T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = cz, -sz, sz, cz
        T[:, :3, 3] = c[:, :3]
        return T

    def text(self, n: int = 5) -> str:
        """A readable summary (mm, degrees) of the first ``n`` candidates."""
        lines = [
            f"base placements on the plane z = {self.z * 1000:.0f} mm for {self.tasks.shape[0]} task poses"
            f"{' (roll free)' if self.roll_free else ''}: {len(self)} of {self.n_grid} grid candidates feasible on the map, "
            f"{int(self.verified.sum())} of {int(self.checked.sum())} checked by IK verified",
            "   x [mm]   y [mm]  yaw [°]  mean index  min w (map)  IK  min w (IK)",
        ]
        for c, im, w, ch, v, wi in zip(self.candidates[:n], self.index_mean, self.manipulability, self.checked,
                                       self.verified, self.ik_manipulability):
            ik = ("yes" if v else "no") if ch else "-"
            lines.append(f"  {c[0] * 1000:7.0f}  {c[1] * 1000:7.0f}  {np.degrees(c[3]):7.1f}  {im:10.3f}  {w:11.4g}  "
                         f"{ik:>3}  {wi:10.4g}")
        return "\n".join(lines)


def _horizontal_reach(m: ReachabilityMap) -> float:
    c = m.centres(m.voxels[m.index > 0])
    if c.shape[0] == 0:
        return 0.0
    return float(np.hypot(c[:, 0], c[:, 1]).max() + np.sqrt(0.5) * m.resolution)


def _tie_ranks(values: np.ndarray) -> np.ndarray:
    """Ranks of ``values`` descending, values within 1e-9 relative of a run's first sharing its rank."""
    order = np.argsort(-values, kind="stable")
    ranks = np.empty(values.size, dtype=np.int64)
    rank, i = 0, 0
    v = values[order]
    while i < v.size:
        j = i + 1
        while j < v.size and v[j] >= v[i] - (1e-15 + 1e-9 * abs(v[i])):
            j += 1
        ranks[order[i:j]] = rank
        rank += 1
        i = j
    return ranks


@dataclass(frozen=True)
class IKCheck:
    """How :func:`base_placements` checks its best map candidates by exact IK.

    Attributes:
        robot: the arm (its URDF must be the map's).
        verify: how many of the best map candidates to check (0: none).
        self_collision, collision: collision checks of the exact IK solutions (as in
            :func:`pinarms.robots.reachability_map`).

    Raises:
        InvalidInput: no robot, or ``verify`` not a non-negative integer.
    """

    robot: Robot
    verify: int = 20
    self_collision: bool = False
    collision: Any = None

    def __post_init__(self) -> None:
        if self.robot is None:
            raise InvalidInput("IKCheck needs the robot=... the map was built for (or pass no check)")
        v = self.verify
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0:
            raise InvalidInput(f"verify must be a non-negative integer, got {v!r}")


def base_placements(
    reach_map: ReachabilityMap,
    tasks: ArrayLike,
    *,
    z: float = 0.0,
    roll_free: bool = True,
    xy_step: float | None = None,
    yaw_step: float = np.radians(10.0),
    roll_steps: int = 8,
    check: IKCheck | None = None,
) -> BasePlacements:
    """Bases ``(x, y, yaw)`` on the plane at ``z`` from which every task pose is reachable (module doc).

    Args:
        reach_map: the arm's reachability map (its base frame).
        tasks: task poses ``(N, 4, 4)``, tool frame → world [m] (see :func:`tool_down_poses`).
        z: height of the base plane in the world [m].
        roll_free: only the tool axis of each task matters (the map set's tool axis).
        xy_step: grid step [m] (default the map's resolution); yaw_step [rad].
        roll_steps: rolls tried per roll-free task on an SO(3) map and in the exact check.
        check: the exact IK check of the best candidates (:class:`IKCheck`); ``None``: none.

    Raises:
        InvalidInput: bad tasks, steps, a grid larger than :data:`MAX_CANDIDATES`.
        ModelError: ``robot`` is not the robot the map was built for.
    """
    if check is not None and not isinstance(check, IKCheck):
        raise InvalidInput(f"check must be a robots.reach.inverse_reach.IKCheck, got {type(check).__name__}")
    robot, verify = (None, 0) if check is None else (check.robot, check.verify)
    self_collision, collision = (False, None) if check is None else (check.self_collision, check.collision)
    T_tasks, z, step = _checked_arguments(reach_map, tasks, robot, z, xy_step, yaw_step, roll_steps)
    X, Y, yaws, n_grid = _candidate_grid(reach_map, T_tasks[:, :3, 3], step, yaw_step)
    xyyaw, sums, wmin, n_lookups = _feasible_on_map(reach_map, T_tasks, X, Y, yaws, z, roll_free, roll_steps)
    order = _map_order(xyyaw, sums, wmin)
    xyyaw, sums, wmin = xyyaw[order], sums[order], wmin[order]
    C = xyyaw.shape[0]
    candidates = np.column_stack([xyyaw[:, 0], xyyaw[:, 1], np.full(C, z), xyyaw[:, 2]])
    checked, verified, ik_w = _exact_check(robot, reach_map, candidates, T_tasks, int(verify), roll_free, roll_steps,
                                           self_collision, collision)
    if checked.any():  # verified candidates first, then the map's order
        final = np.lexsort((np.arange(C), ~verified))
        candidates, sums, wmin = candidates[final], sums[final], wmin[final]
        checked, verified, ik_w = checked[final], verified[final], ik_w[final]
    index_mean = sums / (T_tasks.shape[0] * reach_map.orientations.n_index)
    return BasePlacements(
        tasks=T_tasks, roll_free=bool(roll_free), z=z, xy_step=step, yaw_step=float(yaw_step), candidates=candidates,
        index_sum=sums, index_mean=index_mean, manipulability=wmin, checked=checked, verified=verified,
        ik_manipulability=ik_w, n_grid=int(n_grid), n_lookups=int(n_lookups),
    )


def _checked_arguments(reach_map: Any, tasks: Any, robot: "Robot | None", z: Any, xy_step: Any, yaw_step: Any,
                       roll_steps: Any) -> tuple[np.ndarray, float, float]:
    """The tasks ``(N, 4, 4)``, the plane's height ``z`` [m] and the grid step [m], every argument checked in order."""
    if not isinstance(reach_map, ReachabilityMap):
        raise InvalidInput(f"reach_map must be a ReachabilityMap, got {type(reach_map).__name__}")
    T_tasks = _as_tasks(tasks)
    z = float(z)
    if not np.isfinite(z):
        raise InvalidInput(f"z must be a finite height in m, got {z!r}")
    step = float(reach_map.resolution if xy_step is None else xy_step)
    if not (np.isfinite(step) and step > 0):
        raise InvalidInput(f"xy_step must be a positive length in m, got {xy_step!r}")
    if not (np.isfinite(yaw_step) and 0 < yaw_step <= 2 * np.pi):
        raise InvalidInput(f"yaw_step must be in (0, 2π] rad, got {yaw_step!r}")
    if isinstance(roll_steps, bool) or not isinstance(roll_steps, (int, np.integer)) or roll_steps < 1:
        raise InvalidInput(f"roll_steps must be a positive integer, got {roll_steps!r}")
    if robot is not None and urdf_sha256(robot) != reach_map.urdf_sha256:
        raise ModelError(f"the map was built for '{reach_map.robot}' (another URDF than robot '{robot.name}')")
    return T_tasks, z, step


def _candidate_grid(reach_map: ReachabilityMap, P: np.ndarray, step: float,
                    yaw_step: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Step 1: base positions ``X, Y (n,)`` within the map's horizontal reach of every task ``P (N, 3)``,
    the yaws, and the number of grid candidates (x × y × yaw)."""
    reach = _horizontal_reach(reach_map)
    lo, hi = P[:, :2].min(axis=0) - reach, P[:, :2].max(axis=0) + reach
    # grid aligned on multiples of the step (x = i·step, y = j·step)
    xs = step * np.arange(int(np.ceil(lo[0] / step)), int(np.floor(hi[0] / step)) + 1)
    ys = step * np.arange(int(np.ceil(lo[1] / step)), int(np.floor(hi[1] / step)) + 1)
    yaws = yaw_step * np.arange(int(np.ceil(2 * np.pi / yaw_step - 1e-9)))
    n_grid = xs.size * ys.size * yaws.size
    if n_grid > MAX_CANDIDATES:
        raise InvalidInput(f"{n_grid} candidates (x {xs.size} × y {ys.size} × yaw {yaws.size}); raise xy_step or yaw_step")
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    X, Y = X.reshape(-1), Y.reshape(-1)
    near = np.all(np.hypot(X[:, None] - P[None, :, 0], Y[:, None] - P[None, :, 1]) <= reach, axis=1)
    return X[near], Y[near], yaws, n_grid


def _feasible_on_map(reach_map: ReachabilityMap, T_tasks: np.ndarray, X: np.ndarray, Y: np.ndarray, yaws: np.ndarray,
                     z: float, roll_free: bool, roll_steps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Step 2: the candidates where the map reaches every task, yaw-major.

    Returns ``(x, y, yaw) (C, 3)``, ``index_sum (C,)``, the smallest best manipulability of the
    tasks' voxels ``(C,)`` and the number of map lookups made.
    """
    oset = reach_map.orientations
    rolls = rotations_about(oset.tool_axis, 2 * np.pi * np.arange(roll_steps) / roll_steps) if roll_free else None
    group_reached, count_per_voxel = _voxel_tables(reach_map, roll_free)
    P = T_tasks[:, :3, 3]
    N = T_tasks.shape[0]
    cand_xyyaw, cand_sum, cand_w = [], [], []
    n_lookups = 0
    for yaw in yaws:
        c, s = np.cos(yaw), np.sin(yaw)
        Rz_T = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # Rz(yaw)ᵀ
        # orientation lookups do not depend on x, y: once per yaw (task rotations in base axes)
        kind, which = _task_orientations(oset, Rz_T @ T_tasks[:, :3, :3], roll_free, rolls)
        for start in range(0, X.size, _BLOCK):
            xb, yb = X[start : start + _BLOCK], Y[start : start + _BLOCK]
            n = xb.size
            rel = P[None, :, :] - np.stack([xb, yb, np.full(n, z)], axis=1)[:, None, :]  # (n, N, 3)
            pb = rel @ Rz_T.T
            rows = reach_map.rows_of(pb.reshape(-1, 3)).reshape(n, N)
            n_lookups += n * N
            ok = np.all(rows >= 0, axis=1)
            if not ok.any():
                continue
            r_ok = rows[ok]
            feasible = np.all(_tasks_reached(reach_map, group_reached, r_ok, kind, which), axis=1)
            if not feasible.any():
                continue
            idx = np.flatnonzero(ok)[feasible]
            rf = r_ok[feasible]
            cand_xyyaw.append(np.column_stack([xb[idx], yb[idx], np.full(idx.size, yaw)]))
            cand_sum.append(count_per_voxel[rf].sum(axis=1))
            cand_w.append(np.nanmin(reach_map.best_manipulability[rf], axis=1))
    if not cand_xyyaw:
        return np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(0), n_lookups
    return np.concatenate(cand_xyyaw), np.concatenate(cand_sum), np.concatenate(cand_w), n_lookups


def _voxel_tables(reach_map: ReachabilityMap, roll_free: bool) -> tuple[np.ndarray | None, np.ndarray]:
    """Per map voxel row: the reached direction groups ``(V, G)`` (roll-free tasks on a roll-free map;
    else ``None``) and the reached directions (or rotations) ``(V,)`` that ``index_sum`` adds up."""
    oset = reach_map.orientations
    group_reached = None
    if roll_free and oset.roll_free:
        group_reached = np.zeros((reach_map.n_voxels, oset.n_groups), dtype=bool)
        for k in range(oset.size):
            group_reached[:, oset.group[k]] |= reach_map.reached[:, k]
    if oset.roll_free:
        count_per_voxel = np.round(reach_map.index * oset.n_index).astype(np.int64)
    else:
        count_per_voxel = reach_map.reached.sum(axis=1).astype(np.int64)
    return group_reached, count_per_voxel


def _task_orientations(oset: Any, R_b: np.ndarray, roll_free: bool, rolls: np.ndarray | None) -> tuple[str, np.ndarray]:
    """What each task needs of the map, its rotation ``R_b (N, 3, 3)`` seen in base axes:
    ``("group", (N,))`` the direction group of a roll-free map, or ``("rot", (N, r))`` rotations
    of the set of which any will do (the nearest of each roll, or of the rotation itself)."""
    if roll_free and oset.roll_free:
        d = R_b @ oset.tool_axis
        return "group", np.argmax(d @ oset.directions.T, axis=1)
    if roll_free:
        ks = [oset.nearest(R_b @ rolls[r])[0] for r in range(rolls.shape[0])]
        return "rot", np.stack(ks, axis=1)
    return "rot", oset.nearest(R_b)[0][:, None]


def _tasks_reached(reach_map: ReachabilityMap, group_reached: np.ndarray | None, rows: np.ndarray, kind: str,
                   which: np.ndarray) -> np.ndarray:
    """``(n, N)`` bool: task ``j`` is reached in map voxel row ``rows[i, j]`` (see :func:`_task_orientations`)."""
    if kind == "group":
        return group_reached[rows, np.broadcast_to(which, rows.shape)]
    hit = np.zeros(rows.shape, dtype=bool)
    for j in range(which.shape[1]):
        hit |= reach_map.reached[rows, np.broadcast_to(which[:, j], rows.shape)]
    return hit


def _map_order(xyyaw: np.ndarray, sums: np.ndarray, wmin: np.ndarray) -> np.ndarray:
    """Step 3: most reached directions first, then the largest smallest manipulability (ties within
    1e-9 relative), then the grid order (x, then y, then yaw; candidates were collected yaw-major)."""
    grid_key = np.lexsort((xyyaw[:, 2], xyyaw[:, 1], xyyaw[:, 0])) if xyyaw.size else np.zeros(0, np.int64)
    pos = np.empty_like(grid_key)
    pos[grid_key] = np.arange(grid_key.size)
    return np.lexsort((pos, _tie_ranks(wmin) if wmin.size else wmin, -sums))


def _exact_check(robot: "Robot | None", reach_map: ReachabilityMap, candidates: np.ndarray, T_tasks: np.ndarray,
                 verify: int, roll_free: bool, roll_steps: int, self_collision: bool,
                 collision: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step 4: ``checked``, ``verified`` and ``ik_manipulability`` ``(C,)`` of the first ``verify`` candidates."""
    C = candidates.shape[0]
    checked = np.zeros(C, dtype=bool)
    verified = np.zeros(C, dtype=bool)
    ik_w = np.full(C, np.nan)
    n_check = min(verify, C)
    if n_check:
        checked[:n_check] = True
        verified[:n_check], ik_w[:n_check] = verify_bases(robot, reach_map, candidates[:n_check], T_tasks, roll_free,
                                                          roll_steps, self_collision, collision)
    return checked, verified, ik_w
