"""Monte Carlo workspace of an arm: sampled reachable points with their dexterity.

:func:`sample_workspace` draws joint vectors uniformly within the position limits,
evaluates the frame's position and the *linear* (position) rows ``J_v`` of its Jacobian
in batches, and keeps, per sample:

- ``points (n, 3)`` [m]: origin of the frame in the base frame,
- ``manipulability (n,)``: Yoshikawa's measure of the position Jacobian,
  ``w = sqrt(det(J_v J_vᵀ))`` (``sqrt(det(J_vᵀ J_v))`` for arms with fewer than three
  joints), i.e. ``Robot.manipulability(q, part="position")``. Only linear rows are used,
  so no metres are mixed with radians; the unit is m³/s per (unit joint rate)³, in
  practice m³ for revolute arms and dimensionless for a Cartesian gantry,
- ``inverse_condition (n,)``: ``σ_min / σ_max`` of ``J_v`` (0 = singular, 1 = isotropic),
  unit-free.

A sample is *near-singular* when its inverse condition is below
:data:`SINGULAR_INVERSE_CONDITION` (``κ(J_v) > 10``).

:meth:`Workspace.summary` gives the bounding box, the best-fit sphere of the outer hull
(:func:`fit_sphere_to_hull`), the radial density profile and the near-singular share.
The dexterity measures are computed by :mod:`pinarms.robots.reach.dexterity` (``position_dexterity`` is
re-exported here). Where the tables should stand is :func:`pinarms.robots.reach.table_band.recommend_region` (the module above
this one: table_band imports workspace, never the other way).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput
from pinarms.robots.robot import MAX_RANDOM_SAMPLES
from pinarms.robots.reach.dexterity import CHUNK, position_dexterity, positions_and_dexterity
from pinarms.robots.reach.joint_samples import random_q_slice
from pinarms.robots.reach.sphere_fit import (  # noqa: F401  (the sphere fits: their own module, re-exported here)
    SPHERE_COVERAGE_MIN, SphereFit, as_points, direction_cells, direction_coverage,
    fit_sphere, fit_sphere_to_hull, hull_points)
from pinarms.robots.reach.voxels import VoxelMap, suggest_voxel_size

if TYPE_CHECKING:  # pragma: no cover
    from distributed import Client

    from pinarms.robots.robot import Robot

__all__ = [
    "SINGULAR_INVERSE_CONDITION",
    "as_point",
    "check_singular_threshold",
    "SPHERE_COVERAGE_MIN",
    "Workspace",
    "WorkspaceSummary",
    "SphereFit",
    "RadialProfile",
    "sample_workspace",
    "random_q_slice",
    "TASK_SAMPLES",
    "fit_sphere",
    "fit_sphere_to_hull",
    "position_dexterity",
]

SINGULAR_INVERSE_CONDITION = 0.1
"""Samples whose ``σ_min/σ_max`` of the position Jacobian is below this are near-singular."""

#: Samples per task when a sweep is cut into tasks (:mod:`pinarms.execution`); about 2 s each.
TASK_SAMPLES = 2_000_000


# ------------------------------------------------------------- radial profile
@dataclass(frozen=True)
class RadialProfile:
    """Samples per radial shell, with their dexterity.

    Attributes:
        about: ``"centre"`` (spherical shells around ``origin``) or ``"axis"`` (cylindrical
            shells around the vertical line through ``origin``; radius = horizontal distance).
        origin: ``(3,)`` [m].
        edges: ``(k+1,)`` shell radii [m].
        counts: ``(k,)`` samples per shell.
        density: ``(k,)`` samples per m³ of shell volume (axis: the shell's ring area times
            the height of the samples' bounding box).
        mean_manipulability: ``(k,)`` (NaN for empty shells).
        singular_share: ``(k,)`` share of near-singular samples (NaN for empty shells).
    """

    about: str
    origin: np.ndarray
    edges: np.ndarray
    counts: np.ndarray
    density: np.ndarray
    mean_manipulability: np.ndarray
    singular_share: np.ndarray

    @property
    def centres(self) -> np.ndarray:
        """Mid radius of each shell [m]."""
        return 0.5 * (self.edges[:-1] + self.edges[1:])


def radial_distance(points: np.ndarray, origin: np.ndarray, about: str) -> np.ndarray:
    """Distance of ``points`` to ``origin`` (``about="centre"``) or to the vertical axis through it."""
    d = np.asarray(points, dtype=float) - origin
    if about == "centre":
        return np.sqrt(np.einsum("ij,ij->i", d, d))
    if about == "axis":
        return np.hypot(d[:, 0], d[:, 1])
    raise InvalidInput(f"about must be 'centre' or 'axis', got {about!r}")


# ------------------------------------------------------------------ summary
@dataclass(frozen=True)
class WorkspaceSummary:
    """Shape and dexterity of a sampled workspace (SI units; see :meth:`text`)."""

    robot: str
    frame: str
    n: int
    bbox_min: np.ndarray
    bbox_max: np.ndarray
    sphere: SphereFit
    profile: RadialProfile
    singular_threshold: float
    singular_share: float
    manipulability_mean: float
    manipulability_max: float

    def text(self) -> str:
        """A readable report (lengths in mm)."""
        mm = 1000.0
        s = self.sphere
        lines = [
            f"workspace of {self.robot} ({self.frame}), {self.n} samples",
            "  bounding box [mm]: x {:.0f}..{:.0f}, y {:.0f}..{:.0f}, z {:.0f}..{:.0f}".format(
                *(v * mm for pair in zip(self.bbox_min, self.bbox_max) for v in pair)
            ),
            "  outer-hull sphere: centre ({:.0f}, {:.0f}, {:.0f}) mm, radius {:.0f} mm, "
            "rms residual {:.1f} mm ({:.1%} of r) over {} hull points, direction coverage {:.0%}{}".format(
                *(s.centre * mm), s.radius * mm, s.rms_residual * mm, s.relative_rms, s.n_points, s.coverage,
                "" if s.meaningful else " (the samples cover only a patch of this sphere: it does not describe them)",
            ),
            f"  near-singular (σmin/σmax of J_v < {self.singular_threshold:g}): {self.singular_share:.1%}",
            f"  position manipulability: mean {self.manipulability_mean:.4g}, max {self.manipulability_max:.4g}",
            "  radial profile around the sphere centre (shell [mm]: samples, share near-singular):",
        ]
        p = self.profile
        for lo, hi, n, sing in zip(p.edges[:-1], p.edges[1:], p.counts, p.singular_share):
            if n:
                lines.append(f"    {lo * mm:5.0f}-{hi * mm:5.0f}: {n:8d}  {sing:6.1%}")
        return "\n".join(lines)


# ---------------------------------------------------------------- workspace
@dataclass(frozen=True, eq=False)
class Workspace:
    """Sampled workspace of ``robot`` (arrays are read-only).

    Attributes:
        robot: the sampled :class:`~pinarms.robots.robot.Robot`.
        frame: the frame whose origin was sampled.
        seed: the seed of the joint samples (``None`` when a Generator was given).
        q: ``(n, nq)`` joint samples [rad or m].
        points: ``(n, 3)`` frame origins in the base frame [m].
        manipulability: ``(n,)`` Yoshikawa measure of the position Jacobian ``J_v``.
        inverse_condition: ``(n,)`` ``σ_min/σ_max`` of ``J_v``.
    """

    robot: "Robot" = field(repr=False)
    frame: str
    seed: int | None
    q: np.ndarray = field(repr=False)
    points: np.ndarray = field(repr=False)
    manipulability: np.ndarray = field(repr=False)
    inverse_condition: np.ndarray = field(repr=False)

    def __post_init__(self) -> None:
        for name in ("q", "points", "manipulability", "inverse_condition"):
            getattr(self, name).flags.writeable = False

    def __len__(self) -> int:
        return self.points.shape[0]

    @property
    def n(self) -> int:
        """Number of samples."""
        return self.points.shape[0]

    def near_singular(self, threshold: float = SINGULAR_INVERSE_CONDITION) -> np.ndarray:
        """``(n,)`` bool: samples whose ``σ_min/σ_max`` of ``J_v`` is below ``threshold`` (in (0, 1])."""
        return self.inverse_condition < check_singular_threshold(threshold)

    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        """``(min (3,), max (3,))`` of the sampled points [m]."""
        return self.points.min(axis=0), self.points.max(axis=0)

    def fit_sphere(self, n_bins: int | None = None) -> SphereFit:
        """Sphere fitted to the outer hull of the points (:func:`fit_sphere_to_hull`)."""
        return fit_sphere_to_hull(self.points, n_bins)

    def radial_profile(
        self,
        origin: ArrayLike | None = None,
        *,
        about: str = "centre",
        width: float = 0.025,
        mask: np.ndarray | None = None,
        singular_threshold: float = SINGULAR_INVERSE_CONDITION,
    ) -> RadialProfile:
        """Samples per shell of ``width`` [m] around ``origin`` (default: the hull sphere's centre).

        Args:
            about: ``"centre"`` for spherical shells, ``"axis"`` for cylindrical shells
                around the vertical axis through ``origin``.
            mask: ``(n,)`` bool, only these samples are counted (e.g. ``points[:, 2] > 0``).
        """
        if not (isinstance(width, (int, float, np.integer, np.floating)) and np.isfinite(width) and width > 0):
            raise InvalidInput(f"shell width must be a positive length in m, got {width!r}")
        singular_threshold = check_singular_threshold(singular_threshold)
        origin = self.fit_sphere().centre if origin is None else as_point(origin, "origin")
        P, w, c = self.points, self.manipulability, self.inverse_condition
        if mask is not None:
            mask = np.asarray(mask, dtype=bool)
            if mask.shape != (self.n,):
                raise InvalidInput(f"mask must have shape ({self.n},), got {mask.shape}")
            P, w, c = P[mask], w[mask], c[mask]
        r = radial_distance(P, origin, about)
        k = max(1, int(np.ceil((r.max() if r.size else width) / width)))
        edges = np.arange(k + 1) * width
        idx = np.minimum((r / width).astype(int), k - 1)
        counts = np.bincount(idx, minlength=k)
        sum_w = np.bincount(idx, weights=w, minlength=k)
        n_sing = np.bincount(idx, weights=(c < singular_threshold).astype(float), minlength=k)
        if about == "centre":
            vol = 4.0 / 3.0 * np.pi * (edges[1:] ** 3 - edges[:-1] ** 3)
        else:
            height = float(np.ptp(P[:, 2])) if P.shape[0] else 0.0
            vol = np.pi * (edges[1:] ** 2 - edges[:-1] ** 2) * max(height, width)
        with np.errstate(invalid="ignore", divide="ignore"):
            mean_w = np.where(counts > 0, sum_w / counts, np.nan)
            sing = np.where(counts > 0, n_sing / counts, np.nan)
        return RadialProfile(about, np.asarray(origin, float), edges, counts, counts / vol, mean_w, sing)

    def summary(self, *, width: float = 0.05, singular_threshold: float = SINGULAR_INVERSE_CONDITION) -> WorkspaceSummary:
        """Bounding box, outer-hull sphere, radial profile (shells of ``width`` m) and singular share."""
        singular_threshold = check_singular_threshold(singular_threshold)
        lo, hi = self.bounding_box()
        sphere = self.fit_sphere()
        profile = self.radial_profile(sphere.centre, width=width, singular_threshold=singular_threshold)
        return WorkspaceSummary(
            robot=self.robot.name,
            frame=self.frame,
            n=self.n,
            bbox_min=lo,
            bbox_max=hi,
            sphere=sphere,
            profile=profile,
            singular_threshold=singular_threshold,
            singular_share=float(np.mean(self.inverse_condition < singular_threshold)),
            manipulability_mean=float(np.mean(self.manipulability)),
            manipulability_max=float(np.max(self.manipulability)),
        )

    def voxel_map(self, voxel_size: float | None = None, *, min_count: int = 1) -> "VoxelMap":
        """Voxel reachability map of the samples (see :class:`pinarms.robots.reach.voxels.VoxelMap`).

        ``voxel_size`` [m]; default: :func:`pinarms.robots.reach.voxels.suggest_voxel_size` (about 10
        samples per reachable voxel, so that chance holes do not fake a boundary).
        """
        if voxel_size is None:
            voxel_size = suggest_voxel_size(self.points)
        return VoxelMap.from_samples(self.points, self.manipulability, voxel_size, min_count=min_count)


def sample_workspace(
    robot: "Robot",
    n: int = 100_000,
    seed: int | np.random.Generator | None = 0,
    frame: str = "tcp",
    chunk: int = CHUNK,
    *,
    scheduler: str | Client | None = None,
    progress: Callable[[int, int], None] | None = None,
    task_samples: int = TASK_SAMPLES,
) -> Workspace:
    """Monte Carlo workspace: ``n`` joint vectors uniform within the limits, and their frame origins.

    Args:
        robot: any :class:`~pinarms.robots.robot.Robot`.
        n: number of samples (> 0, at most ``MAX_RANDOM_SAMPLES`` = 5·10⁷ in one call). 10⁶ samples
            take about 100 MB; for 10⁸ and more use
            :func:`pinarms.robots.reach.workspace_stream.stream_workspace` (reductions only, flat memory).
        seed: seed or ``numpy.random.Generator``; the same seed gives the same samples
            (``q`` equals ``robot.random_q(n, seed)``).
        frame: frame whose origin is sampled (``"tcp"`` = the robot's tool frame).
        chunk: samples evaluated per block (bounds the working memory).
        scheduler, progress: with an integer ``seed``, more than ``task_samples`` samples
            (or any ``scheduler``) are cut into tasks of ``task_samples`` run by
            :func:`pinarms.execution.map_chunks` (serial by default, or on Dask). Task ``k``
            draws its slice of the same stream (:func:`random_q_slice`), so the result is
            identical to the one-piece run bit for bit, whoever runs the tasks.
            ``progress(done, total)`` counts tasks then, samples (per chunk) for a one-piece
            run; e.g. a :class:`pinarms.progress.ProgressBar`.

    Raises:
        InvalidInput: ``n`` is not a positive integer or is above 5·10⁷, ``chunk`` is not positive, or
            ``frame`` is not a frame of the robot; a ``scheduler`` with a Generator seed.
        ExecutionError: a task failed (its chunk index is named).
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n <= 0:
        raise InvalidInput(f"number of samples n must be a positive integer, got {n!r}")
    if n > MAX_RANDOM_SAMPLES:
        raise InvalidInput(f"n = {n:,} samples is more than {MAX_RANDOM_SAMPLES:,} at once (10⁶ samples take "
                           f"about 100 MB); for more, robots.stream_workspace keeps only the reductions (voxel map, "
                           "profile, hull sphere) in flat memory")
    if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk <= 0:
        raise InvalidInput(f"chunk must be a positive integer, got {chunk!r}")
    if isinstance(task_samples, bool) or not isinstance(task_samples, (int, np.integer)) or task_samples <= 0:
        raise InvalidInput(f"task_samples must be a positive integer, got {task_samples!r}")
    robot.frame_id(frame)  # raises InvalidInput naming the frames
    if not (np.all(np.isfinite(robot.lower)) and np.all(np.isfinite(robot.upper))):
        raise InvalidInput(f"robot '{robot.name}' has unbounded joint limits; sampling needs finite limits")
    integer_seed = isinstance(seed, (int, np.integer)) and not isinstance(seed, bool)
    if scheduler is not None and not integer_seed:
        raise InvalidInput(f"sampling on a scheduler needs an integer seed >= 0 (each task re-creates its stream), got {seed!r}")
    if integer_seed and (n > task_samples or scheduler is not None):
        q, points, w, c = _sample_in_tasks(robot, int(n), int(seed), frame, int(chunk), int(task_samples), scheduler, progress)
    else:
        q = robot.random_q(int(n), seed=seed)
        points, w, c = positions_and_dexterity(robot, q, frame, int(chunk), progress)
    return Workspace(
        robot=robot,
        frame=frame,
        seed=seed if isinstance(seed, (int, np.integer)) else None,
        q=q,
        points=points,
        manipulability=w,
        inverse_condition=c,
    )


@dataclass(frozen=True)
class _SampleTask:
    robot: Any
    seed: int
    start: int
    count: int
    frame: str
    chunk: int


def _sample_task(task: _SampleTask) -> tuple:
    from pinarms.execution import task_threads

    q = random_q_slice(task.robot, task.seed, task.start, task.count)
    return (q, *positions_and_dexterity(task.robot, q, task.frame, task.chunk, threads=task_threads()))


def _sample_in_tasks(robot, n, seed, frame, chunk, task_samples, scheduler, progress) -> tuple:
    from pinarms.execution import reduce_chunks

    tasks, start = [], 0
    while start < n:
        count = min(task_samples, n - start)
        tasks.append(_SampleTask(robot, seed, start, count, frame, chunk))
        start += count
    out = (np.empty((n, robot.nq)), np.empty((n, 3)), np.empty(n), np.empty(n))
    starts = iter(t.start for t in tasks)

    def place(acc, part):
        s = next(starts)
        for dst, src in zip(acc, part):
            dst[s : s + src.shape[0]] = src
        return acc

    return reduce_chunks(_sample_task, tasks, place, out, scheduler=scheduler, progress=progress)


# ------------------------------------------------------------------ helpers
def check_singular_threshold(threshold: float) -> float:
    """``singular_threshold``: a ``σ_min/σ_max`` bound in (0, 1]."""
    ok = isinstance(threshold, (int, float, np.integer, np.floating)) and not isinstance(threshold, bool)
    if not (ok and 0.0 < float(threshold) <= 1.0):
        raise InvalidInput(
            f"singular_threshold must be an inverse condition number σ_min/σ_max in (0, 1], got {threshold!r}"
        )
    return float(threshold)


def as_point(point: ArrayLike, what: str) -> np.ndarray:
    """``point`` as one (3,) float array [m]; ``what`` names it in the error.

    Raises:
        InvalidInput: not one point of three numbers.
    """
    if np.shape(point) not in ((3,), (1, 3)):
        raise InvalidInput(f"{what} must be one point (3,) [m], got shape {np.shape(point)}")
    P = as_points(point, what)
    if P.shape[0] != 1:
        raise InvalidInput(f"{what} must be one point (3,) [m], got shape {np.shape(point)}")
    return P[0]
