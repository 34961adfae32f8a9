"""Compile every numba kernel once, ahead of first use, into numba's on-disk cache (``pinarms warm``).

pinarms' compiled kernels (:mod:`pinarms.compiled`) are compiled on their first call and cached
on disk; without a cache the first numerical IK of a process takes about a minute and a half and
the first ``plan_motion`` several minutes on two cores. :func:`warm` makes the calls that compile
them all, with the argument types the library really passes (a numerical IK, one and a batch,
position only and full pose; a compiled motion plan in a cell, which runs the sphere cover, the
search, the spline proof and the time-optimal timing; the sphere cover's other entries), so that
every later process loads them from the cache (about a second). ``make install`` runs it
(``pinarms warm``); a second run loads everything and compiles nothing.

:func:`kernels` lists every kernel of :data:`KERNEL_MODULES` by name; :func:`cache_misses` counts
the signatures numba compiled in this process (a signature loaded from the cache is a hit), which is
how :class:`WarmResult` tells compiled from loaded, and how the tests check that after a warm-up
no kernel is compiled again.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["KERNEL_MODULES", "WarmStep", "WarmResult", "kernels", "cached_signatures", "cache_misses", "warm",
           "STEPS"]

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


@dataclass(frozen=True)
class WarmStep:
    """One step of :func:`warm`: its wall time [s] and the kernel signatures it compiled (0: all from the cache)."""

    label: str
    seconds: float
    compiled: int


@dataclass(frozen=True)
class WarmResult:
    """What :func:`warm` did; ``missing``: kernels that no step called (each is compiled on its first real use);
    ``repeated``: kernels this run compiled for several signatures (each one more compile: a literal argument,
    a read-only array; seen only where they were not cached yet)."""

    steps: tuple[WarmStep, ...]
    kernels: int
    missing: tuple[str, ...]
    repeated: tuple[str, ...] = ()

    @property
    def seconds(self) -> float:
        return sum(s.seconds for s in self.steps)

    @property
    def compiled(self) -> int:
        return sum(s.compiled for s in self.steps)

    def lines(self) -> list[str]:
        """A short text report."""
        out = [f"{s.label}: {s.seconds:.1f} s, " + (f"{s.compiled} kernel signatures compiled" if s.compiled
                                                      else "every kernel loaded from the cache") for s in self.steps]
        out.append(f"{self.kernels} kernels ready in {self.seconds:.1f} s")
        if self.missing:
            out.append("not compiled ahead (compiled on first use): " + ", ".join(self.missing))
        if self.repeated:
            out.append("compiled for several signatures in this run: " + ", ".join(self.repeated))
        return out

    def as_dict(self) -> dict[str, Any]:
        return {"steps": [{"label": s.label, "seconds": s.seconds, "compiled": s.compiled} for s in self.steps],
                "kernels": self.kernels, "missing": list(self.missing), "repeated": list(self.repeated),
                "seconds": self.seconds}


def warm(progress: Callable[[str], None] | None = None) -> WarmResult:
    """Run :data:`STEPS` (each kernel compiled, or loaded from numba's cache); ``progress(label)`` before each."""
    steps = []
    for label, call in STEPS:
        if progress is not None:
            progress(label)
        before = cache_misses()
        start = time.perf_counter()
        call()
        steps.append(WarmStep(label, time.perf_counter() - start, cache_misses() - before))
    found = kernels()
    # a kernel called only by kernels loaded from the cache has no signature in memory, but one on disk
    missing = tuple(sorted(name for name, k in found.items() if not k.signatures and not cached_signatures(k)))
    # compiled more than once in this run (signatures another process or a test cached are not counted)
    repeated = tuple(sorted(name for name, k in found.items() if sum(k.stats.cache_misses.values()) > 1))
    return WarmResult(tuple(steps), len(found) - len(missing), missing, repeated)
