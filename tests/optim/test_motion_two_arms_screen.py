"""plan_around's delay screen rejects only delays the continuous proof rejects (scene aubo_two_belt)."""

from __future__ import annotations

import numpy as np

from pinarms.optim.motion import MotionChecker, MotionOptions, MotionRequest, MotionStatus, plan_motion
from pinarms.optim.motion.checker import TimedArm
from pinarms.optim.motion.two_arms import AroundRequest, _screened_delays, _waiting, plan_around

from tests.optim.test_motion_two_arms import MARGIN, _ik, _quintic, belt, stations  # noqa: F401 (fixtures)


def test_screened_delays_fail_the_proof_and_the_first_clear_delay_is_kept(belt, stations):  # noqa: F811
    hold, qa0, qb0 = stations
    vA = belt.arm("right").robot.velocity_limit
    qa1 = _ik(belt, "right", (0.0, 0.10, 0.84), hold)
    there = _quintic(qa0, qa1, vA)
    A = there.concatenated(_quintic(qa1, qa0, vA).shifted(there.duration))
    qb1 = _ik(belt, "left", (0.05, 0.10, 0.86), hold)
    request = MotionRequest(belt, "left", qb0, qb1, hold=hold, options=MotionOptions(seed=0, time_limit=20.0))
    around = plan_around(AroundRequest(request, {"right": A}))
    assert around.status is MotionStatus.SOLVED and around.delay > 0.0 and around.check.collision_free

    # the same path, every delay up to the kept one proven in turn, without the screen
    parked = hold.copy()
    parked[belt.arm("right").q_slice] = A.sample(A.end_time)[0]
    options = MotionOptions(margin=MARGIN, seed=0, time_limit=20.0, recheck=False)
    path = plan_motion(MotionRequest(belt, "left", qb0, qb1, options=options, hold=parked))
    assert np.array_equal(path.trajectory.coefficients, around.plan.trajectory.coefficients)
    together = MotionChecker(belt, ["left"], margin=MARGIN, hold=hold, moving=(TimedArm("right", A, 0.0),))
    delays = np.arange(0.0, A.duration + 0.05, 0.05)
    rejected = _screened_delays(together, path.trajectory, qb0, 0.0, delays, A.duration)
    proven = [together.trajectory_valid(_waiting(path.trajectory, qb0, 0.0, float(d)), 0.0).ok
              for d in delays[: around.delays_tried + 1]]
    first = proven.index(True)
    assert delays[first] == around.delay  # the screen changed nothing
    assert rejected[:first].sum() >= first // 2  # it did skip proofs
    assert not any(r and p for r, p in zip(rejected, proven))  # never a delay the proof accepts
