"""Reachability maps: which tool poses an arm reaches, voxel by voxel, with which orientations.

:func:`reachability_map` answers, for every voxel centre ``p`` of a grid of edge
``resolution`` [m] and every rotation ``R_k`` of an :class:`~pinarms.robots.reach.orientations.OrientationSet`,
whether the tool pose ``(R_k, p)`` (tool frame → base) has an inverse-kinematics solution
within the joint limits, and how dexterous the best one is (the capability / reachability map
of Zacharias et al., 2007; ROS-Industrial's reuleaux builds the same kind of map).

Method
------
1. **Grid.** A guaranteed bound of the tool's reach: a sphere around the first joint's origin
   whose radius is the sum of the chain's link offsets (the joint placements after the first,
   the tool frame's offset) plus the strokes of prismatic joints (:func:`reach_bound`). The grid
   is the sphere's bounding box, aligned so that voxel centres lie at ``(i + ½)·resolution``.
2. **Voxels computed.** Seeded joint-space samples mark the voxels the tool can enter; those
   and their 6 face neighbours inside the sphere are computed first. Then every face neighbour
   of a voxel with a non-zero index that was not computed yet is computed, round after round,
   until none is left (a closure: the map cannot stop at a sampling hole; a reachable region
   joined to the rest only by voxel edges or corners, never by a face, would be missed). Voxels never computed
   have index 0; ``ReachabilityMap.open_faces`` counts computed reachable voxels on the grid
   boundary (0 by construction of the bound).
3. **Poses.** For each voxel of a chunk, the ``M`` poses ``(R_k, p)``: closed-form arms
   (``Robot.has_analytic_ik``) get *every* branch within the joint limits at once (batched,
   each solution checked by forward kinematics within 1e-9 m / 1e-9 rad); any other URDF gets
   the numerical solver (damped least squares, joint limits, ``restarts`` seeded random
   restarts after a warm start from the same orientation's solution in a face-neighbour voxel
   already solved in the chunk, or the previous roll of the same direction). Optional collision checks
   (``self_collision=True`` and/or ``collision=`` any object with ``in_collision(q (N, nq)) ->
   (N,) bool``, e.g. a cell's fixtures) drop solutions.
4. **Scores.** Per pose: reached or not, the stored solution (the one with the largest
   manipulability; solutions within 1e-9 relative of the largest count as tied and the first
   in the solver's order, nearest the neutral configuration, wins) and its manipulability
   ``w = |det J|`` (``sqrt(det(J Jᵀ))`` for redundant arms, ``sqrt(det(Jᵀ J))`` for arms with
   fewer than 6 joints; ``manipulability="position"`` uses the 3 linear rows). Per voxel:
   the **reachability index** (fraction of the set's directions reached; for a roll-free set a
   direction counts when any of its rolls is), which poses are reached, the best
   manipulability.

Execution
---------
Voxels are cut into chunks of ``chunk_voxels`` (a fixed number: the map never depends on who
runs it); each chunk is a task of the picklable top-level function :func:`solve_chunk`, run
serially by default or on a Dask cluster (``scheduler=``, see :mod:`pinarms.execution`).
Workers rebuild the robot from its registry name or URDF text (checked by its SHA-256).
A map built serially equals the one built on a cluster bit for bit.

Steps 1–2 live in :mod:`pinarms.robots.reach.reach_grid`, steps 3–4 (one chunk) in
:mod:`pinarms.robots.reach.reach_chunk`, the robot a worker rebuilds in :mod:`pinarms.robots.reach.robot_spec`,
the map itself in :mod:`pinarms.robots.reach.reach_map`; this module checks the arguments and runs the
rounds.

Units: metres, radians; rotations tool frame → base; joint values in the robot's ``q`` order.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

import numpy as np
from numpy.typing import ArrayLike

from pinarms.robots._checks import check_restarts
from pinarms.errors import InvalidInput, ModelError
from pinarms.robots.reach.orientations import OrientationSet, so3_orientations, tool_down_orientations
from pinarms.robots.reach.reach_chunk import TIE_RTOL, ChunkTask, solve_chunk
from pinarms.robots.reach.reach_grid import ReachGrid, bounding_grid, face_neighbours, reach_bound, seed_voxels
from pinarms.robots.reach.reach_map import MAX_GRID_VOXELS, PoseSolutions, ReachabilityMap
from pinarms.robots.reach.robot_spec import RobotSpec, spec_of

#: Most joint samples :func:`reachability_map` draws to mark its first voxels (``samples=``).
MAX_SEED_SAMPLES = 50_000_000

if TYPE_CHECKING:  # pragma: no cover
    import os

    from distributed import Client

    from pinarms.robots.robot import Robot

__all__ = [
    "ReachabilityMap",
    "PoseSolutions",
    "reachability_map",
    "ReachabilityRequest",
    "reach_bound",
    "solve_chunk",
    "MAX_GRID_VOXELS",
    "TIE_RTOL",
]

_POSES_PER_CHUNK = {"analytic": 100_000, "numerical": 10_000}


# ----------------------------------------------------------------------------- building
@dataclass(frozen=True, eq=False)
class ReachabilityRequest:
    """What :func:`reachability_map` computes: the map of ``arm``'s tool frame (see the module doc).

    Attributes:
        arm: any :class:`~pinarms.robots.robot.Robot`.
        resolution: voxel edge [m].
        orientations: poses per voxel spread over SO(3) (super-Fibonacci), or with ``tool_down``
            the number of tool-axis directions in the cone; or any
            :class:`~pinarms.robots.reach.orientations.OrientationSet`.
        tool_down: cone half-angle [rad] around straight down for the tool axis; roll free
            (``roll_steps`` rolls tried, any counts).
        tool_axis: the tool-frame axis pointed down (default: the tool's +z, or −z for tools
            whose z never points down: see :func:`_default_tool_axis`).
        ik: ``"auto"`` (closed form when the arm has one), ``"analytic"`` or ``"numerical"``.
        manipulability: ``"full"`` (6 rows of the Jacobian) or ``"position"`` (3 linear rows).
        restarts, tol: numerical IK: seeded random restarts after the warm start, and the
            position [m] / rotation [rad] tolerance (closed forms are checked within 1e-9).
        self_collision: drop solutions where the arm hits itself (URDF collision geometry).
        collision: an object with ``in_collision(q (N, nq)) -> (N,) bool`` (e.g. a cell's
            fixtures); picklable when a cluster runs the map.
        keep_solutions: keep the stored solution of every reached pose (``K·(nq+2)`` numbers).
        out: an HDF5 file to write the map to, the stored solutions streamed into it chunk by
            chunk (then the returned map holds no solutions: memory stays flat in the number of
            voxels but for the per-voxel arrays; read them back with
            :func:`pinarms.robots.reach.reach_io.load_reachability`). Written to a temporary file and renamed
            when complete.
        chunk_voxels: voxels per task (default: about 10⁵ poses for closed forms, 10⁴ for
            the numerical solver). The map depends on it only through the numerical warm starts.
        samples: joint samples marking the first voxels (default: 2 per voxel of the bound
            sphere, between 2·10⁵ and 5·10⁶).
        seed: seed of the samples and of the numerical restarts.

    Raises:
        InvalidInput: a bad argument (resolution not positive, an unknown ``ik`` or
            ``manipulability``, a grid of more than :data:`MAX_GRID_VOXELS` voxels, ...).
        ModelError: ``ik="analytic"`` for an arm without a closed form.
    """

    arm: "Robot"
    resolution: float = 0.025
    orientations: int | OrientationSet = 50
    tool_down: float | None = None
    roll_steps: int = 8
    tool_axis: ArrayLike | None = None
    ik: str = "auto"
    manipulability: str = "full"
    restarts: int = 2
    tol: float = 1e-9
    self_collision: bool = False
    collision: Any = None
    keep_solutions: bool = True
    out: "str | os.PathLike | None" = None
    chunk_voxels: int | None = None
    samples: int | None = None
    seed: int = 0

    #: the fields checked, the defaults resolved and the grid around the arm's reach built (by ``__post_init__``)
    settings: _Settings = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "settings", _checked_settings(
            self.arm, resolution=self.resolution, orientations=self.orientations, tool_down=self.tool_down,
            roll_steps=self.roll_steps, tool_axis=self.tool_axis, ik=self.ik, manipulability=self.manipulability,
            restarts=self.restarts, tol=self.tol, self_collision=self.self_collision, collision=self.collision,
            keep_solutions=self.keep_solutions, streamed=self.out is not None, chunk_voxels=self.chunk_voxels,
            samples=self.samples, seed=self.seed))


def reachability_map(request: ReachabilityRequest, *, scheduler: "str | Client | None" = None,
                     progress: Callable[[int, int], None] | None = None) -> ReachabilityMap:
    """Build the reachability map ``request`` asks for (a :class:`ReachabilityRequest`; module doc).

    Args:
        scheduler: ``None`` (serial, here), ``"processes[:N]"``, ``"tcp://HOST:8786"``, ``"env"`` or a
            ``distributed.Client`` (see :mod:`pinarms.execution`).
        progress: ``progress(voxels_done, voxels_to_do)`` after each chunk (the second number
            grows when a closure round adds voxels).
    """
    t0 = time.perf_counter()
    arm, out = request.arm, request.out
    s = request.settings
    spec = spec_of(arm)
    writer = None
    if out is not None:
        from pinarms.robots.reach.reach_write import StreamWriter

        writer = StreamWriter(out, arm.nq)
    acc = _Accumulator(s.keep, writer)
    try:
        start = face_neighbours(seed_voxels(arm, s.grid, s.samples, s.seed), s.grid)
        rounds = _compute_in_rounds(start, s.grid, s.task_fields(spec), s.chunk_voxels, acc, scheduler, progress)
        m = _assemble(arm, spec, s, acc, s.parameters(rounds), time.perf_counter() - t0, scheduler)
        if writer is not None:
            writer.finish(m)
            writer = None
        return m
    finally:
        if writer is not None:
            writer.abort()


@dataclass(frozen=True, eq=False)
class _Settings:
    """The checked options of :func:`reachability_map` (its arguments, with the defaults resolved)."""

    resolution: float
    solver: str
    manipulability: str
    restarts: int
    tol: float
    self_collision: bool
    collision: Any
    keep: bool
    orientations: OrientationSet
    chunk_voxels: int
    grid: ReachGrid
    samples: int
    seed: int

    def task_fields(self, spec: RobotSpec) -> dict:
        """The :class:`ChunkTask` fields shared by every chunk (all but ``voxels``)."""
        oset, grid = self.orientations, self.grid
        return dict(robot=spec, origin=grid.origin, resolution=self.resolution, shape=grid.shape,
                    rotations=oset.rotations, group=oset.group, n_groups=oset.n_groups, roll_free=oset.roll_free,
                    solver=self.solver, manipulability=self.manipulability, restarts=self.restarts, tol=self.tol,
                    self_collision=self.self_collision, collision=self.collision, keep_solutions=self.keep,
                    seed=self.seed)

    def parameters(self, rounds: int) -> dict:
        """How the map was made (:attr:`ReachabilityMap.parameters`, before the statistics)."""
        collision = None if self.collision is None else type(self.collision).__name__
        return dict(seed=self.seed, chunk_voxels=self.chunk_voxels, restarts=self.restarts, tol=self.tol,
                    self_collision=self.self_collision, collision=collision, samples=self.samples, rounds=rounds,
                    bound_centre=self.grid.centre.tolist(), bound_radius=self.grid.radius, keep_solutions=self.keep)


def _checked_settings(arm: "Robot", *, resolution: Any, orientations: Any, tool_down: Any, roll_steps: Any,
                      tool_axis: Any, ik: Any, manipulability: Any, restarts: Any, tol: Any, self_collision: Any,
                      collision: Any, keep_solutions: Any, streamed: bool, chunk_voxels: Any, samples: Any,
                      seed: Any) -> _Settings:
    """The options of :func:`reachability_map` checked in argument order, the grid around the arm's reach built.

    Raises:
        InvalidInput, ModelError: as :func:`reachability_map`.
    """
    resolution = _positive(resolution, "resolution [m]")
    solver = _solver(arm, ik, manipulability)
    restarts = check_restarts(restarts, "restarts")
    tol = _positive(tol, "tol [m, rad]")
    seed = _count(seed, "seed")
    if collision is not None and not callable(getattr(collision, "in_collision", None)):
        raise InvalidInput("collision must have a method in_collision(q (N, nq)) -> (N,) bool")
    oset = _orientation_set(orientations, tool_down, roll_steps, tool_axis, arm)
    if chunk_voxels is None:
        chunk_voxels = max(1, _POSES_PER_CHUNK[solver] // oset.size)
    chunk_voxels = _count(chunk_voxels, "chunk_voxels", 1)
    if not (np.all(np.isfinite(arm.lower)) and np.all(np.isfinite(arm.upper))):
        raise InvalidInput(f"robot '{arm.name}' has unbounded joint limits; a map needs finite limits")
    grid = bounding_grid(arm, resolution)
    if samples is None:
        samples = int(np.clip(2 * int(grid.inside.sum()), 200_000, 5_000_000))
    samples = _count(samples, "samples", 1)
    if samples > MAX_SEED_SAMPLES:  # each sample is a joint vector: refused before any is drawn
        raise InvalidInput(f"samples = {samples:,} is more than the {MAX_SEED_SAMPLES:,} allowed (the default is "
                           f"2 per voxel, 200 000 to 5 000 000): give fewer")
    return _Settings(resolution=resolution, solver=solver, manipulability=manipulability, restarts=restarts, tol=tol,
                     self_collision=bool(self_collision), collision=collision,
                     keep=bool(keep_solutions) or streamed, orientations=oset, chunk_voxels=chunk_voxels, grid=grid,
                     samples=samples, seed=seed)


def _solver(arm: "Robot", ik: str, manipulability: str) -> str:
    """``"analytic"`` or ``"numerical"``: the solver the map uses for ``ik`` (checked with ``manipulability``)."""
    if ik not in ("auto", "analytic", "numerical"):
        raise InvalidInput(f"ik must be 'auto', 'analytic' or 'numerical', got {ik!r}")
    if manipulability not in ("full", "position"):
        raise InvalidInput(f"manipulability must be 'full' or 'position', got {manipulability!r}")
    if ik == "analytic" and not arm.has_analytic_ik:
        raise ModelError(f"robot '{arm.name}' has no closed-form IK; use ik='numerical' (or 'auto')")
    return "analytic" if (ik != "numerical" and arm.has_analytic_ik) else "numerical"


def _compute_in_rounds(todo: np.ndarray, grid: ReachGrid, task: dict, chunk_voxels: int, acc: "_Accumulator",
                       scheduler: Any, progress: Callable | None) -> int:
    """Compute the voxels ``todo``, then every face neighbour of a reachable voxel not computed yet,
    round after round until none is left (step 2 of the module doc); return the number of rounds.

    ``task`` holds the :class:`ChunkTask` fields but ``voxels``; each round's voxels are cut into
    chunks of ``chunk_voxels`` folded into ``acc``.
    """
    computed = np.zeros(grid.inside.size, dtype=bool)
    done_voxels, total_voxels, rounds = 0, int(todo.size), 0
    while todo.size:
        rounds += 1
        computed[todo] = True
        chunks = [todo[s : s + chunk_voxels] for s in range(0, todo.size, chunk_voxels)]
        tasks = [ChunkTask(voxels=c, **task) for c in chunks]
        ends = np.cumsum([c.size for c in chunks])

        def report(done: int, total: int, _offset=done_voxels, _ends=ends) -> None:
            progress(_offset + (int(_ends[done - 1]) if done else 0), total_voxels)

        acc.round_reachable = []
        _fold_round(tasks, acc, scheduler, report if progress is not None else None)
        done_voxels += int(todo.size)
        reachable = np.concatenate(acc.round_reachable) if acc.round_reachable else np.zeros(0, np.int64)
        frontier = face_neighbours(reachable, grid) if reachable.size else np.zeros(0, np.int64)
        todo = frontier[~computed[frontier]]
        total_voxels += int(todo.size)
    return rounds


def _positive(value: Any, what: str) -> float:
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    v = float(value) if ok else float("nan")
    if not (np.isfinite(v) and v > 0):
        raise InvalidInput(f"{what} must be a positive finite number, got {value!r}")
    return v


def _count(value: Any, what: str, low: int = 0) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise InvalidInput(f"{what} must be an integer >= {low}, got {value!r}")
    return int(value)



def _orientation_set(orientations: Any, tool_down: Any, roll_steps: int, tool_axis: Any, robot: "Robot") -> OrientationSet:
    if isinstance(orientations, OrientationSet):
        if tool_down is not None:
            raise InvalidInput("give either an OrientationSet or tool_down=..., not both")
        return orientations
    n = _count(orientations, "orientations (poses per voxel, or tool-axis directions with tool_down)", 1)
    if tool_down is None:
        return so3_orientations(n)
    cone = _positive(tool_down, "tool_down cone half-angle [rad]")
    if cone > np.pi / 2:
        raise InvalidInput(f"tool_down cone half-angle must be at most π/2 rad (90°), got {tool_down!r} rad")
    axis = _default_tool_axis(robot, cone) if tool_axis is None else tool_axis
    return tool_down_orientations(cone, n, _count(roll_steps, "roll_steps", 1), tool_axis=axis)


def _default_tool_axis(robot: "Robot", cone: float) -> np.ndarray:
    """The tool's +z, unless no sampled configuration points +z within ``cone`` of straight down while −z does.

    Rule for arms whose tool frame has z up (a SCARA or gantry modelled with the base's axes):
    4096 configurations seeded 0 decide.
    """
    q = robot.random_q(4096, seed=0)
    z = robot.fk(q)[:, :3, 2]
    cos = np.cos(cone) - 1e-9
    if np.any(-z[:, 2] >= cos) or not np.any(z[:, 2] >= cos):
        return np.array([0.0, 0.0, 1.0])
    return np.array([0.0, 0.0, -1.0])


# ----------------------------------------------------------------------------- execution
class _Accumulator:
    """Folds chunk results in task order (:func:`pinarms.execution.reduce_chunks`): per-voxel arrays
    in memory, the stored solutions in memory or streamed to a file writer, then dropped."""

    def __init__(self, keep_solutions: bool, writer: Any) -> None:
        self.keep = keep_solutions and writer is None
        self.writer = writer
        self.parts: list[dict] = []
        self.solutions: list[tuple] = []
        self.round_reachable: list[np.ndarray] = []

    def __call__(self, acc: "_Accumulator", result: dict) -> "_Accumulator":
        if "q" in result:
            sol = (result.pop("pose_voxel"), result.pop("pose_orientation"), result.pop("q"), result.pop("w"))
            if self.writer is not None:
                self.writer.append(*sol)
            elif self.keep:
                self.solutions.append(sol)
        self.parts.append(result)
        self.round_reachable.append(result["voxels"][result["index"] > 0])
        return self


def _fold_round(tasks: list, acc: _Accumulator, scheduler: Any, progress: Callable | None) -> None:
    """Run one round's chunk tasks (serially or on ``scheduler``) and fold them into ``acc`` in task order."""
    from pinarms.execution import reduce_chunks

    reduce_chunks(solve_chunk, tasks, acc, acc, scheduler=scheduler, progress=progress)


def _assemble(arm: "Robot", spec: RobotSpec, s: _Settings, acc: _Accumulator, params: dict, seconds: float,
              scheduler: Any) -> ReachabilityMap:
    """The :class:`ReachabilityMap` of the folded chunks, voxels sorted by flat index."""
    oset, grid = s.orientations, s.grid
    M = oset.size
    parts = acc.parts
    if parts:
        voxels = np.concatenate([o["voxels"] for o in parts]).astype(np.int64)
        reached = np.concatenate([o["reached"] for o in parts]).reshape(-1, M)
        index = np.concatenate([o["index"] for o in parts])
        best = np.concatenate([o["best"] for o in parts])
        n_solutions = int(sum(o["n_solutions"] for o in parts))
    else:
        voxels, reached = np.zeros(0, np.int64), np.zeros((0, M), bool)
        index, best, n_solutions = np.zeros(0), np.zeros(0), 0
    order = np.argsort(voxels, kind="stable")
    solutions = None
    if acc.keep:
        sols = acc.solutions
        cat = lambda k, dt, shp: (np.concatenate([x[k] for x in sols]).astype(dt) if sols  # noqa: E731
                                  else np.zeros(shp, dt))
        solutions = PoseSolutions(cat(0, np.int64, (0,)), cat(1, np.int32, (0,)),
                                  cat(2, float, (0, arm.nq)).reshape(-1, arm.nq), cat(3, float, (0,)))
    params = dict(params, n_solutions=n_solutions, seconds=seconds,
                  poses_per_second=voxels.size * M / seconds if seconds > 0 else 0.0,
                  scheduler=_describe(scheduler))
    return ReachabilityMap(
        robot=arm.name, urdf_sha256=spec.sha256, tcp_frame=arm.tcp_frame, joint_names=tuple(arm.joint_names),
        joint_lower=np.array(arm.lower, dtype=float), joint_upper=np.array(arm.upper, dtype=float), solver=s.solver,
        manipulability_kind=s.manipulability, origin=np.array(grid.origin, dtype=float), resolution=float(s.resolution),
        shape=tuple(int(v) for v in grid.shape), orientations=oset, voxels=voxels[order],
        reached=np.ascontiguousarray(reached[order]), index=index[order], best_manipulability=best[order],
        solutions=solutions, parameters=params,
    )


def _describe(scheduler: Any) -> str:
    from pinarms.execution import describe_scheduler

    return describe_scheduler(scheduler)
