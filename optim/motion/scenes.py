"""The planning scenes: cell files with task regions, and seeded queries in them.

Each scene is a cell file in ``optim/motion/scene_files/`` (xacro, expanded behind the
wall of :func:`pinarms.robots.expand_xacro` like any user's file) and a few **task regions**:
boxes (world frame, m) where the tool works, each with its approach direction (``"down"``:
tool z along world −z; ``"+x"``: tool z along world +x). :func:`scene_queries` draws
seeded start/goal pairs: a tcp position uniform in one region, the tool turned by a
uniform angle in ±30° about its approach axis, an IK solution whose clearance is at least
the margin; start and goal in two different regions, so that most queries must go around
something (a shelf board, the divider, the box, the guard, the other arm).

=====================  ==========  ===========================================================
scene                  arm         what is in the way
=====================  ==========  ===========================================================
``panda_shelf``        Panda       shelf: 2 levels x 2 compartments (boards, divider, back)
``ur5_shelf``          UR5         the same shelf
``panda_table_box``    Panda       a 0.30 m box on the table between the two pick areas
``ur5_table_box``      UR5         the same table and box
``panda_crate_guard``  Panda       a crate whose near half is under a guard plate
``aubo_crate_guard``   AUBO-i3     seed 001's food station, its crate under a guard plate
``aubo_two_belt``      AUBO-i3 x2  the other arm, holding over the shared belt
=====================  ==========  ===========================================================

``panda_crate_guard`` has no clear query at a 10 mm margin, and its regions cannot give it one:
every Panda IK solution in the crate's far half touches something (20 of 20 targets solved, none
clear) — the hand (two 50 mm spheres 150 mm apart, 100 mm wide across) and link 7's 70 mm spheres
against the crate's far wall (the far half is 120 mm wide inside: the hand fits only centred,
turned along x, with no slack beyond the two margins), and with the tool higher links 5–7 against
the guard plate 0.50 m above the table (none clear on a grid of 192 tcp positions and turns in and
above the far half, tcp 0.84–1.08 m, 6 targets each; a plate at 0.60 or 0.70 m: 0–1 of 8
targets; a plate at 0.80 m and the crate 0.36 m across, centred at y = −0.60: 1–5 of 8). A
solvable Panda crate needs another cell, not other regions; :func:`scene_queries` says so
(``UnreachableTarget``) and the benchmark reports it.

The Panda and UR5 are example-robot-data's, placed by the macros of
:mod:`~pinarms.optim.motion.arm_macros` (the Panda's collision model is spheres and
cylinders, the UR5's meshes).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import CellNotFound, InvalidInput, UnreachableTarget

if TYPE_CHECKING:
    from pinarms.robots.cell.cell import Cell

__all__ = ["Region", "Scene", "Query", "SCENES", "SCENE_DIR", "scene_names", "scene_path", "load_scene",
           "scene_queries", "region_pose", "valid_ik"]

#: Folder of the scene cell files.
SCENE_DIR = Path(__file__).resolve().parent / "scene_files"


@dataclass(frozen=True)
class Region:
    """A box where the tool works: ``lo``/``hi`` corners [m, world] and the approach direction."""

    name: str
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    approach: str = "down"


@dataclass(frozen=True)
class Scene:
    """A planning scene: its cell file, the arm planned, its task regions.

    ``hold``: for a cell with several arms, the region each other arm's tcp holds in
    (the arm stands still there while the planned arm moves).
    """

    name: str
    arm: str
    regions: tuple[Region, ...]
    hold: dict = field(default_factory=dict)
    description: str = ""

    @property
    def file(self) -> Path:
        return SCENE_DIR / f"{self.name}.urdf.xacro"

    def region(self, name: str) -> Region:
        for r in self.regions:
            if r.name == name:
                return r
        raise InvalidInput(f"scene {self.name!r} has no region {name!r}; regions: {[r.name for r in self.regions]}")


def _shelf_regions() -> tuple[Region, ...]:
    out = []
    for level, z in (("lower", 0.70), ("upper", 1.00)):
        for side, y in (("left", 0.19), ("right", -0.19)):
            out.append(Region(f"shelf {level} {side}", (0.60, y - 0.07, z - 0.04), (0.66, y + 0.07, z + 0.04), "+x"))
    return tuple(out)


def _table_regions(h: float) -> tuple[Region, ...]:
    return (Region("table left", (0.35, 0.25, h + 0.04), (0.55, 0.40, h + 0.12)),
            Region("table right", (0.35, -0.40, h + 0.04), (0.55, -0.25, h + 0.12)),
            Region("above box", (0.40, -0.08, h + 0.38), (0.50, 0.08, h + 0.46)))


SCENES: dict[str, Scene] = {
    s.name: s
    for s in (
        Scene("panda_shelf", "panda", _shelf_regions(), description="Panda in front of a shelf, 4 compartments"),
        Scene("ur5_shelf", "ur5", _shelf_regions(), description="UR5 in front of the same shelf"),
        Scene("panda_table_box", "panda", _table_regions(0.75), description="Panda, a box between two table areas"),
        Scene("ur5_table_box", "ur5", _table_regions(0.75), description="UR5, the same table and box"),
        Scene("panda_crate_guard", "panda",
              (Region("table", (0.40, 0.05, 0.80), (0.55, 0.30, 0.88)),
               Region("crate far half", (0.15, -0.64, 0.80), (0.35, -0.58, 0.86))),
              description="Panda, a crate whose near half is under a guard plate"),
        Scene("aubo_crate_guard", "aubo",
              (Region("food table", (0.34, 0.00, 0.76), (0.48, 0.20, 0.82)),
               Region("crate far half", (-0.08, -0.49, 0.76), (0.08, -0.44, 0.80))),
              description="AUBO-i3 food station, crate under a guard plate"),
        Scene("aubo_two_belt", "left",
              (Region("belt", (-0.15, -0.05, 0.80), (0.15, 0.10, 0.88)),
               Region("own crate", (-0.07, 0.74, 0.80), (0.07, 0.82, 0.85))),
              hold={"right": Region("belt", (-0.10, -0.12, 0.80), (0.10, 0.02, 0.88))},
              description="two AUBO-i3 over one belt; the right arm holds over the belt"),
    )
}


def scene_names() -> list[str]:
    """Names of the planning scenes, in :data:`SCENES` order."""
    return list(SCENES)


def scene_path(name: str) -> Path:
    """The cell file of scene ``name``."""
    if name not in SCENES:
        raise CellNotFound(f"unknown planning scene {name!r}; scenes: {', '.join(SCENES)}")
    return SCENES[name].file


@lru_cache(maxsize=8)
def load_scene(name: str) -> Any:
    """The :class:`pinarms.robots.Cell` of scene ``name`` (loaded once per process)."""
    from pinarms import robots
    from pinarms.optim.motion.arm_macros import example_packages

    return robots.load_cell(scene_path(name), packages=example_packages())


def region_pose(region: Region, point: ArrayLike, yaw: float = 0.0) -> np.ndarray:
    """Tool pose (4, 4) in the world at ``point`` [m] with the region's approach, turned by ``yaw`` [rad]."""
    p = np.asarray(point, dtype=float)
    if region.approach == "down":
        R = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])
    elif region.approach == "+x":
        R = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    else:
        raise InvalidInput(f"unknown approach {region.approach!r}: use 'down' or '+x'")
    c, s = np.cos(yaw), np.sin(yaw)
    T = np.eye(4)
    T[:3, :3] = R @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    T[:3, 3] = p
    return T


@dataclass(frozen=True, eq=False)
class Query:
    """A seeded planning query: arm configurations ``start``/``goal`` and where they are."""

    start: np.ndarray
    goal: np.ndarray
    start_region: str
    goal_region: str
    start_pose: np.ndarray
    goal_pose: np.ndarray


def valid_ik(checker: MotionChecker, T_world: np.ndarray, rng: np.random.Generator) -> np.ndarray | None:
    """A configuration of the checker's (one) arm reaching ``T_world`` that is a valid state, or None.

    Closed-form arms: the first valid branch; others: up to 6 seeded numerical solutions."""
    from pinarms.optim.motion.goals import closed_form

    cell = checker.cell
    arm = cell.arm(checker.arms[0])
    robot = closed_form(arm.robot)
    T = arm.to_base(T_world)
    if robot.has_analytic_ik:
        cands = np.asarray(robot.ik_all(T), dtype=float).reshape(-1, arm.nq)
    else:
        cands = []
        for _ in range(6):
            try:
                cands.append(robot.ik(T, q_seed=robot.random_q(1, seed=rng)[0], seed=int(rng.integers(2**31)),
                                      max_restarts=4))
            except UnreachableTarget:
                continue
        cands = np.asarray(cands, dtype=float).reshape(-1, arm.nq)
    for q in cands:
        if np.all(np.isfinite(q)) and checker.state_valid(q):
            return q
    return None


def scene_queries(name: str, n: int = 50, *, seed: int = 0, margin: float = 0.01,
                  cell: Cell | None = None) -> tuple[list[Query], np.ndarray]:
    """``n`` seeded queries of scene ``name`` and the cell configuration the other arms hold.

    Returns ``(queries, hold)``; ``hold`` (nq_cell,) puts each held arm at a seeded IK
    solution in its hold region (and the planned arm at its first start).
    """
    scene = SCENES[name] if name in SCENES else None
    if scene is None:
        raise CellNotFound(f"unknown planning scene {name!r}; scenes: {', '.join(SCENES)}")
    from pinarms.optim.motion.checker import MotionChecker

    cell = cell if cell is not None else load_scene(name)
    rng = np.random.default_rng(seed)
    hold = cell.hold
    for other, region in scene.hold.items():
        held = MotionChecker(cell, [other], margin=margin, hold=hold)
        for _ in range(200):
            p = rng.uniform(region.lo, region.hi)
            q = valid_ik(held, region_pose(region, p, rng.uniform(-0.5, 0.5)), rng)
            if q is not None:
                hold[cell.arm(other).q_slice] = q
                break
        else:
            raise UnreachableTarget(f"scene {name!r}: no clear configuration of arm {other!r} in region {region.name!r}")
    checker = MotionChecker(cell, [scene.arm], margin=margin, hold=hold)
    queries: list[Query] = []
    k = len(scene.regions)
    attempts = 0
    while len(queries) < n:
        attempts += 1
        if attempts > 50 * n:
            raise UnreachableTarget(f"scene {name!r}: only {len(queries)} of {n} queries found clear IK solutions")
        i, j = rng.choice(k, size=2, replace=False)
        ends = []
        for r in (scene.regions[i], scene.regions[j]):
            T = region_pose(r, rng.uniform(r.lo, r.hi), rng.uniform(-np.pi / 6, np.pi / 6))
            q = valid_ik(checker, T, rng)
            if q is None:
                break
            ends.append((q, T))
        if len(ends) == 2:
            queries.append(Query(ends[0][0], ends[1][0], scene.regions[i].name, scene.regions[j].name,
                                 ends[0][1], ends[1][1]))
    return queries, hold
