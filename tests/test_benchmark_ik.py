"""``benchmarks/ik.py`` section 2 times pinarms and the Robotics Toolbox's ``ik_LM`` interleaved, target by target."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

from pinarms import robots

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "ik.py"


def _script():
    spec = importlib.util.spec_from_file_location("benchmark_ik", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class _Peer:
    """Stands in for ik_LM (the Robotics Toolbox is not a test dependency): records when it is called."""

    def __init__(self, calls, robot):
        self.calls, self.robot = calls, robot

    def ik_LM(self, T, tol, joint_limits):
        self.calls.append("peer")
        return (np.zeros(self.robot.nq),)


def test_single_targets_alternate_between_the_two_tools(monkeypatch):
    bench = _script()
    robot = robots.load("ur5")
    T = robot.fk(robot.random_q(4, seed=0))
    calls = []
    real = robot.ik

    def ours(target, **kw):
        calls.append("pinarms")
        return real(target, **kw)

    monkeypatch.setattr(robot, "ik", ours)
    out = bench.one_at_a_time(robot, _Peer(calls, robot), T)
    assert calls == ["pinarms", "peer", "peer", "pinarms", "pinarms", "peer", "peer", "pinarms"]
    assert out["pinarms"][2] == 1.0 and out["rtb"][2] == 0.0  # zeros solve none of the targets
