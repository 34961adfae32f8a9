"""Compile every numba kernel once, ahead of first use, into numba's on-disk cache (``pinarms warm``).

pinarms' compiled kernels (:mod:`pinarms.compiled`) are compiled on their first call and cached
on disk; without a cache the first numerical IK of a process takes about a minute and a half and
the first ``plan_motion`` several minutes on two cores. :func:`warm` makes the calls that compile
them all, with the argument types the library really passes (a numerical IK, one and a batch,
position only and full pose; a compiled motion plan in a cell, which runs the sphere cover, the
search, the spline proof and the time-optimal timing; the sphere cover's other entries), so that
every later process loads them from the cache (about a second). ``make install`` runs it
(``pinarms warm``); a second run loads everything and compiles nothing.

The steps run in parallel, one process per core (:func:`plan_processes`: the longest step first,
each next step to the process with the least work, by :data:`STEP_COST`); numba writes each cache
file atomically (a temporary file renamed), so two processes that compile the same small callee
both leave a whole file. On two cores the motion plan's kernels compile in one process while the
IK's, the cover's and the line simulator's compile in the other.

:func:`kernels` lists every kernel of :data:`KERNEL_MODULES` by name; :func:`cache_misses` counts
the signatures numba compiled in this process (a signature loaded from the cache is a hit), which is
how :class:`WarmResult` tells compiled from loaded, and how the tests check that after a warm-up
no kernel is compiled again.
"""

from __future__ import annotations

import importlib
import json
import os
import queue
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["KERNEL_MODULES", "WarmStep", "WarmResult", "kernels", "cached_signatures", "cache_misses", "warm",
           "STEPS", "STEP_COST", "plan_processes", "cores"]

#: Every module holding kernels of :func:`pinarms.compiled.jit` (the ladder compiles its rule on first access).
KERNEL_MODULES = (
    "pinarms.robots.ik._chain",
    "pinarms.robots.ik._limits_kernel",
    "pinarms.robots.ik._kernel",
    "pinarms.robots.cell.box_kernel",
    "pinarms.robots.cell.cover_kernel",
    "pinarms.robots.cell._pair_kernel",
    "pinarms.robots.cell.ladder",
    "pinarms.optim.motion._fast_kernel",
    "pinarms.optim.motion._spline_kernel",
    "pinarms.optim.topp._profile_kernel",
    "pinarms.optim.line._sim_kernel",
    "pinarms.planning.extrema_kernel",
)


def _is_kernel(obj: Any) -> bool:
    from numba.core.registry import CPUDispatcher

    return isinstance(obj, CPUDispatcher)


def kernels(inlined: bool = False) -> dict[str, Any]:
    """Every kernel of :data:`KERNEL_MODULES`, ``"module.function"`` → numba dispatcher (imports them).

    ``inlined=False`` leaves out the kernels numba inlines into their callers (``jit_inline``):
    they are never compiled on their own.
    """
    found: dict[str, Any] = {}
    for name in KERNEL_MODULES:
        module = importlib.import_module(name)
        if name.endswith(".ladder"):
            getattr(module, "interval_proven")  # compiled on first access
        for attr, obj in vars(module).items():
            if not _is_kernel(obj) or obj.py_func.__module__ != name:
                continue
            if not inlined and obj.targetoptions.get("inline") == "always":
                continue
            found[f"{name}.{attr}"] = obj
    return found


def cached_signatures(kernel: Any) -> int:
    """Signatures of ``kernel`` in numba's disk cache (0 where it has no cache or it cannot be read)."""
    try:
        return len(kernel._cache._cache_file._load_index())
    except (AttributeError, OSError, EOFError):
        return 0


def cache_misses() -> int:
    """Signatures of the kernels compiled in this process (not found in numba's disk cache)."""
    return sum(sum(k.stats.cache_misses.values()) for k in kernels().values())


def _ik() -> None:
    """Numerical IK: one target and a batch, full pose and position only (the compiled solver's four entries)."""
    from pinarms import robots

    for name, position_only in (("ur5", False), ("koji_turner", True)):
        arm = robots.load(name)
        q = np.clip(np.full(arm.nq, 0.3), arm.lower, arm.upper)
        T = arm.fk(q)
        arm.ik(T, position_only=position_only)
        arm.ik(np.stack([T, T]), position_only=position_only)


def _plan() -> None:
    """A compiled motion plan (docs/motion.md's example): cover, search, spline proof, timing."""
    from pinarms import optim
    from pinarms.optim.motion import SCENES, load_scene
    from pinarms.optim.motion.scenes import region_pose

    cell = load_scene("aubo_crate_guard")
    crate = SCENES["aubo_crate_guard"].regions[1]
    goal = region_pose(crate, [0.0, -0.465, 0.78])
    options = optim.MotionOptions(margin=0.01, planner="rrtconnect", time_limit=2.0, seed=0)
    optim.plan_motion(optim.MotionRequest(cell, "aubo", cell.neutral, goal, options=options))


def _cover() -> None:
    """The sphere cover's own entries outside the search: world centres, the excess, a cylinder's gap to a box."""
    from pinarms.optim.motion import load_scene
    from pinarms.robots.cell.box_kernel import cylinder_box_gap
    from pinarms.robots.cell.cover import link_cover, pair_arrays, pairs_for

    cell = load_scene("aubo_crate_guard")
    cover = link_cover(cell)
    Q = np.atleast_2d(cell.neutral)
    cover.world_centers(Q)
    a, b = pair_arrays(pairs_for(cell, 0.01))
    cover.excess(Q, cover.prepare(a, b), np.full(a.size, 0.01))
    cylinder_box_gap(np.zeros(3), np.array([0.0, 0.0, 0.1]), 0.05, np.eye(3), np.array([0.0, 0.0, 1.0]),
                      np.full(3, 0.1))


def _line() -> None:
    """The line simulator's compiled loop: two arms on a synthetic map, first in window and look-ahead."""
    from pinarms.optim.line import Belt, Rule, SimArm, TaskMap, poisson_items, simulate

    belt = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)
    du, w = np.linspace(-0.3, 0.3, 5), np.array([-0.15, 0.15])
    m = TaskMap("warm", du, w, np.full((5, 2), 0.4), np.tile([0.3, 1.5], (5, 1)), 0.5, 0.1, 0.2, 0.1)
    arms = [SimArm("a", 1.0, (m,)), SimArm("b", 1.8, (m,))]
    for rule in ("first", Rule("lookahead", 3)):
        simulate(arms, poisson_items(belt, 1.0, 20.0, seed=0), 0.2, rule, duration=20.0)


def _timing() -> None:
    """A trajectory's exact peaks and an exact multi-quintic timing (the compiled peaks of both)."""
    from pinarms import optim

    q = np.array([[0.0, 0.0], [0.1, 0.5], [0.4, 0.6]])
    optim.minimize_time(optim.TimingRequest(q, "multi-quintic", 1.0, method="exact",
                                            trajectory_options={"velocities": "heuristic"})).trajectory.peaks()


#: What :func:`warm` runs, in order: (label, call).
STEPS: tuple[tuple[str, Callable[[], None]], ...] = (
    ("inverse kinematics", _ik),
    ("motion planning", _plan),
    ("sphere cover", _cover),
    ("line simulation", _line),
    ("trajectory timing", _timing),
)

#: Seconds each step took to compile on a fresh install, one after the other in one process (2026-12, two cores
#: at a load of 15): only their ratio matters, it decides which process runs which step (:func:`plan_processes`).
STEP_COST = {"inverse kinematics": 155.0, "motion planning": 915.0, "sphere cover": 329.0, "line simulation": 91.0,
             "trajectory timing": 60.0}  # (the timing step's: estimated, one small kernel; added after the measurement)

#: A line a worker process writes on stdout for its parent starts with this.
_EVENT = "pinarms-warm-event "


@dataclass(frozen=True)
class WarmStep:
    """One step of :func:`warm`: its wall time [s] and the kernel signatures it compiled (0: all from the cache)."""

    label: str
    seconds: float
    compiled: int


@dataclass(frozen=True)
class WarmResult:
    """What :func:`warm` did; ``missing``: kernels that no step called (each is compiled on its first real use);
    ``repeated``: kernels a process compiled for several signatures (each one more compile: a literal argument,
    a read-only array; seen only where they were not cached yet); ``overlap``: kernels compiled by more than one
    of the parallel processes (the same small callee reached by two steps); ``wall_seconds``: the whole warm-up's
    wall time, ``processes``: how many processes ran the steps."""

    steps: tuple[WarmStep, ...]
    kernels: int
    missing: tuple[str, ...]
    repeated: tuple[str, ...] = ()
    overlap: tuple[str, ...] = ()
    wall_seconds: float | None = None
    processes: int = 1

    @property
    def seconds(self) -> float:
        """Wall time [s] of the whole warm-up (the steps added up where it was not measured)."""
        return self.step_seconds if self.wall_seconds is None else self.wall_seconds

    @property
    def step_seconds(self) -> float:
        """The steps' wall times added up [s] (more than :attr:`seconds` where processes ran them in parallel)."""
        return sum(s.seconds for s in self.steps)

    @property
    def compiled(self) -> int:
        return sum(s.compiled for s in self.steps)

    def lines(self) -> list[str]:
        """A short text report."""
        out = [f"{s.label}: {s.seconds:.1f} s, " + (f"{s.compiled} kernel signatures compiled" if s.compiled
                                                      else "every kernel loaded from the cache") for s in self.steps]
        ready = f"{self.kernels} kernels ready in {self.seconds:.1f} s"
        if self.processes > 1:
            ready += f" ({self.processes} processes in parallel; the steps add up to {self.step_seconds:.1f} s)"
        out.append(ready)
        if self.missing:
            out.append("not compiled ahead (compiled on first use): " + ", ".join(self.missing))
        if self.repeated:
            out.append("compiled for several signatures in this run: " + ", ".join(self.repeated))
        if self.overlap:
            out.append("compiled by more than one process: " + ", ".join(self.overlap))
        return out

    def as_dict(self) -> dict[str, Any]:
        return {"steps": [{"label": s.label, "seconds": s.seconds, "compiled": s.compiled} for s in self.steps],
                "kernels": self.kernels, "missing": list(self.missing), "repeated": list(self.repeated),
                "overlap": list(self.overlap), "seconds": self.seconds, "step_seconds": self.step_seconds,
                "processes": self.processes}


def cores() -> int:
    """The cores this process may run on (its CPU affinity where the system tells it, else the machine's count)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def plan_processes(processes: int, cost: dict[str, float] | None = None) -> list[list[str]]:
    """The labels of :data:`STEPS` split over at most ``processes`` processes: the longest step first, each next
    step to the process with the least work so far (by ``cost``, :data:`STEP_COST` by default); each process keeps
    the order of :data:`STEPS`. No empty process: never more processes than steps."""
    if processes < 1:
        raise ValueError(f"processes must be at least 1, got {processes}")
    cost = STEP_COST if cost is None else cost
    labels = [label for label, _ in STEPS]
    bins: list[list[str]] = [[] for _ in range(min(processes, len(labels)))]
    load = [0.0] * len(bins)
    for label in sorted(labels, key=lambda name: -cost.get(name, 0.0)):
        i = load.index(min(load))
        bins[i].append(label)
        load[i] += cost.get(label, 0.0)
    return [sorted(b, key=labels.index) for b in bins]


def _run_steps(labels: Sequence[str], emit: Callable[[str, Any], None]) -> dict[str, int]:
    """Run the steps named ``labels`` here, in order: ``emit("start", label)`` before each, ``emit("step", step)``
    after; return the signatures compiled per kernel in this process."""
    calls = dict(STEPS)
    for label in labels:
        emit("start", label)
        before = cache_misses()
        start = time.perf_counter()
        calls[label]()
        emit("step", WarmStep(label, time.perf_counter() - start, cache_misses() - before))
    return {name: n for name, k in kernels().items() if (n := sum(k.stats.cache_misses.values()))}


def run_worker(labels: Sequence[str]) -> None:
    """A worker process of :func:`warm`: run the steps ``labels`` and report each on stdout (one JSON line each)."""
    def emit(kind: str, value: Any) -> None:
        if isinstance(value, WarmStep):
            value = [value.label, value.seconds, value.compiled]
        print(_EVENT + json.dumps([kind, value]), flush=True)

    emit("misses", _run_steps(labels, emit))


def _start_worker(labels: list[str], events: queue.Queue) -> tuple[subprocess.Popen, Any, threading.Thread]:
    """A new interpreter of this environment running :func:`run_worker`; a thread passes its events to ``events``."""
    code = "import sys; from pinarms.warmup import run_worker; run_worker(sys.argv[1:])"
    errors = tempfile.TemporaryFile(mode="w+", encoding="utf-8")
    process = subprocess.Popen([sys.executable, "-c", code, *labels], stdout=subprocess.PIPE, stderr=errors,
                               text=True, encoding="utf-8")

    def read() -> None:
        assert process.stdout is not None
        for line in process.stdout:
            if line.startswith(_EVENT):
                events.put(tuple(json.loads(line[len(_EVENT):])))
        events.put(("exit", None))

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    return process, errors, reader


def _run_parallel(plan: list[list[str]], progress: Callable[[str], None] | None,
                  done: Callable[[WarmStep], None] | None) -> tuple[list[WarmStep], list[dict[str, int]]]:
    """Run each list of labels of ``plan`` in its own process; the steps in :data:`STEPS`' order and each
    process's compiles per kernel."""
    events: queue.Queue = queue.Queue()
    workers = [_start_worker(labels, events) for labels in plan]
    steps: dict[str, WarmStep] = {}
    misses: list[dict[str, int]] = []
    try:
        running = len(workers)
        while running:
            kind, value = events.get()
            if kind == "start" and progress is not None:
                progress(value)
            elif kind == "step":
                steps[value[0]] = WarmStep(value[0], float(value[1]), int(value[2]))
                if done is not None:
                    done(steps[value[0]])
            elif kind == "misses":
                misses.append({str(k): int(n) for k, n in value.items()})
            elif kind == "exit":
                running -= 1
        failed = []
        for (process, errors, reader), labels in zip(workers, plan):
            process.wait()
            reader.join()
            if process.returncode:
                errors.seek(0)
                failed.append(f"{', '.join(labels)} (exit {process.returncode}): {errors.read()[-2000:]}")
        if failed:
            raise RuntimeError("the warm-up's process failed: " + "; ".join(failed))
    finally:
        for process, errors, _ in workers:
            if process.poll() is None:
                process.kill()
                process.wait()
            errors.close()
    order = [label for label, _ in STEPS]
    return sorted(steps.values(), key=lambda s: order.index(s.label)), misses


def warm(progress: Callable[[str], None] | None = None, done: Callable[[WarmStep], None] | None = None,
         processes: int | None = None) -> WarmResult:
    """Run :data:`STEPS` (each kernel compiled, or loaded from numba's cache); ``progress(label)`` as each step
    starts, ``done(step)`` as it ends (several run at once in parallel processes).

    ``processes``: how many processes run the steps (default: one per core, :func:`cores`; never more than the
    steps); each is a new interpreter of this Python environment, with its own numba (:func:`plan_processes`
    says which steps each runs). ``processes=1`` runs them one after the other in this process, which then
    holds every kernel.
    """
    processes = cores() if processes is None else processes
    plan = plan_processes(processes)
    start = time.perf_counter()
    found = kernels()  # imports every kernel module here first: their stale-cache guards run once, before the workers
    if len(plan) == 1:
        steps: list[WarmStep] = []

        def emit(kind: str, value: Any) -> None:
            if kind == "start":
                if progress is not None:
                    progress(value)
                return
            steps.append(value)
            if done is not None:
                done(value)

        misses = [_run_steps(plan[0], emit)]
    else:
        steps, misses = _run_parallel(plan, progress, done)
    wall = time.perf_counter() - start
    # a kernel called only by kernels loaded from the cache has no signature in memory, but one on disk
    missing = tuple(sorted(name for name, k in found.items() if not k.signatures and not cached_signatures(k)))
    # compiled more than once by one process (signatures another process or a test cached are not counted)
    repeated = tuple(sorted({name for m in misses for name, n in m.items() if n > 1}))
    overlap = tuple(sorted(name for name in found if sum(name in m for m in misses) > 1))
    return WarmResult(tuple(steps), len(found) - len(missing), missing, repeated, overlap, wall, len(plan))
