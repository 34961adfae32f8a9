"""Check a line layout: can the arm reach each pick/place point, how, and how dexterously?

:func:`check_layout` takes the pick/place points of a line (positions [m] in the robot's
base frame, or full poses) and reports, per point, every inverse-kinematics solution
within the joint limits (the IK *branches*), the position manipulability and inverse
condition of each, and the dexterity margin of the best one:

- ``dexterity_ratio`` = best solution's position manipulability / the median position
  manipulability of the robot's sampled workspace (> 1: better than a typical
  configuration; near 0: close to a singularity),
- ``boundary_margin`` = distance [m] from the point to the edge of the sampled workspace,
  read from a voxel map (:class:`~pinarms.robots.reach.voxels.VoxelMap`).

Solutions come from ``robot.ik_all`` when the arm has a closed form
(``robot.has_analytic_ik``), else from ``robot.ik`` started from several seeded joint
vectors (distinct results are kept: a numerical solver finds branches, not all of them;
under a position-only target, solutions that differ only in joints that do not move the
point count as one branch).

Positions without an orientation get one: for arms with 6 or more joints the tool points
straight down (tool z along the base's −z, tool x along the base's +x), the usual
pick-and-place pose; for arms with fewer joints (SCARA, gantry, koji arm) the orientation
the tool has at the neutral configuration, which these arms keep up to a rotation about the
vertical (yaw). The yaw of such a position-only target is free: when the neutral yaw has no
solution within the limits, the yaws ±5°, ±10°, … ±180° are tried in that order and the
first one with a solution is used (``PointCheck.target`` holds it); if none has one (near
the limits the usable yaws can form a narrow interval), a position-only numerical IK from
``n_seeds`` starts looks for a configuration and the closed form is solved at its yaw. This matters for arms
whose last joint moves the tool point, e.g. the koji arm, whose wrist carries the tool
``H = 0.25 m`` off its axis: its reachable positions need a matching yaw.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput, UnreachableTarget
from pinarms.robots.so3 import rot_z as _rot_z
from pinarms.robots.reach.dexterity import position_dexterity
from pinarms.robots.reach.workspace import Workspace, sample_workspace

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.robot import Robot

__all__ = ["PointCheck", "LayoutReport", "check_layout", "default_orientation"]

_DOWN = np.diag([1.0, -1.0, -1.0])


@dataclass(frozen=True)
class PointCheck:
    """Reachability of one pick/place target.

    Attributes:
        name: label of the point.
        target: ``(4, 4)`` pose asked, tcp → base [m].
        solutions: ``(k, nq)`` IK solutions within the joint limits (k = 0: unreachable),
            every 2π-shifted copy included (see :attr:`n_branches`).
        manipulability: ``(k,)`` position manipulability of each solution.
        inverse_condition: ``(k,)`` ``σ_min/σ_max`` of the position Jacobian of each.
        best: index of the most dexterous solution (-1 if unreachable).
        dexterity_ratio: best manipulability / median of the sampled workspace (0 if unreachable).
        boundary_margin: distance to the edge of the sampled workspace [m] (0 outside it).
    """

    name: str
    target: np.ndarray = field(repr=False)
    solutions: np.ndarray = field(repr=False)
    manipulability: np.ndarray = field(repr=False)
    inverse_condition: np.ndarray = field(repr=False)
    best: int
    dexterity_ratio: float
    boundary_margin: float

    @property
    def reachable(self) -> bool:
        """At least one solution within the joint limits."""
        return self.solutions.shape[0] > 0

    @property
    def n_solutions(self) -> int:
        """Number of IK solutions within the limits (2π-shifted copies of a revolute angle counted apart)."""
        return int(self.solutions.shape[0])

    @property
    def n_branches(self) -> int:
        """Number of distinct arm configurations among :attr:`solutions`.

        Solutions whose joint values differ only by multiples of 2π (a revolute joint with
        a range wider than one turn, e.g. the UR arms' ±360°) are the same configuration of
        the arm and count once: a UR5 pose has at most 8 branches but up to 8·2⁶ solutions.
        (A prismatic joint's values would have to differ by exactly 2π m to be merged.)
        """
        q = self.solutions
        if q.shape[0] < 2:
            return int(q.shape[0])
        d = q[:, None, :] - q[None, :, :]
        same = np.all(np.abs((d + np.pi) % (2.0 * np.pi) - np.pi) < 1e-6, axis=2)
        first = np.argmax(same, axis=1)  # lowest index of each solution's class
        return int(np.count_nonzero(first == np.arange(q.shape[0])))


@dataclass(frozen=True)
class LayoutReport:
    """Result of :func:`check_layout`: one :class:`PointCheck` per point."""

    robot: str
    frame: str
    method: str  # "analytic" or "numerical"
    points: tuple[PointCheck, ...]
    median_manipulability: float

    @property
    def all_reachable(self) -> bool:
        """Every point has at least one solution."""
        return all(p.reachable for p in self.points)

    @property
    def reachable(self) -> np.ndarray:
        """``(N,)`` bool per point."""
        return np.array([p.reachable for p in self.points], dtype=bool)

    def text(self) -> str:
        """A readable table (mm)."""
        lines = [
            f"layout check of {self.robot} ({self.frame}, {self.method} IK; dexterity = w / median w "
            f"of the workspace = {self.median_manipulability:.4g})",
            "  point                 x [mm]   y [mm]   z [mm]  branches (solutions)  dexterity  σmin/σmax  margin [mm]",
        ]
        for p in self.points:
            x, y, z = p.target[:3, 3] * 1000.0
            if p.reachable:
                lines.append(
                    f"  {p.name:<20s} {x:8.1f} {y:8.1f} {z:8.1f}  {p.n_branches:8d} {f'({p.n_solutions})':>11s}"
                    f"  {p.dexterity_ratio:9.2f}"
                    f"  {p.inverse_condition[p.best]:9.3f}  {p.boundary_margin * 1000.0:11.0f}"
                )
            else:
                lines.append(f"  {p.name:<20s} {x:8.1f} {y:8.1f} {z:8.1f}  UNREACHABLE within the joint limits")
        lines.append("  all points reachable" if self.all_reachable else "  some points are NOT reachable: move them or the robot")
        return "\n".join(lines)


def default_orientation(robot: "Robot") -> np.ndarray:
    """Tool orientation ``(3, 3)`` used for position-only targets (see the module doc)."""
    if robot.nq >= 6:
        return _DOWN.copy()
    return robot.fk(robot.neutral)[:3, :3]


_YAW_STEP_DEG = 5


def _yaw_candidates() -> np.ndarray:
    """Yaws [rad] tried for position-only targets of arms with < 6 joints: 0, +5°, −5°, … 180°."""
    steps = [0]
    for k in range(1, 180 // _YAW_STEP_DEG):
        steps += [k * _YAW_STEP_DEG, -k * _YAW_STEP_DEG]
    return np.radians(steps + [180])


def _targets(robot: "Robot", points: Any, orientation: Any) -> np.ndarray:
    try:
        arr = np.asarray(points, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"points must be positions (N, 3) [m] or poses (N, 4, 4) of numbers, got {points!r}") from exc
    if arr.ndim == 1 and arr.shape == (3,):
        arr = arr[None]
    if arr.ndim == 2 and arr.shape == (4, 4) and orientation is None and np.allclose(arr[3], [0, 0, 0, 1]):
        arr = arr[None]
    if arr.ndim == 3 and arr.shape[1:] == (4, 4):
        T = arr.copy()
    elif arr.ndim == 2 and arr.shape[1] == 3:
        R = default_orientation(robot) if orientation is None else np.asarray(orientation, dtype=float)
        if R.shape != (3, 3) or not np.allclose(R @ R.T, np.eye(3), atol=1e-6):
            raise InvalidInput(f"orientation must be a (3, 3) rotation matrix, got {np.shape(orientation)}")
        T = np.tile(np.eye(4), (arr.shape[0], 1, 1))
        T[:, :3, :3] = R
        T[:, :3, 3] = arr
    else:
        raise InvalidInput(f"points must be positions (N, 3) [m] or poses (N, 4, 4), got shape {arr.shape}")
    if T.shape[0] == 0 or not np.all(np.isfinite(T)):
        raise InvalidInput("points must be a non-empty array of finite numbers")
    return T


def _numerical_solutions(robot: "Robot", T: np.ndarray, n_seeds: int, seed: int, position_only: bool) -> list[np.ndarray]:
    seeds = np.vstack([robot.neutral[None], robot.random_q(max(1, n_seeds - 1), seed=seed)])
    out = []
    for target in T:
        found: list[np.ndarray] = []
        for qs in seeds:
            try:
                q = np.asarray(robot.ik(target, q_seed=qs, position_only=position_only), dtype=float)
            except UnreachableTarget:
                continue
            # joints that do not move the point (e.g. a SCARA's hand rotation under a
            # position-only target) do not make a new branch
            moves = np.linalg.norm(robot.jacobian(q)[:3], axis=0) > 1e-9 if position_only else np.ones(robot.nq, bool)
            if not any(np.max(np.abs(q - f)[moves], initial=0.0) < 1e-6 for f in found):
                found.append(q)
        out.append(np.array(found).reshape(-1, robot.nq))
    return out


def check_layout(
    robot: "Robot",
    points: ArrayLike,
    *,
    names: Sequence[str] | None = None,
    orientation: ArrayLike | None = None,
    workspace: Workspace | None = None,
    voxel_size: float | None = None,
    n_seeds: int = 8,
    seed: int = 0,
) -> LayoutReport:
    """Which of the line's ``points`` the arm reaches, with which IK branches and dexterity margin.

    Args:
        robot: any :class:`~pinarms.robots.robot.Robot`.
        points: positions ``(N, 3)`` [m] (tool orientation from ``orientation`` or
            :func:`default_orientation`) or poses ``(N, 4, 4)`` (tcp → base).
        names: labels of the points (default ``P1, P2, ...``).
        workspace: a sampled workspace of the robot's tcp used for the dexterity median
            and the boundary margin (default: 100 000 samples with ``seed``).
        voxel_size: voxel edge of the boundary-margin map [m]; default: about 10 samples
            per reachable voxel (:func:`pinarms.robots.reach.voxels.suggest_voxel_size`).
        n_seeds: starts of the numerical IK (arms without a closed form), ≥ 1.
        seed: seed of the default workspace and of the numerical IK starts.

    Position-only targets of arms with fewer than 6 joints have a free yaw (module doc).

    Raises:
        InvalidInput: malformed points, names, orientation or n_seeds, or a workspace of
            another robot or frame.
    """
    T = _targets(robot, points, orientation)
    yaw_free = orientation is None and robot.nq < 6 and np.ndim(points) in (1, 2) and np.shape(points)[-1] == 3
    N = T.shape[0]
    if isinstance(n_seeds, bool) or not isinstance(n_seeds, (int, np.integer)) or n_seeds < 1:
        raise InvalidInput(f"n_seeds must be an integer >= 1 (starts of the numerical IK), got {n_seeds!r}")
    if names is None:
        names = [f"P{i + 1}" for i in range(N)]
    names = [str(n) for n in names]
    if len(names) != N:
        raise InvalidInput(f"got {len(names)} names for {N} points")
    workspace = _tcp_workspace(robot, workspace, seed)
    median_w = float(np.median(workspace.manipulability))
    vmap = workspace.voxel_map(voxel_size)
    margins = vmap.query(T[:, :3, 3]).margin

    if robot.has_analytic_ik:
        method = "analytic"
        sols = [np.asarray(s, dtype=float).reshape(-1, robot.nq) for s in robot.ik_all(T, equivalents=True)]
        if yaw_free:
            _solve_with_free_yaw(robot, T, sols, n_seeds, seed)
    else:
        method = "numerical"
        sols = _numerical_solutions(robot, T, n_seeds, seed, position_only=robot.nq < 6)
    checks = [_point_check(robot, *row, median_w) for row in zip(names, T, sols, margins)]
    return LayoutReport(robot.name, workspace.frame, method, tuple(checks), median_w)


def _tcp_workspace(robot: "Robot", workspace: Workspace | None, seed: int) -> Workspace:
    """``workspace`` checked to be the robot's tcp workspace, or 100 000 samples seeded ``seed``."""
    if workspace is None:
        return sample_workspace(robot, 100_000, seed=seed, frame="tcp")
    if not isinstance(workspace, Workspace) or workspace.robot.name != robot.name or (
        workspace.robot.frame_id(workspace.frame) != robot.frame_id("tcp")
    ):
        raise InvalidInput(
            "workspace must be a Workspace sampled for this robot's tcp "
            f"(sample_workspace({robot.name!r}, frame='tcp')), got "
            + (f"one of {workspace.robot.name!r} ({workspace.frame})" if isinstance(workspace, Workspace) else type(workspace).__name__)
        )
    return workspace


def _solve_with_free_yaw(robot: "Robot", T: np.ndarray, sols: list, n_seeds: int, seed: int) -> None:
    """Position-only targets of an arm that keeps the tool vertical: their yaw is free.

    For each target without a closed-form solution, try the other yaws of the grid, then a
    position-only numerical solve (near the limits the usable yaws can be a narrow interval
    between grid values) whose rotation the closed form then solves for its branches.
    ``T (N, 4, 4)`` and ``sols`` are updated in place with the yaw that worked.
    """
    R0 = T[:, :3, :3].copy()
    for yaw in _yaw_candidates()[1:]:
        todo = [i for i, q in enumerate(sols) if q.shape[0] == 0]
        if not todo:
            break
        Ty = T[todo].copy()
        Ty[:, :3, :3] = _rot_z(yaw) @ R0[todo]
        for i, Ti, q in zip(todo, Ty, robot.ik_all(Ty, equivalents=True)):
            q = np.asarray(q, dtype=float).reshape(-1, robot.nq)
            if q.shape[0]:
                sols[i], T[i] = q, Ti
    todo = [i for i, q in enumerate(sols) if q.shape[0] == 0]
    if todo:
        for i, q in zip(todo, _numerical_solutions(robot, T[todo], n_seeds, seed, position_only=True)):
            if q.shape[0]:
                Ti = T[i].copy()
                Ti[:3, :3] = robot.fk(q[0])[:3, :3]
                exact = np.asarray(robot.ik_all(Ti, equivalents=True), dtype=float).reshape(-1, robot.nq)
                sols[i], T[i] = (exact, Ti) if exact.shape[0] else (q[:1], Ti)


def _point_check(robot: "Robot", name: str, target: np.ndarray, q: np.ndarray, margin: float,
                 median_w: float) -> PointCheck:
    """The :class:`PointCheck` of one target: its branches' dexterity, the best branch and its ratio to the median."""
    if q.shape[0]:
        J = robot.jacobian(q)[:, :3, :]
        w, c = position_dexterity(J)
        best = int(np.argmax(w))
        ratio = float(w[best] / median_w) if median_w > 0 else float("inf")
    else:
        w = c = np.zeros(0)
        best, ratio = -1, 0.0
    return PointCheck(name, target, q, w, c, best, ratio, float(margin))
