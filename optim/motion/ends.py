"""The ends of a planned motion: the arms, the start and the goal (joints, or a tool pose and its IK branches).

Frames: poses in the world (the cell's root), joint coordinates in rad or m.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping, Sequence

import numpy as np

from pinarms.optim.errors import GoalInCollision, StartInCollision
from pinarms.optim.motion.goals import GoalCandidate, describe_pair, ik_candidates, point_in_fixture
from pinarms.errors import InvalidInput, UnreachableTarget

if TYPE_CHECKING:
    from pinarms.optim.motion.checker import MotionChecker
    from pinarms.robots.cell import Cell

__all__ = ["planned_arms", "arm_joints", "is_pose", "nearest_turn", "check_end", "check_hold", "goal_candidates"]


def planned_arms(cell: Cell, arm: str | Sequence[str]) -> tuple[str, ...]:
    names = (arm,) if isinstance(arm, str) else tuple(arm)
    if not names or not all(isinstance(a, str) for a in names):
        raise InvalidInput(f"arm must be an arm name or a sequence of arm names, got {arm!r}")
    return tuple(cell.arm(a).name for a in names)


def arm_joints(cell: Cell, arms: tuple[str, ...], value: np.ndarray | Mapping[str, np.ndarray],
               what: str) -> np.ndarray:
    """The planned arms' coordinates from an array (concatenated) or ``{arm: q}``."""
    sizes = [cell.arm(a).nq for a in arms]
    if isinstance(value, Mapping):
        missing = [a for a in arms if a not in value]
        if missing:
            raise InvalidInput(f"{what} gives no joints for arm(s) {missing}")
        parts = [np.asarray(value[a], dtype=float).reshape(-1) for a in arms]
        if any(p.size != n for p, n in zip(parts, sizes)):
            raise InvalidInput(f"{what}: arm joint counts must be {dict(zip(arms, sizes))}")
        x = np.concatenate(parts)
    else:
        try:
            x = np.asarray(value, dtype=float).reshape(-1)
        except (TypeError, ValueError) as exc:
            raise InvalidInput(f"{what} must be joint coordinates, got {value!r}") from exc
    if x.size != sum(sizes) or not np.all(np.isfinite(x)):
        raise InvalidInput(f"{what} must be {sum(sizes)} finite joint coordinates (arms {list(arms)}), got {value!r}")
    return x


def is_pose(value: object) -> bool:
    if isinstance(value, Mapping):
        return False
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return arr.shape == (4, 4)


def nearest_turn(x: np.ndarray, ref: np.ndarray, continuous: np.ndarray) -> np.ndarray:
    """``x (..., n)`` with each continuous column moved by a multiple of 2π to the angle nearest ``ref (n,)``
    (the same pose; within ``ref ± π``); the other columns as they are."""
    x = np.array(x, dtype=float)
    turns = np.round((np.asarray(ref, dtype=float) - x) / (2.0 * np.pi))
    return np.where(np.asarray(continuous, dtype=bool), x + 2.0 * np.pi * turns, x)


def _idle_arms(checker: Any) -> tuple[str, ...]:
    """The cell's arms neither planned nor moving on their own trajectory: they stay at the hold pose."""
    moving = {m.arm for m in checker.moving}
    return tuple(a.name for a in checker.cell.arms if a.name not in checker.arms and a.name not in moving)


def _idle_note(pair: Any, idle: tuple[str, ...]) -> str:
    """``"; b_link2 belongs to arm 'b', idle at its hold pose ..."`` when the pair touches an idle arm."""
    if pair is None:
        return ""
    for body, owner in ((pair.body_a, pair.owner_a), (pair.body_b, pair.owner_b)):
        if owner in idle:
            return (f"; {body} belongs to arm {owner!r}, idle at its hold pose (give it another: hold in the cell "
                    f"description, --hold {owner}=Q1,Q2,..., or hold=)")
    return ""


def check_hold(checker: MotionChecker) -> None:
    """The arms that stay at their hold pose must touch nothing there.

    The planner checks only the pairs of the planned arms; a contact between an idle arm and
    a fixture (or itself, or another idle arm) would otherwise surface only when the timed
    motion is re-checked, after the whole search, as a failure of "the timed motion".

    Raises:
        StartInCollision: ``which="hold"``, naming the idle arm and the pairs in contact.
    """
    from pinarms.robots.cell.idle import idle_contacts

    found = idle_contacts(checker.cell, checker.hold, set(checker.arms) | {m.arm for m in checker.moving})
    if found:
        raise StartInCollision(found.message(f"hold in the cell description, --hold {found.arms[0]}=Q1,Q2,..., "
                                             "or hold="),
                               which="hold", pairs=tuple(p.bodies for p in found.pairs), distances=found.distances,
                               configurations=checker.hold)


def check_end(checker: MotionChecker, x: np.ndarray, label: str = "start") -> None:
    """``x`` within the checker's box (continuous joints: widen it first, :meth:`MotionChecker.span_turns`) and
    clear of every pair at its margin; else :class:`InvalidInput` naming the joints, or the collision error."""
    if not checker.within_limits(x[None])[0]:
        names = checker.cell.joint_names
        bad = [f"{names[c]} = {x[i]:.4g} outside [{checker.lower[i]:.4g}, {checker.upper[i]:.4g}]"
               for i, c in enumerate(checker.cols) if not checker.lower[i] - 1e-12 <= x[i] <= checker.upper[i] + 1e-12]
        raise InvalidInput(f"the {label} is outside the joint limits: {'; '.join(bad)}")
    if not checker.state_valid(x):
        e, pair, d = checker.closest(x)
        m = checker.self_margin if pair is not None and pair.kind == "self" else checker.margin
        err = StartInCollision if label == "start" else GoalInCollision
        raise err(f"the {label} configuration is in collision: {describe_pair(pair, d, m)}"
                  f"{_idle_note(pair, _idle_arms(checker))}; move it clear or lower the margin", which=label,
                  pairs=(None if pair is None else pair.bodies,), distances=(d,), configurations=x)


def _q_text(robot: Any, q: np.ndarray) -> str:
    """``[0.2676, -0.5556] rad`` (4 digits; each value with its unit when the joints mix rad and m)."""
    units = robot.joint_units
    if len(set(units)) == 1:
        return "[" + ", ".join(f"{v:.4g}" for v in q) + f"] {units[0]}"
    return "[" + ", ".join(f"{v:.4g} {u}" for v, u in zip(q, units)) + "]"


def goal_candidates(checker: MotionChecker, arms: tuple[str, ...], goal: np.ndarray | Mapping[str, np.ndarray],
                    start: np.ndarray, seed: int, frame: str | None, *, nearest: bool = True) -> list[GoalCandidate]:
    """The goal's configurations, clear or not (with why). ``nearest``: each continuous joint of a joint goal
    (or of each IK branch) at its 2π equivalent nearest the start (:func:`nearest_turn`); ``False``: a joint
    goal as given (a cycle's transfer must end where its lowering starts). The checker's box of the
    continuous joints is widened to hold the start and the goals (:meth:`MotionChecker.span_turns`)."""
    cell = checker.cell
    turn = checker.continuous if nearest else np.zeros(checker.n, dtype=bool)
    if not is_pose(goal):
        x = nearest_turn(arm_joints(cell, arms, goal, "goal"), start, turn)
        checker.span_turns(np.vstack([start, x]))
        check_end(checker, x, "goal")
        return [GoalCandidate(x, True)]
    if len(arms) != 1:
        raise InvalidInput("a pose goal needs one planned arm; give two arms' goals as joint vectors {arm: q}")
    T = np.asarray(goal, dtype=float)
    if not np.all(np.isfinite(T)) or np.abs(T[:3, :3] @ T[:3, :3].T - np.eye(3)).max() > 1e-6 or \
            np.abs(T[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-9:
        raise InvalidInput("goal pose must be a finite homogeneous transform (4, 4): tool → world [m]")
    inside = point_in_fixture(cell, T[:3, 3])
    if inside is not None:
        raise GoalInCollision(f"the goal point {np.round(T[:3, 3], 4).tolist()} m lies inside fixture {inside[0]!r} "
                              f"({inside[1] * 1e3:.1f} mm deep): no configuration can reach it clear",
                              which="goal", pairs=(("tcp", inside[0]),), distances=(-inside[1],))
    arm = cell.arm(arms[0])
    robot = arm.robot
    if frame is not None and frame not in ("tcp", robot.tcp_frame):
        raise InvalidInput(f"frame {frame!r}: pose goals are for the arm's tcp ({robot.tcp_frame!r})")
    T_base = arm.to_base(T)
    q, branch = ik_candidates(robot, T_base, start, seed=seed)
    if q.shape[0] == 0:
        reason = robot.ik_failure_reason(T_base) or "no IK solution within the joint limits"
        raise UnreachableTarget(f"the goal pose at {np.round(T[:3, 3], 4).tolist()} m is unreachable for arm "
                                f"{arm.name!r}: {reason}")
    q = nearest_turn(q, start, turn)  # each branch's continuous joints the short way from the start
    checker.span_turns(np.vstack([start, q]))
    out = []
    for qi, bi in zip(q, branch):
        if checker.state_valid(qi):
            out.append(GoalCandidate(qi, True, "", int(bi)))
            continue
        e, pair, d = checker.closest(qi)
        m = checker.self_margin if pair is not None and pair.kind == "self" else checker.margin
        out.append(GoalCandidate(qi, False, describe_pair(pair, d, m) + _idle_note(pair, _idle_arms(checker)), int(bi),
                                 () if pair is None else pair.bodies, d))
    if not any(g.valid for g in out):
        lines = "; ".join(f"{f'branch {g.branch} ' if g.branch >= 0 else ''}(q = {_q_text(robot, g.q)}): {g.reason}"
                          for g in out)
        raise GoalInCollision(f"every IK solution of the goal pose is in collision ({len(out)} tried): {lines}",
                              which="goal", pairs=tuple(g.pair for g in out), distances=tuple(g.distance for g in out),
                              configurations=np.array([g.q for g in out]))
    return out

