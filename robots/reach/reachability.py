"""Reachability maps: which tool poses an arm reaches, voxel by voxel, with which orientations.

:func:`reachability_map` answers, for every voxel centre ``p`` of a grid of edge
``resolution`` [m] and every rotation ``R_k`` of an :class:`~robots.orientations.OrientationSet`,
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

Units: metres, radians; rotations tool frame → base; joint values in the robot's ``q`` order.
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np
from scipy import ndimage

from ..errors import InvalidInput, ModelError
from .orientations import OrientationSet, so3_orientations, tool_down_orientations
from .reach_map import MAX_GRID_VOXELS, PoseSolutions, ReachabilityMap, _centres

if TYPE_CHECKING:  # pragma: no cover
    from ..robot import Robot

__all__ = [
    "ReachabilityMap",
    "PoseSolutions",
    "reachability_map",
    "reach_bound",
    "solve_chunk",
    "MAX_GRID_VOXELS",
    "TIE_RTOL",
]

#: Relative tolerance under which two solutions' manipulabilities count as tied.
TIE_RTOL = 1e-9
_TIE_ATOL = 1e-15
_POSES_PER_CHUNK = {"analytic": 100_000, "numerical": 10_000}


# ----------------------------------------------------------------------------- robot specs
@dataclass(frozen=True)
class _RobotSpec:
    """What a worker needs to rebuild the robot: a registry name, or the URDF text (picklable, small)."""

    name: str
    sha256: str
    tcp_frame: str
    registry: bool
    urdf_text: str | None
    package_dirs: tuple[str, ...]
    family: str | None


_ROBOT_CACHE: dict[tuple, Any] = {}


def _urdf_sha256(robot: "Robot") -> str:
    return hashlib.sha256(robot.urdf_text.encode("utf-8")).hexdigest()


def _family(robot: "Robot") -> str | None:
    solver = getattr(robot, "_analytic_ik", None)
    if solver is None:
        return None
    from ..ik import FAMILIES

    for key, cls in FAMILIES.items():
        if type(solver) is cls:
            return key
    raise ModelError(f"robot '{robot.name}' has a closed-form solver of an unknown family ({type(solver).__name__})")


def _spec_of(robot: "Robot") -> _RobotSpec:
    from .. import registry

    sha = _urdf_sha256(robot)
    family = _family(robot)
    is_registry = False
    if robot.name in registry.names():
        try:
            ref = registry.load(robot.name)
            is_registry = _urdf_sha256(ref) == sha and ref.tcp_frame == robot.tcp_frame and _family(ref) == family
        except Exception:  # a registry robot that cannot load here: ship the URDF text instead
            is_registry = False
    spec = _RobotSpec(
        name=robot.name,
        sha256=sha,
        tcp_frame=robot.tcp_frame,
        registry=is_registry,
        urdf_text=None if is_registry else robot.urdf_text,
        package_dirs=tuple(str(p) for p in robot.package_dirs),
        family=family,
    )
    _ROBOT_CACHE.setdefault(_cache_key(spec), robot)
    return spec


def _cache_key(spec: _RobotSpec) -> tuple:
    return (spec.sha256, spec.tcp_frame, spec.family)


def _robot(spec: _RobotSpec) -> "Robot":
    """The robot of ``spec``, built once per process."""
    key = _cache_key(spec)
    robot = _ROBOT_CACHE.get(key)
    if robot is None:
        from .. import registry
        from ..ik import attach_analytic_ik

        if spec.registry:
            robot = registry.load(spec.name)
        else:
            robot = registry.from_urdf_text(spec.urdf_text, tcp=spec.tcp_frame, name=spec.name,
                                            package_dirs=spec.package_dirs)
            attach_analytic_ik(robot, spec.family) if spec.family else None
        if _urdf_sha256(robot) != spec.sha256:
            raise ModelError(
                f"robot '{spec.name}' loads here with another URDF (SHA-256 {_urdf_sha256(robot)[:12]}… instead of "
                f"{spec.sha256[:12]}…): the worker runs another pinarms version"
            )
        _ROBOT_CACHE[key] = robot
    return robot


# ----------------------------------------------------------------------------- the bound
def reach_bound(robot: "Robot", frame: str = "tcp") -> tuple[np.ndarray, float]:
    """A sphere ``(centre (3,), radius)`` [m] that contains every position of ``frame``'s origin.

    The centre is the origin of the first joint on the chain from the base to ``frame`` (fixed
    in the base frame for a revolute first joint); the radius adds, by the triangle inequality,
    the length of every later joint placement's offset, the frame's offset from its joint, and
    the largest travel ``max(|lower|, |upper|)`` of every prismatic joint on the chain.
    """
    model = robot.model
    fid = robot.frame_id(frame)
    f = model.frames[fid]
    chain = []
    j = f.parentJoint
    while j > 0:
        chain.append(j)
        j = model.parents[j]
    chain.reverse()
    if not chain:
        raise ModelError(f"frame {frame!r} of '{robot.name}' does not move with any joint")
    centre = np.array(model.jointPlacements[chain[0]].translation, dtype=float)
    radius = float(np.linalg.norm(f.placement.translation))
    radius += sum(float(np.linalg.norm(model.jointPlacements[j].translation)) for j in chain[1:])
    tree = robot._tree
    for j in chain:
        if tree.kind[j] == 2:  # prismatic (mimic prismatic joints move by scale·q + offset)
            q_index = tree.q_index[j]
            stroke = max(abs(robot.lower[q_index]), abs(robot.upper[q_index]))
            radius += abs(float(tree.scale[j])) * stroke + abs(float(tree.offset[j]))
    return centre, radius


# ----------------------------------------------------------------------------- chunk work
@dataclass(frozen=True)
class ChunkTask:
    """One chunk of voxels: everything :func:`solve_chunk` needs (picklable, a few kB).

    ``voxels`` are flat indices (C order) into the grid ``origin``/``resolution``/``shape``.
    """

    robot: _RobotSpec
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


def _manipulability(robot: "Robot", q: np.ndarray, part: str) -> np.ndarray:
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


def _self_collision(spec: _RobotSpec, robot: "Robot"):
    key = _cache_key(spec)
    checker = _COLLISION_CACHE.get(key)
    if checker is None:
        from ..self_collision import SelfCollision

        checker = _COLLISION_CACHE[key] = SelfCollision(robot, seed=0)
    return checker


def _collision_free(task: ChunkTask, robot: "Robot", q: np.ndarray) -> np.ndarray:
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
    P = _centres(task.origin, task.resolution, task.shape, task.voxels)
    n, M = P.shape[0], task.rotations.shape[0]
    T = np.zeros((n, M, 4, 4))
    T[:, :, :3, :3] = task.rotations[None]
    T[:, :, :3, 3] = P[:, None, :]
    T[:, :, 3, 3] = 1.0
    return T.reshape(n * M, 4, 4)


def _solve_analytic(task: ChunkTask, robot: "Robot") -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """``(pose index (K,), q (K, nq), w (K,), n_solutions)``: the chosen solution of each reached pose."""
    T = _poses(task)
    idx, q = robot._analytic_ik.candidates(T)
    n_all = int(idx.size)
    keep = _collision_free(task, robot, q)
    idx, q = idx[keep], q[keep]
    w = _manipulability(robot, q, task.manipulability)
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
    solver = robot._numerical_ik()
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
            res = solver._solve(T[r * M + k], start, position_only=False, tol=task.tol,
                                max_restarts=task.restarts, seed=rng, limits=True)
            if res.success and _collision_free(task, robot, res.q[None])[0]:
                here[k] = res.q
                poses.append(r * M + k)
                qs.append(res.q)
        solved[v] = here
    pose = np.asarray(poses, dtype=np.int64)
    q = np.asarray(qs, dtype=float).reshape(-1, nq)
    return pose, q, _manipulability(robot, q, task.manipulability), int(pose.size)


def solve_chunk(task: ChunkTask) -> dict:
    """Reachability of one chunk of voxels (the task function of :func:`reachability_map`).

    Returns a dict of arrays: ``voxels (n,)`` (the task's), ``reached (n, M)`` bool, ``index (n,)``, ``best (n,)`` (NaN where
    nothing is reached), ``n_solutions`` (every in-limit solution found, before collisions), and
    with ``keep_solutions`` the reached poses' ``pose_voxel (K,)`` (grid flat index),
    ``pose_orientation (K,)``, ``q (K, nq)`` and ``w (K,)``.
    """
    robot = _robot(task.robot)
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
    from pinarms.execution import reduce_chunks

    reduce_chunks(solve_chunk, tasks, acc, acc, scheduler=scheduler, progress=progress)


# ----------------------------------------------------------------------------- building
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


def _seed_voxels(robot: "Robot", origin: np.ndarray, resolution: float, shape: tuple, n: int, seed: int) -> np.ndarray:
    """Grid flat indices entered by the tool in ``n`` seeded joint samples (streamed in blocks)."""
    size = int(np.prod(shape))
    hit = np.zeros(size, dtype=bool)
    rng = np.random.default_rng([int(seed), 0x5EED])
    dims = np.array(shape)
    for start in range(0, n, 200_000):
        m = min(200_000, n - start)
        q = rng.uniform(robot.lower, robot.upper, size=(m, robot.nq))
        p = robot.position(q)
        ijk = np.floor((p - origin) / resolution).astype(np.int64)
        ok = np.all((ijk >= 0) & (ijk < dims), axis=1)
        ijk = ijk[ok]
        hit[(ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]] = True
    return np.flatnonzero(hit)


def _dilate(flat: np.ndarray, shape: tuple, allowed: np.ndarray) -> np.ndarray:
    """``flat`` and its 6 face neighbours, restricted to the bool grid ``allowed``."""
    grid = np.zeros(int(np.prod(shape)), dtype=bool)
    grid[flat] = True
    grown = ndimage.binary_dilation(grid.reshape(shape), structure=ndimage.generate_binary_structure(3, 1))
    return np.flatnonzero(grown.reshape(-1) & allowed)


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


def reachability_map(
    arm: "Robot",
    resolution: float = 0.025,
    orientations: int | OrientationSet = 50,
    *,
    tool_down: float | None = None,
    roll_steps: int = 8,
    tool_axis: Any = None,
    ik: str = "auto",
    manipulability: str = "full",
    restarts: int = 2,
    tol: float = 1e-9,
    self_collision: bool = False,
    collision: Any = None,
    keep_solutions: bool = True,
    out: Any = None,
    chunk_voxels: int | None = None,
    samples: int | None = None,
    seed: int = 0,
    scheduler: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> ReachabilityMap:
    """Build the reachability map of ``arm``'s tool frame (see the module doc).

    Args:
        arm: any :class:`~robots.robot.Robot`.
        resolution: voxel edge [m].
        orientations: poses per voxel spread over SO(3) (super-Fibonacci), or with ``tool_down``
            the number of tool-axis directions in the cone; or any
            :class:`~robots.orientations.OrientationSet`.
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
            :func:`robots.reach_io.load_reachability`). Written to a temporary file and renamed
            when complete.
        chunk_voxels: voxels per task (default: about 10⁵ poses for closed forms, 10⁴ for
            the numerical solver). The map depends on it only through the numerical warm starts.
        samples: joint samples marking the first voxels (default: 2 per voxel of the bound
            sphere, between 2·10⁵ and 5·10⁶).
        seed: seed of the samples and of the numerical restarts.
        scheduler: ``None`` (serial, here), ``"processes[:N]"``, ``"tcp://HOST:8786"``, ``"env"`` or a
            ``distributed.Client`` (see :mod:`pinarms.execution`).
        progress: ``progress(voxels_done, voxels_to_do)`` after each chunk (the second number
            grows when a closure round adds voxels).

    Raises:
        InvalidInput: a bad argument (resolution not positive, an unknown ``ik`` or
            ``manipulability``, a grid of more than :data:`MAX_GRID_VOXELS` voxels, ...).
        ModelError: ``ik="analytic"`` for an arm without a closed form.
    """
    t0 = time.perf_counter()
    resolution = _positive(resolution, "resolution [m]")
    if ik not in ("auto", "analytic", "numerical"):
        raise InvalidInput(f"ik must be 'auto', 'analytic' or 'numerical', got {ik!r}")
    if manipulability not in ("full", "position"):
        raise InvalidInput(f"manipulability must be 'full' or 'position', got {manipulability!r}")
    if ik == "analytic" and not arm.has_analytic_ik:
        raise ModelError(f"robot '{arm.name}' has no closed-form IK; use ik='numerical' (or 'auto')")
    solver = "analytic" if (ik != "numerical" and arm.has_analytic_ik) else "numerical"
    restarts = _count(restarts, "restarts")
    tol = _positive(tol, "tol [m, rad]")
    seed = _count(seed, "seed")
    if collision is not None and not callable(getattr(collision, "in_collision", None)):
        raise InvalidInput("collision must have a method in_collision(q (N, nq)) -> (N,) bool")
    oset = _orientation_set(orientations, tool_down, roll_steps, tool_axis, arm)
    M = oset.size
    if chunk_voxels is None:
        chunk_voxels = max(1, _POSES_PER_CHUNK[solver] // M)
    chunk_voxels = _count(chunk_voxels, "chunk_voxels", 1)
    if not (np.all(np.isfinite(arm.lower)) and np.all(np.isfinite(arm.upper))):
        raise InvalidInput(f"robot '{arm.name}' has unbounded joint limits; a map needs finite limits")

    # grid: the guaranteed bound
    centre, radius = reach_bound(arm)
    lo_i = np.floor((centre - radius) / resolution).astype(np.int64)
    hi_i = np.ceil((centre + radius) / resolution).astype(np.int64)
    shape = tuple(int(v) for v in np.maximum(hi_i - lo_i, 1))
    n_grid = int(np.prod(shape))
    if n_grid > MAX_GRID_VOXELS:
        raise InvalidInput(
            f"resolution {resolution} m gives a grid of {n_grid} voxels around the reach of '{arm.name}' "
            f"(radius {radius:.3f} m); use a larger resolution (at most {MAX_GRID_VOXELS} voxels)"
        )
    origin = lo_i * resolution
    all_centres_inside = np.zeros(n_grid, dtype=bool)
    for start in range(0, n_grid, 1 << 21):
        flat = np.arange(start, min(n_grid, start + (1 << 21)))
        c = _centres(origin, resolution, shape, flat)
        all_centres_inside[flat] = np.einsum("ij,ij->i", c - centre, c - centre) <= radius * radius
    n_sphere = int(all_centres_inside.sum())
    if samples is None:
        samples = int(np.clip(2 * n_sphere, 200_000, 5_000_000))
    samples = _count(samples, "samples", 1)

    spec = _spec_of(arm)
    base = dict(robot=spec, origin=origin, resolution=resolution, shape=shape, rotations=oset.rotations,
                group=oset.group, n_groups=oset.n_groups, roll_free=oset.roll_free, solver=solver,
                manipulability=manipulability, restarts=restarts, tol=tol, self_collision=bool(self_collision),
                collision=collision, keep_solutions=bool(keep_solutions) or out is not None, seed=seed)

    writer = None
    if out is not None:
        from .reach_write import StreamWriter

        writer = StreamWriter(out, arm.nq)
    acc = _Accumulator(bool(keep_solutions) or writer is not None, writer)
    try:
        todo = _dilate(_seed_voxels(arm, origin, resolution, shape, samples, seed), shape, all_centres_inside)
        computed = np.zeros(n_grid, dtype=bool)
        done_voxels, total_voxels, rounds = 0, int(todo.size), 0
        while todo.size:
            rounds += 1
            computed[todo] = True
            chunks = [todo[s : s + chunk_voxels] for s in range(0, todo.size, chunk_voxels)]
            tasks = [ChunkTask(voxels=c, **base) for c in chunks]
            ends = np.cumsum([c.size for c in chunks])

            def report(done: int, total: int, _offset=done_voxels, _ends=ends) -> None:
                progress(_offset + (int(_ends[done - 1]) if done else 0), total_voxels)

            acc.round_reachable = []
            _fold_round(tasks, acc, scheduler, report if progress is not None else None)
            done_voxels += int(todo.size)
            reachable = np.concatenate(acc.round_reachable) if acc.round_reachable else np.zeros(0, np.int64)
            frontier = _dilate(reachable, shape, all_centres_inside) if reachable.size else np.zeros(0, np.int64)
            todo = frontier[~computed[frontier]]
            total_voxels += int(todo.size)

        params = dict(
            seed=seed, chunk_voxels=chunk_voxels, restarts=restarts, tol=tol, self_collision=bool(self_collision),
            collision=None if collision is None else type(collision).__name__, samples=samples, rounds=rounds,
            bound_centre=centre.tolist(), bound_radius=radius, keep_solutions=bool(keep_solutions) or writer is not None,
        )
        m = _assemble(arm, spec, oset, solver, manipulability, origin, resolution, shape, acc, params,
                      time.perf_counter() - t0, scheduler)
        if writer is not None:
            writer.finish(m)
            writer = None
        return m
    finally:
        if writer is not None:
            writer.abort()


def _assemble(arm, spec, oset, solver, manipulability, origin, resolution, shape, acc, params, seconds, scheduler):
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
        joint_lower=np.array(arm.lower, dtype=float), joint_upper=np.array(arm.upper, dtype=float), solver=solver,
        manipulability_kind=manipulability, origin=np.array(origin, dtype=float), resolution=float(resolution),
        shape=tuple(int(v) for v in shape), orientations=oset, voxels=voxels[order],
        reached=np.ascontiguousarray(reached[order]), index=index[order], best_manipulability=best[order],
        solutions=solutions, parameters=params,
    )


def _describe(scheduler: Any) -> str:
    from pinarms.execution import describe_scheduler

    return describe_scheduler(scheduler)
