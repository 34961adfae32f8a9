"""Counts, seeds and paths past their documented range: refused at once (within 5 s) with a named error,
never a run that would take as long as the count asks (IK restarts, GA generations, planner seeds, paths
with a NUL byte or too long)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import optim, robots


def _quickly(call, error, match):
    import time

    t0 = time.perf_counter()
    with pytest.raises(error, match=match):
        call()
    assert time.perf_counter() - t0 < 5.0


def test_ik_restarts_past_the_cap_are_refused_at_once():
    from pinarms.robots import MAX_RESTARTS
    from pinarms.errors import InvalidInput
    from pinarms.robots.ik import NumericalIK

    ur5 = robots.load("ur5")
    far = ur5.fk(ur5.neutral)
    far[0, 3] = 5.0  # out of reach: every restart would run
    _quickly(lambda: ur5.ik(far, max_restarts=10**9), InvalidInput, f"max_restarts.*{MAX_RESTARTS}")
    _quickly(lambda: ur5.ik(np.stack([far, far]), max_restarts=MAX_RESTARTS + 1), InvalidInput, "max_restarts")
    _quickly(lambda: NumericalIK(ur5).solve(far, max_restarts=10**9), InvalidInput, "max_restarts")
    _quickly(lambda: robots.reachability_map(robots.ReachabilityRequest(ur5, 0.5, restarts=10**9)), InvalidInput, "restarts")


def test_minimize_time_max_generations_outside_its_documented_range_is_refused():
    from pinarms.optim.errors import SettingOutOfRange

    via = np.array([[0.0], [1.0], [0.5]])
    for bad in (0, -1, 10**9):
        _quickly(lambda bad=bad: optim.minimize_time(optim.TimingRequest(via, "multi-quintic", 1.0, max_generations=bad)),
                 SettingOutOfRange, "max_generations")


@pytest.mark.parametrize("seed", [-1, 2**64, 1.5])
def test_plan_motion_seed_outside_its_range_is_a_named_error(seed):
    from pinarms.optim.errors import InvalidSettings
    from pinarms.optim.motion import MotionOptions

    _quickly(lambda: MotionOptions(seed=seed), InvalidSettings, "seed")


@pytest.mark.parametrize("path", ["arm\0.urdf", "a" * 300 + ".urdf", "d/" * 3000 + "arm.urdf"])
@pytest.mark.parametrize("load", ["from_urdf", "load_cell", "from_xacro"])
def test_a_description_path_with_a_nul_byte_or_too_long_is_a_named_error(load, path):
    from pinarms.errors import InvalidInput

    path = path.replace(".urdf", ".xacro") if load == "from_xacro" else path
    _quickly(lambda: getattr(robots, load)(path), InvalidInput, "NUL byte|too long")
