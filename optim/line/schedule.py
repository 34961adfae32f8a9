"""Several arms of one cell cycling together: time offsets that never collide, the line's rate.

Every arm repeats its own pick-and-place cycle (:func:`pinarms.optim.plan_cycle`) with the line's
period ``T`` (the longest cycle; a faster arm waits at its pick until the next period).
The first arm starts at 0; each next arm's start (its *offset*) is scanned over ``[0, T)``
and every offset is checked with :meth:`pinarms.robots.cell.Cell.check_motion` over one period of
the periodic motion (all arms moving at once, continuously in time). The offset kept is
the **centre of the widest run of clear offsets** (the most tolerant of timing jitter; a
scanned offset, the lower middle one of an even run), lowest offset on ties. When no offset clears, the line slows down: ``T`` grows by 10 % of
the longest cycle at a time (up to twice it) and the scan is repeated.

The line's rate is ``n_arms · 60 / T`` picks per minute, against ``60 / cycle time`` for
each arm alone.

**Shared zone.** An arm is *busy in the shared zone* while its tcp is within another arm's
horizontal reach (the largest horizontal distance of that arm's tcp from its base axis,
from 2000 seeded random configurations): :attr:`LineSchedule.busy` lists these intervals
over one period, for the schedule plot.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, NamedTuple, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.optim.caps import (MAX_CLEARANCE, MAX_LINE_CYCLE_TIME, MAX_OFFSETS, MIN_MARGIN, count_setting,
                               number_setting)
from pinarms.optim.errors import InfeasibleProblem, SettingOutOfRange
from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.optim.cycle.spec import CycleResult
    from pinarms.robots.cell.cell import Cell

__all__ = ["LineSchedule", "schedule_line"]

#: Time step [s] of the busy-interval sampling.
BUSY_STEP = 1e-3


@dataclass(frozen=True, eq=False)
class LineSchedule:
    """Offsets that keep the arms of a cell apart, and the line's rate.

    Attributes:
        cell: the cell's name; ``arms``: the arms in order.
        cycle_times: each arm's own cycle time [s].
        period: the line's period ``T`` [s].
        offsets: start of each arm's cycle in the period [s] (the first arm: 0).
        picks_per_minute: the line's rate (``n_arms · 60 / T``).
        single_arm_picks_per_minute: each arm alone (``60 / cycle time``).
        scanned: ``(K,)`` offsets tried for the last arm [s]; ``clear``: ``(K,)`` whether each
            is proven clear; ``min_clearance``: ``(K,)`` smallest distance at the samples [m].
        check: the :class:`~pinarms.robots.cell.MotionCheck` of the kept schedule (every pair).
        arm_check: the same motion checked on the arm–arm pairs only, with the exact
            distance at every sample: how close the arms come to each other over a period
            (the clearance-over-time curve).
        busy: per arm, the ``(start, end)`` intervals [s] of one period it spends in the
            shared zone (module doc).
        periods_tried: the periods scanned [s].
    """

    cell: str
    arms: tuple[str, ...]
    cycle_times: dict[str, float]
    period: float
    offsets: dict[str, float]
    picks_per_minute: float
    single_arm_picks_per_minute: dict[str, float]
    scanned: np.ndarray
    clear: np.ndarray
    min_clearance: np.ndarray
    check: Any = field(repr=False)
    arm_check: Any = field(default=None, repr=False)
    busy: dict[str, list[tuple[float, float]]] = field(default_factory=dict)
    periods_tried: tuple[float, ...] = ()

    def as_dict(self) -> dict[str, Any]:
        return {
            "cell": self.cell,
            "arms": list(self.arms),
            "cycle_times_s": self.cycle_times,
            "period_s": self.period,
            "offsets_s": self.offsets,
            "picks_per_minute": self.picks_per_minute,
            "single_arm_picks_per_minute": self.single_arm_picks_per_minute,
            "offsets_scanned_s": self.scanned.tolist(),
            "offsets_clear": self.clear.tolist(),
            "offsets_min_clearance_m": self.min_clearance.tolist(),
            "min_clearance_m": float(self.check.min_clearance),
            "min_arm_distance_m": None if self.arm_check is None else float(self.arm_check.min_clearance),
            "collision_free": bool(self.check.collision_free),
            "busy_s": {k: [list(v) for v in vs] for k, vs in self.busy.items()},
            "periods_tried_s": list(self.periods_tried),
        }


def _widest_run_centre(clear: np.ndarray, offsets: np.ndarray, period: float) -> float | None:
    """The checked offset at the centre of the widest run of consecutive clear offsets (cyclic;
    the lower middle of an even run), the lowest offset on ties."""
    K = clear.size
    if not clear.any():
        return None
    if clear.all():
        return 0.0
    start = int(np.argmin(clear))  # a blocked offset: runs do not wrap past it
    best_len, best_mid = -1, None
    k = 0
    while k < K:
        i = (start + k) % K
        if clear[i]:
            run = 0
            while k + run < K and clear[(start + k + run) % K]:
                run += 1
            mid = float(offsets[(start + k + (run - 1) // 2) % K])
            if run > best_len or (run == best_len and mid < best_mid):
                best_len, best_mid = run, mid
            k += run
        else:
            k += 1
    return float(best_mid)


def _horizontal_reach(arm: Any) -> float:
    q = arm.robot.random_q(2000, seed=0)
    p = arm.robot.position(q)
    return float(np.max(np.hypot(p[:, 0], p[:, 1])))


def _busy_intervals(cell: Any, motions: list, period: float) -> dict[str, list[tuple[float, float]]]:
    t = np.arange(0.0, period, BUSY_STEP)
    reach = {m.arm: _horizontal_reach(cell.arm(m.arm)) for m in motions}
    out: dict[str, list[tuple[float, float]]] = {}
    for m in motions:
        arm = cell.arm(m.arm)
        q = np.asarray(m.trajectory.sample(m.local_time(t))[0], dtype=float)
        tcp = arm.tcp_to_world(q)[:, :3, 3]
        inside = np.zeros(t.size, dtype=bool)
        for other in motions:
            if other.arm == m.arm:
                continue
            base = cell.arm(other.arm).base_to_world[:3, 3]
            inside |= np.hypot(tcp[:, 0] - base[0], tcp[:, 1] - base[1]) <= reach[other.arm]
        edges = np.flatnonzero(np.diff(np.concatenate([[0], inside.astype(int), [0]])))
        out[m.arm] = [(float(t[a]), float(t[b - 1] + BUSY_STEP)) for a, b in zip(edges[::2], edges[1::2])]
    return out


def schedule_line(
    cell: Cell,
    cycles: Mapping[str, CycleResult],
    *,
    clearance: float = 0.0,
    margin: float = 0.01,
    n_offsets: int = 24,
    hold: ArrayLike | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> LineSchedule:
    """Time offsets for the arms of ``cell`` cycling together (module doc).

    Args:
        cycles: ``{arm name: CycleResult}`` (each planned for ``cell.arm(name).robot``); the
            order is the order offsets are chosen in.
        clearance: distance every pair must keep [m] (0: no contact).
        margin: resolution of the continuous checks [m].
        n_offsets: offsets scanned per arm and period (2 to :data:`pinarms.optim.caps.MAX_OFFSETS`).
        hold: cell configuration of the arms without a cycle (default :attr:`Cell.hold`).
        progress: optional callable ``progress(done, total)`` (for a progress bar).

    Raises:
        InvalidInput: fewer than two arms, an unknown arm, a cycle of the wrong width;
            ``SettingOutOfRange`` (an ``InvalidInput``): ``n_offsets``, ``clearance``, ``margin``
            or a cycle time outside its cap (:mod:`pinarms.optim.caps`).
        InfeasibleProblem: no offset clears even at twice the longest cycle.
    """
    from pinarms.robots.cell import ArmMotion

    names, cycle_times, n_offsets, clearance, margin = _settings(cell, cycles, n_offsets, clearance, margin)
    longest = max(cycle_times.values())
    periods = [longest * (1.0 + 0.1 * k) for k in range(11)]
    scan = _OffsetScan(cell, cycles, names, n_offsets, clearance, margin, hold, progress,
                       len(periods) * n_offsets * (len(names) - 1))
    tried = []
    for period in periods:
        tried.append(period)
        offsets, last = scan.period(period)
        if offsets is not None:
            break
    else:
        raise InfeasibleProblem(
            f"no time offsets keep the arms of cell {cell.name!r} apart, even with the line's period at "
            f"{periods[-1]:.3f} s (twice the longest cycle): the arms' cycles overlap for too long in the shared "
            "zone; move the picks apart or give each arm its own part of the belt"
        )
    motions = [ArmMotion(n, cycles[n].trajectory, offsets[n], period) for n in names]
    final = cell.check_motion(motions, margin=margin, clearance=clearance, window=(0.0, period), hold=hold)
    between = cell.with_pairs("arm-arm").check_motion(motions, margin=margin, window=(0.0, period), hold=hold,
                                                       curve=True)
    return LineSchedule(
        cell=cell.name,
        arms=tuple(names),
        cycle_times=cycle_times,
        period=float(period),
        offsets={k: float(v) for k, v in offsets.items()},
        picks_per_minute=len(names) * 60.0 / period,
        single_arm_picks_per_minute={n: 60.0 / cycle_times[n] for n in names},
        scanned=last.grid,
        clear=last.clear,
        min_clearance=last.closest,
        check=final,
        arm_check=between,
        busy=_busy_intervals(cell, motions, period),
        periods_tried=tuple(tried),
    )


def _settings(cell: Any, cycles: Mapping[str, Any], n_offsets: int, clearance: float,
              margin: float) -> tuple[list[str], dict[str, float], int, float, float]:
    """(arm names, cycle times [s], n_offsets, clearance, margin) checked (see :func:`schedule_line`)."""
    names = list(cycles)
    if len(names) < 2:
        raise InvalidInput("schedule_line needs the cycles of at least two arms")
    n_offsets = count_setting(n_offsets, "n_offsets (time offsets scanned per arm)", 2, MAX_OFFSETS)
    clearance = number_setting(clearance, "clearance", 0.0, MAX_CLEARANCE, unit="m")
    margin = number_setting(margin, "margin (resolution of the continuous checks)", MIN_MARGIN, unit="m")
    for name in names:
        arm = cell.arm(name)
        if cycles[name].trajectory.n_joints != arm.nq:
            raise InvalidInput(f"the cycle given for arm {name!r} has {cycles[name].trajectory.n_joints} joints, "
                               f"the arm {arm.nq}")
    cycle_times = {n: float(cycles[n].trajectory.duration) for n in names}
    for n, t in cycle_times.items():
        if not 0.0 < t <= MAX_LINE_CYCLE_TIME:
            raise SettingOutOfRange(f"the cycle of arm {n!r} lasts {t:g} s; a line schedule takes cycles of up to "
                                    f"{MAX_LINE_CYCLE_TIME:g} s: plan a faster cycle (higher limits, shorter dwell)")
    return names, cycle_times, n_offsets, clearance, margin


class ScannedOffsets(NamedTuple):
    """One arm's scan over a period: ``grid`` (K,) offsets [s], ``clear`` (K,) proven clear,
    ``closest`` (K,) smallest distance at the samples [m]."""

    grid: np.ndarray
    clear: np.ndarray
    closest: np.ndarray


@dataclass(eq=False)
class _OffsetScan:
    """The offsets of each next arm scanned over one period, the arms before it at their offsets kept."""

    cell: Any
    cycles: Mapping[str, Any]
    names: list[str]
    n_offsets: int
    clearance: float
    margin: float
    hold: Any
    progress: Any
    total: int
    done: int = 0

    def period(self, period: float) -> tuple[dict[str, float] | None, ScannedOffsets | None]:
        """The offsets of every arm at ``period`` (None when some arm has no clear offset) and the last scan."""
        offsets = {self.names[0]: 0.0}
        scan = None
        for name in self.names[1:]:
            scan = self.arm(name, offsets, period)
            chosen = _widest_run_centre(scan.clear, scan.grid, period)
            if chosen is None:
                return None, scan
            offsets[name] = chosen
        return offsets, scan

    def arm(self, name: str, offsets: dict[str, float], period: float) -> ScannedOffsets:
        """Arm ``name``'s offsets over ``[0, period)`` checked against the arms of ``offsets``."""
        from pinarms.robots.cell import ArmMotion

        grid = np.arange(self.n_offsets) * (period / self.n_offsets)
        clear = np.zeros(self.n_offsets, dtype=bool)
        closest = np.zeros(self.n_offsets)
        for k, phi in enumerate(grid):
            motions = [ArmMotion(n, self.cycles[n].trajectory, offsets[n], period) for n in offsets]
            motions.append(ArmMotion(name, self.cycles[name].trajectory, float(phi), period))
            result = self.cell.check_motion(motions, margin=self.margin, clearance=self.clearance,
                                            window=(0.0, period), hold=self.hold)
            clear[k] = result.clear if self.clearance > 0 else result.collision_free
            closest[k] = result.min_clearance
            self.done += 1
            if self.progress is not None:
                self.progress(self.done, self.total)
        return ScannedOffsets(grid, clear, closest)
