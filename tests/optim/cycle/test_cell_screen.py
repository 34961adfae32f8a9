"""The screens of a cycle in a cell (exact distances at via points and timed states) reject only
what the continuous check rejects: screened and unscreened plans keep the same cycle."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pinarms import optim
from pinarms.optim.cycle import CellSettings, CycleRequest
from pinarms.optim.motion.scenes import scene_path
from pinarms.optim.motion.transfer import _joined
from pinarms.planning import Trajectory
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.errors import CollisionError

PICK, CRATE = np.array([0.36, 0.0, 0.75]), np.array([0.0, -0.42, 0.77])


@pytest.fixture(scope="module")
def station():
    return load_cell("aubo_food_station")


def _plan(cell, pick, place, **settings):
    arm = cell.arm("aubo")
    spec = optim.PickPlace(arm.to_base(pick), arm.to_base(place), lift=0.05, dwell=0.2)
    return optim.plan_cycle(CycleRequest(arm.robot, spec, cell=CellSettings(cell, clearance=0.02, **settings)))


def test_screened_and_unscreened_cycles_are_the_same(station):
    full = _plan(station, PICK, CRATE, screen=False)
    fast = _plan(station, PICK, CRATE, recheck=False)
    assert fast.status is full.status is optim.CycleStatus.REPLANNED
    assert fast.cycle_time == full.cycle_time  # bit for bit: the same attempt kept, timed alike
    assert np.array_equal(fast.q_via, full.q_via)
    assert [a[1] for a in fast.cell_report.attempts] == [a[1] for a in full.cell_report.attempts]
    assert fast.cell_report.lift == full.cell_report.lift
    # reported from the check that kept it: proven above the clearance, at most the exact minimum
    assert 0.02 <= fast.cell_report.lower_bound <= fast.cell_report.min_clearance
    assert 0.02 <= fast.cell_report.min_clearance <= full.cell_report.min_clearance + 1e-9
    # the kept cycle passes the cell's own continuous check
    check = station.with_pairs("external").check_motion([ArmMotion("aubo", fast.trajectory)], margin=0.005,
                                                        clearance=0.02)
    assert check.clear


def test_an_attempt_rejected_at_a_via_point_is_recorded_and_named():
    cell = load_cell(scene_path("aubo_crate_guard"))
    arm = cell.arm("aubo")
    spec = optim.PickPlace(arm.to_base(np.array([0.40, 0.10, 0.78])), arm.to_base(np.array([0.0, -0.46, 0.78])),
                           lift=0.05, dwell=0.2)
    settings = CellSettings(cell, clearance=0.02, plan_transfer=False)
    with pytest.raises(CollisionError, match="guard_plate blocks") as err:
        optim.plan_cycle(CycleRequest(arm.robot, spec, cell=settings))
    assert "at a via point" in str(err.value)
    # every attempt is there: the screens skip the timing and the checks, not the attempts
    assert int(str(err.value).split(" after ")[1].split()[0]) >= 10
    # a raised lift puts a via point closer than the clearance (what the screen rejects untimed)
    from pinarms.optim.cycle.joint import via_points

    last = dataclasses.replace(spec, lift=0.05 + 0.02 * 9)
    q = via_points(arm.robot, last.poses(arm.robot), last.names, None)[0]
    Q = np.repeat(cell.neutral[None], len(q), axis=0)
    Q[:, arm.q_slice] = q
    assert cell.with_pairs("external").clearance(Q).distance.min() < 0.02


def test_joined_is_concatenated_in_turn():
    rng = np.random.default_rng(4)
    pieces, q = [], np.zeros(3)
    for k in range(4):
        m = 2 + k
        coefs = rng.normal(size=(m, 4 + k % 2, 3))
        coefs[:, 0] = 0.0
        for i in range(m):  # continuous: each piece starts where the previous ends
            coefs[i, 0] = q
            q = q + coefs[i, 1:].sum(axis=0)
        pieces.append(Trajectory(np.arange(m + 1, dtype=float) + 10.0 * k, coefs))  # pieces of 1 s
    turn = pieces[0]
    for p in pieces[1:]:
        turn = turn.concatenated(p, atol=1e-7)
    got = _joined(pieces)
    assert np.array_equal(got.knot_times, turn.knot_times)
    assert np.array_equal(got.coefficients, turn.coefficients)
    assert got.definition == turn.definition
    bad = Trajectory(np.array([0.0, 1.0]), np.ones((1, 2, 3)))
    with pytest.raises(Exception, match="position jump"):
        _joined([pieces[0], bad])


@pytest.mark.slow
def test_layout_search_screened_and_not_agree_on_every_candidate(station):
    # the cell's placement, 250 mm towards the crate (collides), out of reach, and three seeded ones
    cand = np.vstack([[[0.0, 0.0, 0.7, 0.0], [0.0, -0.25, 0.7, 0.0], [0.9, 0.0, 0.7, 0.0]],
                      optim.random_candidates(3, x=(-0.06, 0.06), y=(-0.06, 0.06), z=0.7, yaw=(-0.2, 0.2), seed=3)])
    kw = dict(refine=0, carry=("stand",), workspace_samples=2000)
    fast = optim.search_layout(optim.LayoutRequest(station, PICK, CRATE, cand, **kw))
    full = optim.search_layout(optim.LayoutRequest(station, PICK, CRATE, cand, screen=False, **kw))
    assert fast.failure == full.failure
    assert fast.failure[:3] == (None, "collision", "unreachable")
    ok = np.array([not f for f in fast.failure])
    assert ok.sum() >= 3
    assert np.array_equal(fast.cycle_time[ok], full.cycle_time[ok])


def test_the_branch_screen_rejects_only_what_the_via_points_reject(monkeypatch):
    """Every IK solution of a waypoint closer than the clearance: so is the via point on the cycle's branch."""
    from pinarms.optim.cycle import in_cell

    cell = load_cell(scene_path("aubo_crate_guard"))
    arm = cell.arm("aubo")
    spec = optim.PickPlace(arm.to_base(np.array([0.40, 0.10, 0.78])), arm.to_base(np.array([0.0, -0.46, 0.78])),
                           lift=0.05, dwell=0.2)
    settings = CellSettings(cell, clearance=0.02, plan_transfer=False)
    reports = {}
    for branches in (False, True):
        monkeypatch.setattr(in_cell, "SCREEN_BRANCHES", branches)
        with pytest.raises(CollisionError, match="guard_plate blocks") as err:
            optim.plan_cycle(CycleRequest(arm.robot, spec, cell=settings))
        reports[branches] = str(err.value)
    # the same attempts, each failing: the error counts them and names the last
    count = [int(reports[b].split(" after ")[1].split()[0]) for b in (False, True)]
    assert count[0] == count[1] >= 10
    assert reports[False].split(", the last with ")[1] == reports[True].split(", the last with ")[1]
    # the best solution of a rejected waypoint is at least as far as the one the via points take
    trials = in_cell._Trials(CycleRequest(arm.robot, spec, cell=settings), arm, cell.neutral.copy())
    last = dataclasses.replace(spec, lift=0.05 + 0.02 * 9)
    assert not trials.branches_screened("lift", last.poses(arm.robot)[1:-1])
    from pinarms.optim.cycle.joint import via_points

    q = via_points(arm.robot, last.poses(arm.robot), last.names, None)[0]
    Q = np.repeat(cell.neutral[None], len(q), axis=0)
    Q[:, arm.q_slice] = q
    assert trials.attempts[-1][2] >= cell.with_pairs("external").clearance(Q).distance.min() - 1e-12
    # the pick's own solutions: one of them keeps the clearance (the pick is proven clear), so no rejection
    assert trials.branches_screened("pick", last.poses(arm.robot)[:1])
    # screened ahead in one batch: the same verdicts and records as one at a time
    ahead = in_cell._Trials(CycleRequest(arm.robot, spec, cell=settings), arm, cell.neutral.copy())
    lifts = [dataclasses.replace(spec, lift=0.05 + 0.02 * k) for k in (1, 9, 2)]
    ahead.prescreen([(f"lift {k}", s) for k, s in enumerate(lifts)])
    alone = in_cell._Trials(CycleRequest(arm.robot, spec, cell=settings), arm, cell.neutral.copy())
    for k, s in enumerate(lifts):
        poses = s.poses(arm.robot)[1:-1]
        assert ahead.branches_screened(f"lift {k}", poses) == alone.branches_screened(f"lift {k}", poses)
    assert ahead.attempts == alone.attempts and len(ahead.attempts) >= 1 and not ahead._ahead


def test_a_cycle_stopped_after_its_move_to_place_is_the_same_cycle_when_let_through(station):
    """joint_cycle's hook: the move to place first (the screen may stop it there), then the move back."""
    from pinarms.optim.cycle.joint import via_points, joint_cycle

    arm = station.arm("aubo")
    spec = optim.PickPlace(arm.to_base(PICK), arm.to_base(CRATE), lift=0.05, dwell=0.2)
    request = CycleRequest(arm.robot, spec)
    seen = []
    assert joint_cycle(request, there_clear=lambda move: seen.append(move) or False) is None
    whole = joint_cycle(request)
    via = via_points(arm.robot, spec.poses(arm.robot), spec.names, None)
    let = joint_cycle(request, via=via, there_clear=lambda move: True)
    assert let.cycle_time == whole.cycle_time and np.array_equal(let.q_via, whole.q_via)
    # the move it was shown is the cycle's move to place
    move = whole.moves[0].trajectory
    assert seen[0].end_time - seen[0].start_time == move.end_time - move.start_time
