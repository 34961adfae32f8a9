"""The clearance curves of a motion check: each moving arm against everything else (issue 36 item 11)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.robots.cell.motion_curves import moving_arm_groups
from pinarms.robots.cell.timeline import configurations


@pytest.fixture(scope="module")
def line():
    return load_cell("mushroom_line")


@pytest.fixture(scope="module")
def left_moves(line):
    arm = line.arm("left")
    q0 = arm.robot.ik(arm.to_base(np.array([-0.05, -0.03, 0.90])), position_only=True)
    q1 = arm.robot.ik(arm.to_base(np.array([0.22, 0.68, 0.90])), position_only=True)
    motion = [ArmMotion("left", planning.multi_quintic([0.0, 1.0], np.array([q0, q1])))]
    return motion, line.check_motion(motion, margin=0.01, clearance=0.0, curve=True)


def test_the_groups_are_the_moving_arm_against_everything_else(line):
    groups = moving_arm_groups(line, ["left"])
    assert list(groups) == ["left ↔ fixtures", "left ↔ right", "left: own links"][: len(groups)]
    assert "left ↔ fixtures" in groups and "left ↔ right" in groups
    for name, idx in groups.items():
        for k in idx:
            p = line._candidates[k]
            assert "left" in (p.owner_a, p.owner_b)
    # the idle arm's own links and its fixtures never make a curve: their distance does not change
    every = np.concatenate(list(groups.values()))
    idle = [k for k, p in enumerate(line._candidates) if "left" not in (p.owner_a, p.owner_b)]
    assert idle and not set(idle) & set(every.tolist())


def test_each_curve_is_the_exact_distance_of_its_group(line, left_moves):
    motion, check = left_moves
    assert set(check.curves) == set(moving_arm_groups(line, ["left"]))
    groups = moving_arm_groups(line, ["left"])
    rows = np.linspace(0, check.times.size - 1, 6).astype(int)
    Q = configurations(line, motion, check.times[rows], line.neutral)
    pairs = line.pairs_for(float("inf"))
    view_d = {name: np.full(rows.size, np.inf) for name in groups}
    from pinarms.robots.cell.collision import exact_min_distance

    every, _, _, _ = exact_min_distance(line, Q, n=len(pairs))  # all pairs, no pruning by group
    for name, idx in groups.items():
        lb = np.full((rows.size, len(pairs)), np.inf)
        lb[:, idx] = -np.inf  # every pair of the group computed
        view_d[name] = exact_min_distance(line, Q, lb=lb, n=len(pairs))[0]
        assert check.curves[name][rows] == pytest.approx(view_d[name], abs=1e-9)
        assert np.all(view_d[name] >= every - 1e-12)
    assert check.curve_pairs["left ↔ right"].kind == "arm-arm"


def test_without_curve_there_are_no_curves(line, left_moves):
    motion, _ = left_moves
    assert line.check_motion(motion, margin=0.01).curves == {}
