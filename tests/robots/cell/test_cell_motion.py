"""Continuous collision checks of the arms of a cell moving together."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.robots.cell.motion import configurations
from pinarms.errors import InvalidInput

UP = np.array([0.0, 0.0, -0.13, 0.0])  # SCARA j3 up by 0.13 m


@pytest.fixture(scope="module")
def line():
    return load_cell("mushroom_line")


def ik(cell, arm, point):
    a = cell.arm(arm)
    return a.robot.ik(a.to_base(np.asarray(point, dtype=float)), position_only=True)


def cycle(pick, place, lift=True):
    if not lift:
        return planning.multi_quintic([0.0, 1.0], np.array([pick, place]))
    return planning.multi_quintic(
        [0.0, 0.3, 1.3, 1.6, 1.9, 2.9, 3.2], np.array([pick, pick + UP, place + UP, place, place + UP, pick + UP, pick])
    )


@pytest.fixture(scope="module")
def cycles(line):
    left = cycle(ik(line, "left", (-0.05, -0.03, 0.84)), ik(line, "left", (0.22, 0.68, 0.84)))
    right = cycle(ik(line, "right", (0.05, 0.03, 0.84)), ik(line, "right", (0.22, -0.68, 0.84)))
    return left, right


def dense(cell, motions, window, step=2e-4):
    """Distances on a grid far finer than the check's (the reference the proofs must respect)."""
    t = np.arange(window[0], window[1] + step / 2, step)
    Q = configurations(cell, motions, t, cell.neutral)
    return t, cell.clearance(Q).distance


def test_a_move_through_the_packing_box_wall_reports_the_wall_first(line):
    pick, place = ik(line, "left", (-0.05, -0.03, 0.84)), ik(line, "left", (0.22, 0.68, 0.84))
    straight = cycle(pick, place, lift=False)
    result = line.check_motion({"left": straight}, margin=0.01)
    assert not result.collision_free and not result.clear
    contact = result.first_contact
    assert contact.pair.owner_a == "left" and contact.pair.body_b.startswith("left_box_wall")
    t, d = dense(line, [ArmMotion("left", straight)], (0.0, 1.0))
    first_dense = t[np.argmax(d <= 0.0)]
    assert abs(contact.time - first_dense) <= 2e-4 + 1e-6
    assert result.max_depth > 0.005
    assert "CONTACT at t = " in result.summary() and str(contact.pair.body_b) in result.summary()


def test_the_lifted_cycle_is_proven_clear_and_the_proof_holds_densely(line, cycles):
    left, _ = cycles
    motion = [ArmMotion("left", left)]
    result = line.check_motion(motion, margin=0.01, clearance=0.005)
    assert result.collision_free and result.clear and result.first_contact is None
    t, d = dense(line, motion, (0.0, left.end_time), step=5e-4)
    assert d.min() > 0.005
    assert result.lower_bound <= d.min() + 1e-9  # a proven bound never exceeds the truth
    assert result.lower_bound >= 0.005


def test_samples_follow_the_approach_budget(line, cycles):
    left, _ = cycles
    result = line.check_motion([ArmMotion("left", left)], margin=0.01, curve=True)
    assert result.exact.all()
    # dense where the arm moves fast, sparse where it is slow: far fewer samples than the
    # global bound's uniform step would take
    assert result.n_samples < 0.8 * (left.duration / result.dt)


@pytest.mark.parametrize("offset, free", [(0.0, False), (1.6, True)])
def test_two_arm_offsets_decide_whether_they_collide_over_the_belt(line, cycles, offset, free):
    left, right = cycles
    motions = [ArmMotion("left", left, 0.0, 3.2), ArmMotion("right", right, offset, 3.2)]
    result = line.check_motion(motions, margin=0.01)
    assert result.collision_free is free
    t, d = dense(line, motions, (0.0, 3.2), step=1e-3)
    assert bool(d.min() > 0.0) is free
    if not free:
        assert result.first_contact.pair.kind == "arm-arm"
    else:
        assert result.lower_bound <= d.min() + 1e-9


def test_random_motions_never_contradict_the_proof(line):
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(4):
        q = line.random_q(3, seed=rng)
        traj_l = planning.multi_quintic([0.0, 0.7, 1.4], q[:, :4])
        traj_r = planning.multi_quintic([0.0, 0.7, 1.4], q[:, 4:])
        motions = [ArmMotion("left", traj_l), ArmMotion("right", traj_r)]
        result = line.check_motion(motions, margin=0.02)
        t, d = dense(line, motions, (0.0, 1.4), step=1e-3)
        if result.collision_free:
            assert d.min() > 0.0
            checked += 1
        else:
            assert result.first_contact is not None or result.lower_bound <= 0.0
        if result.first_contact is None:
            assert result.lower_bound <= d.min() + 1e-9
        else:  # the dense grid finds the contact too, no earlier than the reported time
            assert d.min() <= 0.0 and t[np.argmax(d <= 0.0)] >= result.first_contact.time - 1e-3
    assert checked >= 1


def test_motion_inputs_are_checked(line, cycles):
    left, _ = cycles
    with pytest.raises(InvalidInput, match="arms: left, right"):
        line.check_motion({"middle": left})
    with pytest.raises(InvalidInput, match="has 3 joints"):
        line.check_motion({"left": planning.multi_quintic([0.0, 1.0], np.zeros((2, 3)))})
    with pytest.raises(InvalidInput, match="margin"):
        line.check_motion({"left": left}, margin=0.0)
    with pytest.raises(InvalidInput, match="period"):
        line.check_motion([ArmMotion("left", left, 0.0, 1.0)])


def every_pair_distance(cell, motions, t, hold):
    """``(len(t), P)``: coal's distance of every candidate pair of the cell (no pruning) at times ``t``."""
    import pinocchio as pin

    n = len(cell._candidates)
    Q = cell.robot.q_to_pinocchio(configurations(cell, motions, t, hold))
    gm, gd, data = cell._views.geometry(n), cell._views.distance_data(n), cell._views.data()
    out = np.empty((t.size, n))
    for i in range(t.size):
        pin.updateGeometryPlacements(cell.model, data, gm, gd, Q[i])
        pin.computeDistances(gm, gd)
        out[i] = [r.min_distance for r in gd.distanceResults]
    return out


def approach_budget_holds(cell, motions, window, step, hold=None):
    """Every candidate pair's distance changes between two dense times by at most the check's approach budget."""
    from pinarms.robots.cell import motion as cell_motion

    schedule = cell_motion._schedule(cell, motions, window[0], window[1], 0.01)
    t = np.arange(window[0], window[1] + step / 2, step)
    D = every_pair_distance(cell, motions, t, cell.neutral if hold is None else hold)
    allowed = schedule.budget_between(t[:-1], t[1:])
    change = np.abs(np.diff(D, axis=0))
    assert np.all(change <= allowed[:, None] * (1 + 1e-9) + 5e-6)  # coal's GJK tolerance
    return schedule, change, allowed


def test_two_arms_approach_at_most_at_the_sum_of_their_speed_bounds(line, cycles):
    """The approach budget of two moving arms is their two bounds summed, and no pair's distance outruns it."""
    from pinarms.robots.cell.speed_bound import joint_levers

    left, right = cycles
    motions = [ArmMotion("left", left, 0.0, 3.2), ArmMotion("right", right, 1.6, 3.2)]
    schedule, change, allowed = approach_budget_holds(line, motions, (0.0, 3.2), 4e-3)
    levers = joint_levers(line)
    caps = [float(np.abs(tr.peaks().velocity) @ levers[line.arm(a).q_slice]) for a, tr in (("left", left), ("right", right))]
    assert schedule.speed_bound == pytest.approx(sum(caps), rel=1e-12)  # not twice the faster one
    assert change.max() > 0.2 * allowed.max()  # the arms do move towards things
