"""Workspaces of 10⁸–10⁹ samples: streamed reductions, flat memory, serial or on Dask.

:func:`stream_workspace` draws the same joint samples as :func:`~pinarms.robots.reach.workspace.sample_workspace`
(``robot.random_q(n, seed)``) but never holds them: the samples are cut into tasks of
``task_samples`` (10⁷ by default, about 10 s each), each task evaluates its samples in
blocks and returns only reductions, and the reductions are folded **in task order** into

- the bounding box, the mean and maximum position manipulability, the near-singular share;
- a voxel map (:class:`~pinarms.robots.reach.voxels.VoxelMap`): samples, mean and minimum manipulability
  per voxel on a grid anchored at the base origin (voxel ``i`` spans ``[i s, (i+1) s)``),
  the margin to the boundary as in the in-memory map;
- the radial profile around a centre fixed before the sweep (see below);
- the outer-hull sphere: the farthest sample of every direction cell around that centre,
  then the algebraic sphere through those hull points.

**Same samples, any scheduler.** Task ``k`` draws from the one stream of
``numpy.random.default_rng(seed)`` jumped ahead (``PCG64.advance``) to its first sample, so
the samples are those of ``robot.random_q(n, seed)`` whatever the task size, and the folds run
in task order: the result is identical bit for bit in a serial loop, on local processes or on
a Dask cluster (:func:`pinarms.execution.map_chunks`).

**Pilot.** The centre of the direction cells and of the radial shells, and the default voxel
edge, come from a *pilot*: the first ``min(n, 200 000)`` samples of the same stream, held in
memory (:meth:`~pinarms.robots.reach.workspace.Workspace.fit_sphere`, :func:`~pinarms.robots.reach.voxels.suggest_voxel_size`).
The final sphere is refitted to the hull of all ``n`` samples around the pilot's centre: the
last of the in-memory fit's iterations. The default voxel edge aims at 10 samples per voxel
but is never below :data:`MIN_DEFAULT_VOXEL` (memory of the grid: about 40 bytes per voxel of
the bounding box); pass ``voxel_size`` for a finer map.

Memory: the pilot, the grid, and per task one block of ``block`` samples: flat in ``n``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from pinarms.errors import InvalidInput
from pinarms.robots.reach.dexterity import positions_and_dexterity
from pinarms.robots.reach.joint_samples import generator_at
from pinarms.robots.reach.stream_reduction import Reduction, ReductionSpec, add_block, merge, sparse_voxels
from pinarms.robots.reach.voxels import VoxelMap, suggest_voxel_size
from pinarms.robots.reach.workspace import (
    SINGULAR_INVERSE_CONDITION,
    RadialProfile,
    SphereFit,
    WorkspaceSummary,
    check_singular_threshold,
    fit_sphere,
    sample_workspace,
)

if TYPE_CHECKING:  # pragma: no cover
    from distributed import Client

    from pinarms.robots.robot import Robot

__all__ = [
    "StreamedWorkspace",
    "StreamGrid",
    "stream_workspace",
    "TASK_SAMPLES",
    "PILOT_SAMPLES",
    "MIN_DEFAULT_VOXEL",
    "MAX_STREAM_SAMPLES",
    "MAX_STREAM_VOXELS",
]

#: Samples per task (a task evaluates them in blocks and returns reductions only). A task's
#: result holds its occupied voxels (24 bytes each, up to the whole grid): with 10⁷ samples a
#: task lasts about 10 s and ships at most a few tens of MB, small beside its work.
TASK_SAMPLES = 10_000_000
#: Samples of the in-memory pilot that fixes the shell centre and the default voxel edge.
PILOT_SAMPLES = 200_000
#: Smallest default voxel edge [m] (a finer grid must be asked for with ``voxel_size``).
MIN_DEFAULT_VOXEL = 0.01
#: Largest ``n`` accepted (10¹²).
MAX_STREAM_SAMPLES = 10**12
#: Most voxels of a streamed workspace's map (about 2.4 GB of counts, sums and minima).
MAX_STREAM_VOXELS = 10**8
_BLOCK = 262_144


# ------------------------------------------------------------------------ tasks
@dataclass(frozen=True)
class WorkspaceTask:
    """One task of a streamed workspace: samples ``start … start+count-1`` of the seeded stream."""

    robot: Any
    seed: int
    start: int
    count: int
    spec: ReductionSpec


def _run_task(task: WorkspaceTask) -> Reduction:
    """Evaluate one task's samples block by block; return its reduction (voxels shipped sparse)."""
    acc = Reduction()
    robot, spec = task.robot, task.spec
    from pinarms.execution import task_threads

    threads = task_threads()
    rng = generator_at(robot, task.seed, task.start)
    done = 0
    while done < task.count:
        m = min(spec.block, task.count - done)
        q = rng.uniform(robot.lower, robot.upper, size=(m, robot.nq))
        P, w, c = positions_and_dexterity(robot, q, spec.frame, threads=threads)
        add_block(acc, P, w, c, spec)
        done += m
    acc.vox_sparse = sparse_voxels(acc)
    acc.vox_lo = acc.vox_count = acc.vox_sum = acc.vox_min = None
    return acc


# ------------------------------------------------------------------------ result
@dataclass(frozen=True, eq=False)
class StreamedWorkspace:
    """Reductions of a streamed workspace (no per-sample arrays).

    Attributes:
        summary: bounding box, hull sphere, radial profile (around :attr:`centre`),
            near-singular share, manipulability mean and max (:class:`~pinarms.robots.reach.workspace.WorkspaceSummary`).
        voxels: occupancy and manipulability per voxel, margins (:class:`~pinarms.robots.reach.voxels.VoxelMap`).
        seed: the seed of the samples (``robot.random_q(n, seed)``).
        centre: ``(3,)`` centre of the direction cells and of the radial shells [m] (the pilot's hull centre).
        n_tasks: number of tasks the samples were cut into.
    """

    summary: WorkspaceSummary
    voxels: VoxelMap
    seed: int
    centre: np.ndarray
    n_tasks: int

    @property
    def n(self) -> int:
        """Number of samples."""
        return self.summary.n

    def text(self) -> str:
        """The summary's report plus the voxel map's size (mm)."""
        v = self.voxels
        return self.summary.text() + (
            f"\n  voxel map: {v.voxel_size * 1000:.0f} mm voxels, {int(np.count_nonzero(v.reachable))} reachable, "
            f"reachable volume {v.reachable_volume:.3f} m³"
        )


@dataclass(frozen=True)
class StreamGrid:
    """The grids a :func:`stream_workspace` sweep reduces onto, checked when made.

    Attributes:
        voxel_size: voxel edge [m]; ``None``: from the pilot (≥ :data:`MIN_DEFAULT_VOXEL`).
        width: radial shell width [m].
        singular_threshold: ``σ_min/σ_max`` of ``J_v`` below which a sample is near-singular.

    Raises:
        InvalidInput: a size that is not a positive length, a threshold out of (0, 1].
    """

    voxel_size: float | None = None
    width: float = 0.05
    singular_threshold: float = SINGULAR_INVERSE_CONDITION

    def __post_init__(self) -> None:
        w, v = self.width, self.voxel_size
        if not (isinstance(w, (int, float, np.integer, np.floating)) and np.isfinite(w) and w > 0):
            raise InvalidInput(f"shell width must be a positive length in m, got {w!r}")
        object.__setattr__(self, "singular_threshold", check_singular_threshold(self.singular_threshold))
        if v is not None and not (isinstance(v, (int, float, np.integer, np.floating)) and np.isfinite(v) and v > 0):
            raise InvalidInput(f"voxel_size must be a positive length in m, got {v!r}")


def stream_workspace(
    robot: "Robot",
    n: int,
    seed: int = 0,
    frame: str = "tcp",
    *,
    grid: StreamGrid | None = None,
    task_samples: int = TASK_SAMPLES,
    block: int = _BLOCK,
    scheduler: str | Client | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> StreamedWorkspace:
    """Workspace statistics of ``n`` samples in flat memory (see the module docstring).

    Args:
        robot: any :class:`~pinarms.robots.robot.Robot` with finite joint limits.
        n: number of samples (10⁸ take about 1.5 min on one core for a 6-axis arm).
        seed: a non-negative integer (the samples are ``robot.random_q(n, seed)``).
        frame: the frame whose origin is sampled.
        grid: voxel size, shell width and near-singular threshold (:class:`StreamGrid`;
            default ``StreamGrid()``).
        task_samples: samples per task (a task should last a second or more on a cluster).
        block: samples evaluated at once inside a task (bounds a task's memory).
        scheduler, progress: see :func:`pinarms.execution.map_chunks`.

    Raises:
        InvalidInput: a bad count, seed, size or frame.
        ExecutionError: a task failed or its worker died (chunk index and start sample named).
    """
    from pinarms.execution import reduce_chunks

    for name, v, least in (("n", n, 1), ("task_samples", task_samples, 1), ("block", block, 1)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < least:
            raise InvalidInput(f"{name} must be a positive integer, got {v!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInput(f"a streamed workspace needs an integer seed >= 0 (tasks re-create the stream), got {seed!r}")
    g = StreamGrid() if grid is None else grid
    if not isinstance(g, StreamGrid):
        raise InvalidInput(f"grid must be a robots.reach.workspace_stream.StreamGrid, got {type(g).__name__}")
    voxel_size, width, singular_threshold = g.voxel_size, g.width, g.singular_threshold
    n, seed = int(n), int(seed)
    if n > MAX_STREAM_SAMPLES:
        raise InvalidInput(f"n = {n:,} samples is more than {MAX_STREAM_SAMPLES:,} (about a week on 100 cores)")
    pilot = sample_workspace(robot, min(n, PILOT_SAMPLES), seed=seed, frame=frame)
    centre = pilot.fit_sphere().centre
    if voxel_size is None:
        per_pilot = 10.0 * pilot.n / n  # 10 samples per voxel at n samples
        voxel_size = max(suggest_voxel_size(pilot.points, samples_per_voxel=per_pilot), MIN_DEFAULT_VOXEL)
    extent = np.ptp(pilot.points, axis=0) * 1.5  # the pilot sees most of the box; the rest stays in the margin
    n_voxels = float(np.prod(np.floor(extent / float(voxel_size)) + 1.0))
    if n_voxels > MAX_STREAM_VOXELS:
        raise InvalidInput(f"voxel_size {float(voxel_size):g} m makes about {n_voxels:.3g} voxels over the workspace, "
                           f"more than {MAX_STREAM_VOXELS:.0e} (3 arrays of 8 bytes each): give a larger voxel_size")
    spec = ReductionSpec(
        frame=frame,
        voxel_size=float(voxel_size),
        centre=centre,
        width=float(width),
        n_dir_bins=int(np.clip(n // 30, 32, 2048)),
        singular_threshold=singular_threshold,
        block=int(block),
    )
    tasks, start = [], 0
    while start < n:
        count = min(int(task_samples), n - start)
        tasks.append(WorkspaceTask(robot, seed, start, count, spec))
        start += count
    acc = reduce_chunks(_run_task, tasks, _merge_into, Reduction(), scheduler=scheduler, progress=progress)
    return _finish(robot, frame, seed, n, spec, acc, len(tasks))


def _merge_into(acc: Reduction, part: Reduction) -> Reduction:
    merge(acc, part)
    return acc


def _finish(robot, frame, seed, n, spec: ReductionSpec, acc: Reduction, n_tasks: int) -> StreamedWorkspace:
    # voxel map on the global grid, cropped to the occupied block
    origin = acc.vox_lo * spec.voxel_size
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(acc.vox_count > 0, acc.vox_sum / acc.vox_count, np.nan)
    wmin = np.where(acc.vox_count > 0, acc.vox_min, np.nan)
    voxels = VoxelMap.from_counts(origin, spec.voxel_size, acc.vox_count, mean, wmin)
    # hull sphere through the farthest sample of each direction cell
    hull = acc.hull_point[acc.hull_count > 0]
    fit = fit_sphere(hull)
    coverage = float(np.count_nonzero(acc.hull_count) / acc.hull_count.size)
    sphere = SphereFit(fit.centre, fit.radius, fit.rms_residual, fit.max_residual, fit.n_points, "outer-hull", coverage)
    # radial profile
    k = acc.shell_count.size
    edges = np.arange(k + 1) * spec.width
    vol = 4.0 / 3.0 * np.pi * (edges[1:] ** 3 - edges[:-1] ** 3)
    counts = acc.shell_count
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_w = np.where(counts > 0, acc.shell_sum_w / counts, np.nan)
        sing = np.where(counts > 0, acc.shell_singular / counts, np.nan)
    profile = RadialProfile("centre", spec.centre.copy(), edges, counts, counts / vol, mean_w, sing)
    summary = WorkspaceSummary(
        robot=robot.name,
        frame=frame,
        n=n,
        bbox_min=acc.bbox_min,
        bbox_max=acc.bbox_max,
        sphere=sphere,
        profile=profile,
        singular_threshold=spec.singular_threshold,
        singular_share=acc.n_singular / n,
        manipulability_mean=acc.sum_w / n,
        manipulability_max=acc.max_w,
    )
    return StreamedWorkspace(summary=summary, voxels=voxels, seed=seed, centre=spec.centre.copy(), n_tasks=n_tasks)
