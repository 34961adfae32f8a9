"""Check a line layout: can the arm reach each pick/place point, how, and how dexterously?

:func:`check_layout` takes the pick/place points of a line (positions [m] in the robot's
base frame, or full poses) and reports, per point, every inverse-kinematics solution
within the joint limits (the IK *branches*), the position manipulability and inverse
condition of each, and the dexterity margin of the best one:

- ``dexterity_ratio`` = best solution's position manipulability / the median position
  manipulability of the robot's sampled workspace (> 1: better than a typical
  configuration; near 0: close to a singularity),
- ``boundary_margin`` = distance [m] from the point to the edge of the sampled workspace,
  read from a voxel map (:class:`~robots.voxels.VoxelMap`).

Solutions come from ``robot.ik_all`` when the arm has a closed form
(``robot.has_analytic_ik``), else from ``robot.ik`` started from several seeded joint
vectors (distinct results are kept: a numerical solver finds branches, not all of them;
under a position-only target, solutions that differ only in joints that do not move the
point count as one branch).

Positions without an orientation get one: for arms with 6 or more joints the tool points
straight down (tool z along the base's −z, tool x along the base's +x), the usual
pick-and-place pose; for arms with fewer joints (SCARA, gantry, koji arm) the orientation
the tool has at the neutral configuration, which these arms keep up to a rotation about the
vertical that their last joint provides.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import InvalidInput, UnreachableTarget
from .workspace import Workspace, position_dexterity, sample_workspace

if TYPE_CHECKING:  # pragma: no cover
    from .robot import Robot

__all__ = ["PointCheck", "LayoutReport", "check_layout", "default_orientation"]

_DOWN = np.diag([1.0, -1.0, -1.0])


@dataclass(frozen=True)
class PointCheck:
    """Reachability of one pick/place target.

    Attributes:
        name: label of the point.
        target: ``(4, 4)`` pose asked, tcp → base [m].
        solutions: ``(k, nq)`` IK solutions within the joint limits (k = 0: unreachable).
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
    def n_branches(self) -> int:
        """Number of distinct IK solutions found."""
        return int(self.solutions.shape[0])


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
            "  point                 x [mm]   y [mm]   z [mm]  branches  dexterity  σmin/σmax  margin [mm]",
        ]
        for p in self.points:
            x, y, z = p.target[:3, 3] * 1000.0
            if p.reachable:
                lines.append(
                    f"  {p.name:<20s} {x:8.1f} {y:8.1f} {z:8.1f}  {p.n_branches:8d}  {p.dexterity_ratio:9.2f}"
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


def _targets(robot: "Robot", points: Any, orientation: Any) -> np.ndarray:
    arr = np.asarray(points, dtype=float)
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
    points: Any,
    *,
    names: Any = None,
    orientation: Any = None,
    workspace: Workspace | None = None,
    voxel_size: float = 0.02,
    n_seeds: int = 8,
    seed: int = 0,
) -> LayoutReport:
    """Which of the line's ``points`` the arm reaches, with which IK branches and dexterity margin.

    Args:
        robot: any :class:`~robots.robot.Robot`.
        points: positions ``(N, 3)`` [m] (tool orientation from ``orientation`` or
            :func:`default_orientation`) or poses ``(N, 4, 4)`` (tcp → base).
        names: labels of the points (default ``P1, P2, ...``).
        workspace: a sampled workspace of the robot's tcp used for the dexterity median
            and the boundary margin (default: 100 000 samples with ``seed``).
        voxel_size: voxel edge of the boundary-margin map [m].
        n_seeds: starts of the numerical IK (arms without a closed form).

    Raises:
        InvalidInput: malformed points, names or orientation.
    """
    T = _targets(robot, points, orientation)
    N = T.shape[0]
    if names is None:
        names = [f"P{i + 1}" for i in range(N)]
    names = [str(n) for n in names]
    if len(names) != N:
        raise InvalidInput(f"got {len(names)} names for {N} points")
    if workspace is None:
        workspace = sample_workspace(robot, 100_000, seed=seed, frame="tcp")
    median_w = float(np.median(workspace.manipulability))
    vmap = workspace.voxel_map(voxel_size)
    margins = vmap.query(T[:, :3, 3]).margin

    if robot.has_analytic_ik:
        method = "analytic"
        sols = robot.ik_all(T)
        sols = [np.asarray(s, dtype=float).reshape(-1, robot.nq) for s in sols]
    else:
        method = "numerical"
        sols = _numerical_solutions(robot, T, n_seeds, seed, position_only=robot.nq < 6)

    checks = []
    for name, target, q, margin in zip(names, T, sols, margins):
        if q.shape[0]:
            J = robot.jacobian(q)[:, :3, :]
            w, c = position_dexterity(J)
            best = int(np.argmax(w))
            ratio = float(w[best] / median_w) if median_w > 0 else float("inf")
        else:
            w = c = np.zeros(0)
            best, ratio = -1, 0.0
        checks.append(PointCheck(name, target, q, w, c, best, ratio, float(margin)))
    return LayoutReport(robot.name, workspace.frame, method, tuple(checks), median_w)
