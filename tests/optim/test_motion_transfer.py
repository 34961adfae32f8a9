"""plan_cycle(..., cell=) falls back to a planned transfer when raising it cannot clear (a crate under a guard)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import optim
from pinarms.optim.motion import load_scene
from pinarms.optim.motion.transfer import PlannedMove
from pinarms.robots.cell.motion import joint_levers

from tests.optim.motion_helpers import BulletScene, dense_times

CLEARANCE = 0.01


@pytest.mark.slow
def test_crate_under_a_guard_gets_a_planned_transfer():
    cell = load_scene("aubo_crate_guard")
    arm = cell.arm("aubo")
    pick = arm.to_base(np.array([0.40, 0.10, 0.78]))  # on the food table
    place = arm.to_base(np.array([0.0, -0.46, 0.78]))  # in the crate's far half, past the guard plate
    spec = optim.PickPlace(pick, place, lift=0.05)
    result = optim.plan_cycle(optim.CycleRequest(arm.robot, spec, timing=optim.CycleTiming(amax=10.0),
                                                 cell=optim.CellSettings(cell, clearance=CLEARANCE, lift_step=0.1)))
    report = result.cell_report
    assert report.planned_transfer and result.status is optim.CycleStatus.TRANSFER_PLANNED
    # raising the transfer and via points were tried first, and none cleared
    assert len(report.attempts) >= 3 and not any(a[1] for a in report.attempts[:-1])
    assert "RRTConnect" in report.attempts[-1][0] and report.attempts[-1][1]
    assert report.min_clearance >= CLEARANCE
    assert all(isinstance(m, PlannedMove) for m in result.moves)
    traj = result.trajectory
    np.testing.assert_allclose(traj.sample(traj.start_time)[0], result.q_via[0], atol=1e-7)
    assert np.all(result.peaks.acceleration <= 10.0 * (1 + 1e-6))
    # PyBullet (its own kinematics and distances) over the whole cycle, every 2 mm of travel
    t = dense_times(traj, joint_levers(cell)[arm.q_slice], resolution=0.002)
    q = traj.sample(t)[0]
    bullet = BulletScene(cell, ["aubo"])
    try:
        d = np.empty(t.size)
        for i, qi in enumerate(q):
            bullet.set("aubo", qi)
            d[i] = bullet.distance("aubo")
    finally:
        bullet.close()
    assert d.min() >= CLEARANCE - 2e-5
    assert d.min() < 0.03  # it does pass close to the guard
