"""Goal states of a motion: a joint vector, or a tool pose and every IK branch that reaches it."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from pinarms.robots import Robot
    from pinarms.robots.cell import Cell
    from pinarms.robots.cell.pairs import CollisionPair

__all__ = ["closed_form", "GoalCandidate", "describe_pair", "point_in_fixture", "ik_candidates"]


@lru_cache(maxsize=1)
def _families_by_joints() -> dict[tuple[str, ...], str]:
    from pinarms.robots import registry
    from pinarms.robots.ik import FAMILY_OF

    out = {}
    for name, family in FAMILY_OF.items():
        try:
            out[registry.load(name).joint_names] = family
        except Exception:  # an arm whose model cannot load here has no say
            continue
    return out


def closed_form(robot: Robot) -> Robot:
    """``robot`` with its closed-form IK attached when its joints are those of a known arm family.

    A cell's arms get the closed form of pinarms' built-in arms; an example-robot-data arm
    placed in a cell (UR5) is recognised here by its joint names.
    """
    if getattr(robot, "has_analytic_ik", False):
        return robot
    family = _families_by_joints().get(tuple(robot.joint_names))
    if family is not None:
        from pinarms.robots.ik import attach_analytic_ik
        from pinarms.errors import ModelError

        try:
            attach_analytic_ik(robot, family)
        except ModelError:
            robot.set_analytic_ik(None)
    return robot


@dataclass(frozen=True, eq=False)
class GoalCandidate:
    """One configuration that reaches the goal: the arm's ``q``, whether it is a valid goal
    state, and why not (the pair nearest its margin and its distance, or a joint limit)."""

    q: np.ndarray
    valid: bool
    reason: str = ""
    branch: int = -1
    pair: tuple = ()
    distance: float = float("nan")


def describe_pair(pair: CollisionPair | None, distance: float, margin: float) -> str:
    """``"aubo_wrist1_Link – guard_plate 3.2 mm apart (margin 10 mm)"`` or ``"... overlap by 4.1 mm"``."""
    if pair is None:
        return "no checked pair"
    what = f"{pair.body_a} – {pair.body_b}"
    if distance < 0.0:
        return f"{what} overlap by {-distance * 1e3:.1f} mm (margin {margin * 1e3:.1f} mm)"
    return f"{what} {distance * 1e3:.1f} mm apart (margin {margin * 1e3:.1f} mm)"


def point_in_fixture(cell: Cell, point: np.ndarray) -> tuple[str, float] | None:
    """``(fixture, depth [m])`` when the world point lies inside a fixture's box, cylinder,
    sphere or capsule (the deepest), else ``None``. Meshes are not tested (a surface has no inside)."""
    best = None
    p = np.asarray(point, dtype=float)
    for fixture in cell.fixtures:
        for shape in fixture.shapes:
            local = np.linalg.inv(shape.shape_to_world) @ np.append(p, 1.0)
            x = local[:3]
            if shape.kind == "box":
                depth = float(np.min(np.asarray(shape.size) / 2.0 - np.abs(x)))
            elif shape.kind == "cylinder":
                r, length = shape.size
                depth = float(min(r - np.hypot(x[0], x[1]), length / 2.0 - abs(x[2])))
            elif shape.kind == "sphere":
                depth = float(shape.size[0] - np.linalg.norm(x))
            elif shape.kind == "capsule":
                r, length = shape.size
                z = np.clip(x[2], -length / 2.0, length / 2.0)
                depth = float(r - np.linalg.norm(x - np.array([0.0, 0.0, z])))
            else:
                continue
            if depth > 0.0 and (best is None or depth > best[1]):
                best = (fixture.name, depth)
    return best


def ik_candidates(robot: Robot, T_base: np.ndarray, q_ref: np.ndarray, *, seed: int = 0,
                  attempts: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Configurations ``(k, nq)`` reaching ``T_base`` (arm base frame) and their branch labels ``(k,)``.

    A closed-form arm: every branch once (:meth:`pinarms.robots.Robot.ik_branches`, each angle at its
    2π equivalent nearest ``q_ref``). Otherwise the numerical solver from ``q_ref`` and from
    ``attempts − 1`` seeded random starts, distinct solutions only (1e-3 rad apart), branch −1.
    """
    robot = closed_form(robot)
    if robot.has_analytic_ik:
        q, branch = robot.ik_branches(T_base, q_ref=q_ref)
        q = np.asarray(q, dtype=float).reshape(-1, robot.nq)
        ok = np.asarray(robot.within_limits(q), dtype=bool).reshape(-1) if q.shape[0] else np.zeros(0, bool)
        return q[ok], np.asarray(branch, dtype=int).reshape(-1)[ok]
    from pinarms.errors import UnreachableTarget

    rng = np.random.default_rng(seed)
    found: list[np.ndarray] = []
    starts = [np.asarray(q_ref, dtype=float)] + [robot.random_q(1, seed=rng)[0] for _ in range(attempts - 1)]
    for k, q0 in enumerate(starts):
        try:
            q = robot.ik(T_base, q_seed=q0, seed=int(seed) + k, max_restarts=2 if k else 10)
        except UnreachableTarget:
            continue
        if all(np.abs(q - f).max() > 1e-3 for f in found):
            found.append(q)
    q = np.array(found, dtype=float).reshape(-1, robot.nq)
    return q, np.full(q.shape[0], -1, dtype=int)
