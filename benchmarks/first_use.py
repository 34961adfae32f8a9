"""First use on a fresh install: the first IK and the first motion plan of a process, cold and warm.

Run: python benchmarks/first_use.py [--skip-cold]
The package is copied, as a wheel lays it out and without any numba cache, into a temporary
folder (the checkout's own caches are neither read nor touched), and each measurement runs in a
new Python process on that copy:

  * cold: numba's cache empty, as after ``pip install`` without ``pinarms warm``: the first IK
    call (the README's quick start, numerical IK of the koji turner) and, on a second fresh copy,
    the first ``plan_motion`` (docs/motion.md's example, AUBO-i3 under a crate guard);
  * ``pinarms warm`` on a third fresh copy (what ``make install`` runs) and a second ``pinarms warm``
    (kernels loaded only);
  * warm: after that, the first IK and the first plan of new processes.

Each figure is printed against the goal (first IK <= 5 s, first plan <= 20 s on a fresh install,
that is: after the install's warm-up). The cold runs take minutes on two cores (``--skip-cold``
leaves them out). Wall times on a shared machine vary: the load average is printed with them.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: pyproject.toml's package-dir: the checkout's folders and where a wheel puts them
LAYOUT = (("pinarms", "pinarms"), ("robots", "pinarms/robots"), ("urdf", "pinarms/urdf"),
          ("planning", "pinarms/planning"), ("optim", "pinarms/optim"), ("viz", "pinarms/viz"))
GOALS = {"first IK": 5.0, "first plan": 20.0}

FIRST_IK = """
import time
import numpy as np
from pinarms import robots
arm = robots.load("koji_turner")
T = arm.fk(np.radians([-90.0, 25.0, -30.0, 90.0]))
start, cpu = time.perf_counter(), time.process_time()
arm.ik(T, position_only=True)
print(time.perf_counter() - start, time.process_time() - cpu)
"""

FIRST_PLAN = """
import time
from pinarms import optim
from pinarms.optim.motion import SCENES, load_scene
from pinarms.optim.motion.scenes import region_pose
cell = load_scene("aubo_crate_guard")
goal = region_pose(SCENES["aubo_crate_guard"].regions[1], [0.0, -0.465, 0.78])
start, cpu = time.perf_counter(), time.process_time()
options = optim.MotionOptions(margin=0.01, planner="rrtconnect", time_limit=2.0, seed=0)
optim.plan_motion(optim.MotionRequest(cell, "aubo", cell.neutral, goal, options=options))
print(time.perf_counter() - start, time.process_time() - cpu)
"""

WARM = "from pinarms.warmup import warm; warm()"


def fresh_copy(into: Path) -> Path:
    """The package as a wheel lays it out, without ``__pycache__`` (no numba cache), under ``into``."""
    for folder, target in LAYOUT:
        shutil.copytree(ROOT / folder, into / target, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    return into


def run(code: str, where: Path) -> tuple[float, str]:
    """Wall time [s] of a new process running ``code`` on the copy ``where``, and its last output line."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["PYTHONPATH"] = str(where)
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code], cwd=where, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if out.returncode:
        raise RuntimeError(f"failed: {out.stderr.strip().splitlines()[-1:]}")
    lines = out.stdout.strip().splitlines()
    return wall, lines[-1] if lines else ""


def report(label: str, seconds: float, goal: float | None = None, cpu: float | None = None) -> None:
    """One figure [s] against its goal, with the load average (and the call's own CPU seconds: what a machine
    with a free core would take, about)."""
    load = os.getloadavg()[0]
    verdict = "" if goal is None else (f"  goal <= {goal:.0f} s: " + ("met" if seconds <= goal else "NOT met"))
    spent = "" if cpu is None else f", {cpu:.1f} s CPU"
    print(f"{label:<34} {seconds:8.1f} s   (load {load:.1f}{spent}){verdict}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-cold", action="store_true", help="leave out the cold first IK and first plan")
    args = parser.parse_args()
    print(f"{os.cpu_count()} cores, Python {sys.version.split()[0]}")
    with tempfile.TemporaryDirectory(prefix="pinarms-first-use-") as tmp:
        tmp = Path(tmp)
        if not args.skip_cold:
            for name, code in (("first IK", FIRST_IK), ("first plan", FIRST_PLAN)):
                try:
                    _, call = run(code, fresh_copy(tmp / f"cold-{name.split()[1]}"))
                    wall, cpu = (float(v) for v in call.split())
                    report(f"cold {name} (no warm-up)", wall, cpu=cpu)
                except RuntimeError as exc:
                    print(f"cold {name}: {exc}")
        installed = fresh_copy(tmp / "installed")
        try:
            report("pinarms warm (install step)", run(WARM, installed)[0])
            report("pinarms warm again (loads only)", run(WARM, installed)[0])
            for name, code in (("first IK", FIRST_IK), ("first plan", FIRST_PLAN)):
                wall, call = run(code, installed)
                seconds, cpu = (float(v) for v in call.split())
                report(f"{name} after the warm-up", seconds, GOALS[name], cpu=cpu)
                report(f"  the whole process (import, load)", wall)
        except RuntimeError as exc:
            print(f"warm-up: {exc}")


if __name__ == "__main__":
    main()
