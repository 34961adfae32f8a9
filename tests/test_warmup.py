"""pinarms.warmup (``pinarms warm``): every kernel compiled ahead into numba's cache, loaded afterwards.

The warm-up's coverage is checked by numba's own counters, not by timing: after :func:`warm`, a
new process that warms up again and then solves and plans other problems compiles no kernel (every
signature it needs is a cache hit) and no kernel is left without a signature.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from pinarms import warmup

ROOT = Path(__file__).resolve().parents[1]
#: the repository's folders and the packages they install as (pyproject.toml's package-dir)
FOLDERS = {"pinarms": "pinarms", "robots": "pinarms.robots", "planning": "pinarms.planning",
           "optim": "pinarms.optim", "viz": "pinarms.viz"}


def _modules_that_compile() -> set[str]:
    """Modules whose source decorates or wraps a function with pinarms.compiled's ``jit`` / ``jit_inline``
    (read as text: nothing imported)."""
    found = set()
    for folder, package in FOLDERS.items():
        for path in (ROOT / folder).rglob("*.py"):
            text = path.read_text(encoding="utf-8")
            if path.name != "compiled.py" and re.search(r"^@jit(_inline)?\s*$|\bjit\(", text, re.MULTILINE):
                parts = path.relative_to(ROOT / folder).with_suffix("").parts
                found.add(".".join((package, *parts)))
    return found


def test_every_module_that_compiles_kernels_is_warmed():
    assert _modules_that_compile() == set(warmup.KERNEL_MODULES)


def test_cached_signatures_counts_what_numba_keeps_on_disk(tmp_path, monkeypatch):
    """A kernel called with an int and then a float is cached for two signatures."""
    import importlib

    (tmp_path / "one_kernel.py").write_text("from pinarms.compiled import jit\n\n@jit\ndef twice(x):\n    return 2 * x\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("one_kernel")
    assert warmup.cached_signatures(module.twice) == 0
    module.twice(1)
    assert warmup.cached_signatures(module.twice) == 1
    module.twice(1.5)
    assert warmup.cached_signatures(module.twice) == 2
    assert warmup.cached_signatures(object()) == 0


def test_every_kernel_module_holds_kernels_compiled_on_their_own():
    names = warmup.kernels()
    for module in warmup.KERNEL_MODULES:
        assert any(n.startswith(module + ".") for n in names), module
    assert "pinarms.robots.cell.ladder.interval_proven" in names
    inlined = set(warmup.kernels(inlined=True)) - set(names)
    assert "pinarms.robots.ik._chain.fk" in inlined  # inlined into its callers, never compiled alone


_SECOND_PROCESS = """
import json
import numpy as np
from pinarms import optim, robots, warmup
from pinarms.optim.motion import SCENES, load_scene
from pinarms.optim.motion.scenes import region_pose

result = warmup.warm(processes=1)  # in this process: every kernel loaded here
# another arm, another goal, every goal branch searched
panda = robots.load("panda")
T = panda.fk(panda.neutral)
panda.ik(T), panda.ik(np.stack([T, T]), position_only=True)
scene = SCENES["aubo_crate_guard"]
cell = load_scene(scene.name)
region = scene.region("food table")
goal = region_pose(region, [(a + b) / 2 for a, b in zip(region.lo, region.hi)])
options = optim.MotionOptions(margin=0.02, time_limit=1.0, seed=1, goals="best")
optim.plan_motion(optim.MotionRequest(cell, scene.arm, cell.neutral, goal, options=options))
print(json.dumps({"warm": result.as_dict(), "compiled": result.compiled, "after": warmup.cache_misses()}))
"""


def test_the_steps_are_shared_out_longest_first():
    labels = [label for label, _ in warmup.STEPS]
    assert set(warmup.STEP_COST) == set(labels)
    two = warmup.plan_processes(2)
    assert two == [["motion planning"], [label for label in labels if label != "motion planning"]]
    for n in (1, 2, 3, 4, 9):
        plan = warmup.plan_processes(n)
        assert len(plan) == min(n, len(labels)) and all(plan)
        assert sorted(label for part in plan for label in part) == sorted(labels)  # each step once
        assert all(part == sorted(part, key=labels.index) for part in plan)
    assert warmup.plan_processes(2, {"inverse kinematics": 10.0}) == [
        ["inverse kinematics"], [label for label in labels if label != "inverse kinematics"]]
    with pytest.raises(ValueError, match="processes must be at least 1"):
        warmup.plan_processes(0)


@pytest.mark.slow
def test_after_the_warm_up_no_kernel_compiles_again():
    """Warm up here in parallel processes (minutes on a fresh checkout, seconds once cached), then a new process
    warms up in itself and loads every kernel it needs, for the warm-up's calls and for other calls (another arm's
    IK, another plan), from numba's cache."""
    first = warmup.warm(processes=2)
    assert first.missing == () and first.processes == 2
    assert [s.label for s in first.steps] == [label for label, _ in warmup.STEPS]
    assert first.seconds >= max(s.seconds for s in first.steps)  # the wall time spans every step
    # one compile per kernel (checked where this warm-up compiles, as on a fresh checkout): the IK descent was
    # compiled once per phase constant (numba literals), the cover's excess once more for a module's read-only empty
    # array, the spline proof's search for a path's read-only breaks; left: the cover's excess, for the cover's
    # scratch arrays and for the search's (which hold the moving arm's too)
    assert set(first.repeated) <= {"pinarms.robots.cell.cover_kernel.excess_placed"}
    out = subprocess.run([sys.executable, "-c", _SECOND_PROCESS], capture_output=True, text=True, timeout=600,
                         cwd=ROOT)
    assert out.returncode == 0, out.stderr[-2000:]
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["compiled"] == 0 and got["warm"]["missing"] == []
    assert got["after"] == 0, "a later call compiled a kernel signature the warm-up did not"
